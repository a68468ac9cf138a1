"""The dataset on disk (SPEC section 5): a directory with ``manifest.json`` and one Parquet file
per stream, every column's unit in the Parquet field metadata.

Streams are written from column tables (``simulator.tables``) or DataFrames, to the same Parquet
schema either way: float and integer columns as they are, NaN as null (pandas' convention), text
columns as ``large_string`` (what pandas' ``str`` dtype writes), no schema-level metadata. Writing
imports pandas only for a DataFrame; reading returns DataFrames.

Writing is atomic: everything goes into a temporary sibling directory that is renamed into place
when complete, so an interrupted or failed run never leaves a half-written dataset.

Public names
------------
DatasetWriter, write_dataset, open_dataset, Dataset, write_table, read_table, atomic_output_dir.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
from collections.abc import Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from simulator import columns as col
from simulator.errors import InputError, Problem
from simulator.tables import Table, column, n_rows

if TYPE_CHECKING:
    import pandas as pd


def _units_for(name: str, table: Table) -> dict[str, str]:
    declared = dict(col.STREAMS.get(name, (None, {}))[1])
    declared.update(getattr(table, "attrs", {}).get("units", {}))
    names = list(table)
    missing = [c for c in names if c not in declared]
    if missing:
        raise ValueError(f"stream {name!r}: no unit declared for column(s) {missing}; add them "
                         "to simulator/columns.py or frame.attrs['units']")
    return {c: declared[c] for c in names}


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
    if values.dtype.kind == "f":
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


def _arrow_table(table: Table, units: dict[str, str]) -> pa.Table:
    """The Arrow table of a column table or DataFrame, each field with its unit and no
    schema-level metadata (no ``pandas`` key)."""
    if isinstance(table, dict):
        names, arrays = list(table), [_arrow_column(v) for v in table.values()]
    else:
        converted = pa.Table.from_pandas(table, preserve_index=False)
        names, arrays = converted.column_names, converted.columns
    schema = pa.schema([pa.field(name, array.type).with_metadata({"unit": units.get(name, "")})
                        for name, array in zip(names, arrays, strict=True)], metadata={})
    return pa.Table.from_arrays(arrays, schema=schema)


def write_table(frame: Table, path: Path, units: dict[str, str]) -> None:
    """Write one table (a column table or a DataFrame) as Parquet with each column's unit in its
    field metadata."""
    table = _arrow_table(frame, units)
    # dictionary encoding for text columns only (on floats it costs time and saves nothing);
    # floats byte-stream-split before zstd: smooth time series then compress about twice as
    # well, and faster; no column statistics (nothing here filters row groups by them)
    text_columns = [f.name for f in table.schema if pa.types.is_string(f.type)
                    or pa.types.is_large_string(f.type)]
    float_columns = [f.name for f in table.schema if pa.types.is_floating(f.type)]
    pq.write_table(table, path, compression="zstd", compression_level=1,
                   use_dictionary=text_columns, use_byte_stream_split=float_columns,
                   write_statistics=False)


def read_table(path: Path, columns: list[str] | None = None) -> pd.DataFrame:
    """Read one Parquet table; raise InputError naming the file if it is missing or corrupt."""
    try:
        return pq.read_table(path, columns=columns).to_pandas()
    except FileNotFoundError:
        raise InputError([Problem(str(path), None, "", "file not found")]) from None
    except (pa.ArrowException, OSError) as exc:
        raise InputError([Problem(str(path), None, "", f"not a readable Parquet file: {exc}")]
                         ) from None


@contextlib.contextmanager
def atomic_output_dir(out_dir: Path, force: bool) -> Iterator[Path]:
    """Yield a temporary directory beside ``out_dir``; on success it replaces ``out_dir``.

    Refuses an existing ``out_dir`` unless ``force``. On any error the temporary directory is
    removed and ``out_dir`` is left as it was.
    """
    out_dir = Path(out_dir)
    if out_dir.exists() and not force:
        raise InputError([Problem(str(out_dir), None, "",
                                  "already exists; use --force to overwrite it")])
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError([Problem(str(out_dir), None, "", "exists and is not a directory")])
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    tmp = out_dir.parent / f".{out_dir.name}.tmp-{os.getpid()}"
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir()
    try:
        yield tmp
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    old = out_dir.parent / f".{out_dir.name}.old-{os.getpid()}"
    if out_dir.exists():
        out_dir.rename(old)
    tmp.rename(out_dir)
    shutil.rmtree(old, ignore_errors=True)


class DatasetWriter:
    """Writes a dataset's streams into ``directory`` (inside ``atomic_output_dir``), each as soon
    as it is handed over, two at a time (Parquet encoding and compression release the GIL, so
    the files are written side by side, and beside the work that makes the next streams).

    ``write(name, table)`` starts one stream; ``finish(manifest, streams)`` writes those not yet
    started, waits for all and writes the manifest, its ``streams`` block filled from the
    tables. Used as a context manager, which waits for (or, after an error, drops) what is
    still being written.
    """

    def __init__(self, directory: Path):
        self.directory = Path(directory)
        self._pool = ThreadPoolExecutor(max_workers=2)
        self._jobs: dict[str, Future] = {}

    def __enter__(self) -> DatasetWriter:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._pool.shutdown(wait=True, cancel_futures=exc_info[0] is not None)

    @staticmethod
    def file_name(name: str) -> str:
        return col.STREAMS[name][0] if name in col.STREAMS else f"{name}.parquet"

    def write(self, name: str, table: Table) -> None:
        self._jobs[name] = self._pool.submit(write_table, table,
                                             self.directory / self.file_name(name),
                                             _units_for(name, table))

    def finish(self, manifest: dict, streams: dict[str, Table]) -> None:
        manifest = dict(manifest)
        manifest["format"] = col.DATASET_FORMAT
        manifest["streams"] = {}
        for name, table in streams.items():
            if name not in self._jobs:
                self.write(name, table)
        for name, job in self._jobs.items():
            job.result()
            if name not in streams:  # handed over, then left out of the dataset
                (self.directory / self.file_name(name)).unlink()
        for name, table in streams.items():
            rows = n_rows(table)
            rate = None
            if "t" in table and rows > 1 and name not in ("gnss_raw", "truth_gnss"):
                t = column(table, "t")
                rate = round(float((rows - 1) / (t[-1] - t[0])), 6)
            manifest["streams"][name] = {"file": self.file_name(name), "rows": rows,
                                         "rate_hz": rate}
        text = json.dumps(manifest, indent=2, sort_keys=True, default=str)
        (self.directory / "manifest.json").write_text(text + "\n", encoding="utf-8")


def write_dataset(directory: Path, manifest: dict, streams: dict[str, Table]) -> None:
    """Write streams (column tables or DataFrames) and the manifest into ``directory`` (use
    inside ``atomic_output_dir``); the manifest's ``streams`` block is filled from the tables."""
    with DatasetWriter(directory) as writer:
        writer.finish(manifest, streams)


