"""Parquet files of the dataset: a stream (column table or DataFrame) written with each column's
unit in its field metadata, and read back as a DataFrame.

Streams are written from column tables (``simulator.tables``) or DataFrames, to the same Parquet
schema either way: float and integer columns as they are, NaN as null (pandas' convention), text
columns as ``large_string`` (what pandas' ``str`` dtype writes), no schema-level metadata. Writing
imports pandas only for a DataFrame; reading returns DataFrames.

This module imports pyarrow (about 60 ms); ``simulator.dataset.io`` loads it on first use, in the
dataset writer's threads, so that a generation starts its work without waiting for it.

Public functions
----------------
write_table, read_table, read_units, read_metadata.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from simulator.errors import InputError, Problem
from simulator.tables import Table

if TYPE_CHECKING:
    import pandas as pd


def _arrow_column(values: np.ndarray) -> pa.Array:
    """One column of a column table as an Arrow array, built from its buffers: ``pyarrow.array``
    would import pandas (it checks every argument for pandas types). NaN becomes null, as in
    ``pyarrow.Table.from_pandas``; text becomes ``large_string``."""
    values = np.asarray(values)
    if values.dtype.kind in "UO":
        return _text_column(values)
    if values.dtype.kind == "b":
        bits = np.packbits(values, bitorder="little")
        return pa.Array.from_buffers(pa.bool_(), len(values), [None, pa.py_buffer(bits)])
    values = np.ascontiguousarray(values, dtype=values.dtype.newbyteorder("="))
    validity, null_count = None, 0
    # a sum is NaN when a value is (one read-only pass, against two and a mask)
    if values.dtype.kind == "f" and np.isnan(np.add.reduce(values)):
        nan = np.isnan(values)
        null_count = int(np.count_nonzero(nan))
        if null_count:
            validity = pa.py_buffer(np.packbits(~nan, bitorder="little"))
    return pa.Array.from_buffers(pa.from_numpy_dtype(values.dtype), len(values),
                                 [validity, pa.py_buffer(values)], null_count=null_count)


def _text_column(values: np.ndarray) -> pa.Array:
    """A text column (None as null) as ``large_string``, run by run: the columns written this
    way (truth zone, event kinds) hold long runs of one value."""
    n = len(values)
    changes = np.ones(n, dtype=bool)
    changes[1:] = values[1:] != values[:-1]
    starts = np.flatnonzero(changes)
    runs = np.diff(np.append(starts, n))
    run_values = [values[i] for i in starts]
    valid = np.array([v is not None and v == v for v in run_values], dtype=bool)  # v != v: NaN
    encoded = [str(v).encode() if ok else b"" for v, ok in zip(run_values, valid, strict=True)]
    row_bytes = np.repeat(np.array([len(e) for e in encoded], dtype=np.int64), runs)
    offsets = np.concatenate([[0], np.cumsum(row_bytes)]).astype(np.int64)
    data = b"".join(e * int(r) for e, r in zip(encoded, runs, strict=True))
    validity, null_count = None, int(runs[~valid].sum())
    if null_count:
        validity = pa.py_buffer(np.packbits(np.repeat(valid, runs), bitorder="little"))
    return pa.Array.from_buffers(pa.large_string(), n, [validity, pa.py_buffer(offsets),
                                                        pa.py_buffer(data)],
                                 null_count=null_count)


def _arrow_table(table: Table, units: dict[str, str], metadata: dict[str, str] | None = None
                 ) -> pa.Table:
    """The Arrow table of a column table or DataFrame, each field with its unit and no
    schema-level metadata (no ``pandas`` key)."""
    if isinstance(table, dict):
        names, arrays = list(table), [_arrow_column(v) for v in table.values()]
    else:
        converted = pa.Table.from_pandas(table, preserve_index=False)
        names, arrays = converted.column_names, converted.columns
    schema = pa.schema([pa.field(name, array.type).with_metadata({"unit": units.get(name, "")})
                        for name, array in zip(names, arrays, strict=True)],
                       metadata=metadata or {})
    return pa.Table.from_arrays(arrays, schema=schema)


def write_table(frame: Table, path: Path, units: dict[str, str],
                metadata: dict[str, str] | None = None) -> None:
    """Write one table (a column table or a DataFrame) as Parquet with each column's unit in its
    field metadata, and ``metadata`` (none for dataset streams) as the schema's metadata."""
    table = _arrow_table(frame, units, metadata)
    # dictionary encoding for text columns only (on floats it costs time and saves nothing);
    # floats byte-stream-split before zstd: smooth time series then compress about twice as
    # well, and faster; no column statistics (nothing here filters row groups by them)
    text_columns = [f.name for f in table.schema if pa.types.is_string(f.type)
                    or pa.types.is_large_string(f.type)]
    float_columns = [f.name for f in table.schema if pa.types.is_floating(f.type)]
    pq.write_table(table, path, compression="zstd", compression_level=1,
                   use_dictionary=text_columns, use_byte_stream_split=float_columns,
                   write_statistics=False)


def read_table(path: Path, columns: list[str] | None = None,
               read_only: bool = False) -> pd.DataFrame:
    """Read one Parquet table; raise InputError naming the file if it is missing or corrupt.
    ``read_only``: each Arrow column released as it is converted, so the table is not held
    twice, at the price of columns that may not be written in place (for a caller that only
    reads them)."""
    try:
        table = pq.read_table(path, columns=columns)
        if read_only:
            return table.to_pandas(split_blocks=True, self_destruct=True)
        return table.to_pandas()
    except FileNotFoundError:
        raise InputError([Problem(str(path), None, "", "file not found")]) from None
    except (pa.ArrowException, OSError) as exc:
        raise InputError([Problem(str(path), None, "", f"not a readable Parquet file: {exc}")]
                         ) from None


def read_metadata(path: Path) -> dict[str, str]:
    """The schema-level metadata of a Parquet file (text keys and values)."""
    metadata = pq.read_schema(path).metadata or {}
    return {k.decode(errors="replace"): v.decode(errors="replace") for k, v in metadata.items()}


def read_units(path: Path) -> dict[str, str]:
    """Each column's unit, from the field metadata of a Parquet file's schema."""
    schema = pq.read_schema(path)
    return {f.name: (f.metadata or {}).get(b"unit", b"").decode() for f in schema}
