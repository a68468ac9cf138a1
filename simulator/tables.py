"""Stream tables on the generation path: column tables, and pandas DataFrames only where a
scenario needs pandas.

A *column table* is a ``dict[str, numpy.ndarray]`` of equal-length 1-D columns in the stream's
column order (the SPEC section 5 names of ``simulator.columns``, which also holds their units).
The sensors without pandas code (IMU, odometer, barometer, magnetometer) return column tables,
``Kinematics.columns`` gives the truth as one, and the dataset writer hands them to pyarrow
directly, so that generating a dataset without GNSS and faults never imports pandas (about 0.3 s
of the process start). The GNSS receiver returns DataFrames, the faults convert the tables they
act on with ``as_frame``, and everything that reads a dataset gets DataFrames
(``simulator.dataset.parquet.read_table``). A ``Table`` is either kind; ``n_rows`` and ``column``
read both.

``as_frame`` of a column table is the DataFrame the sensors returned before column tables
existed (``pandas.DataFrame(table)``): same columns, order and dtypes.

Public names
------------
ColumnTable, Table, as_frame, as_frames, n_rows, column.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Union

import numpy as np

if TYPE_CHECKING:
    import pandas as pd

ColumnTable = dict[str, np.ndarray]
Table = Union[ColumnTable, "pd.DataFrame"]


def as_frame(table: Table) -> pd.DataFrame:
    """The table as a DataFrame (a DataFrame is returned as it is); imports pandas."""
    if isinstance(table, dict):
        import pandas as pd

        return pd.DataFrame(table)
    return table


def as_frames(streams: dict[str, Table]) -> dict[str, pd.DataFrame]:
    """Every table of a ``{stream_name: table}`` mapping as a DataFrame."""
    return {name: as_frame(table) for name, table in streams.items()}


def n_rows(table: Table) -> int:
    """Number of rows of a column table or DataFrame."""
    if isinstance(table, dict):
        return len(next(iter(table.values()))) if table else 0
    return len(table)


def column(table: Table, name: str) -> np.ndarray:
    """One column as a numpy array."""
    if isinstance(table, dict):
        return np.asarray(table[name])
    return table[name].to_numpy()