class Dataset:
    """A landnav dataset directory opened for reading."""

    def __init__(self, path: Path, manifest: dict):
        self.path = Path(path)
        self.manifest = manifest

    @property
    def stream_names(self) -> list[str]:
        return list(self.manifest["streams"])

    def has(self, name: str) -> bool:
        return name in self.manifest["streams"]

    def read(self, name: str, columns: list[str] | None = None) -> pd.DataFrame:
        """Read a stream by name (``imu``, ``gnss_fix``, ``truth``, ...)."""
        if name not in self.manifest["streams"]:
            raise InputError([Problem(str(self.path), None, "", f"the dataset has no {name!r} "
                                      f"stream (it has: {', '.join(self.stream_names)})")])
        return read_table(self.path / self.manifest["streams"][name]["file"], columns)

    def units(self, name: str) -> dict[str, str]:
        schema = pq.read_schema(self.path / self.manifest["streams"][name]["file"])
        return {f.name: (f.metadata or {}).get(b"unit", b"").decode() for f in schema}


def open_dataset(path: str | Path) -> Dataset:
    """Open a dataset directory; raise InputError if it is not a landnav dataset."""
    path = Path(path)
    manifest_path = path / "manifest.json"
    if not path.is_dir():
        raise InputError([Problem(str(path), None, "", "no such dataset directory")])
    if not manifest_path.is_file():
        raise InputError([Problem(str(path), None, "", "not a landnav dataset (no manifest.json;"
                                  " make one with `landnav generate SCENARIO -o DIR`)")])
    try:
        manifest = json.loads(manifest_path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise InputError([Problem(str(manifest_path), None, "", f"corrupt manifest: {exc}")]
                         ) from None
    if not isinstance(manifest, dict) or manifest.get("format") != col.DATASET_FORMAT:
        raise InputError([Problem(str(manifest_path), None, "format",
                                  f"not a {col.DATASET_FORMAT} manifest")])
    streams = manifest.get("streams")
    if not isinstance(streams, dict):
        raise InputError([Problem(str(manifest_path), None, "streams", "missing or malformed")])
    for name, entry in streams.items():
        if not (path / entry.get("file", "")).is_file():
            raise InputError([Problem(str(manifest_path), None, f"streams.{name}",
                                      f"its file {entry.get('file')!r} is missing")])
    return Dataset(path, manifest)
