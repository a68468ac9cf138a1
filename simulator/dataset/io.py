"""The dataset on disk (SPEC section 5): a directory with ``manifest.json`` and one Parquet file
per stream, every column's unit in the Parquet field metadata (the files themselves:
``simulator.dataset.parquet``, imported on first use since pyarrow takes about 60 ms to load).

Writing is atomic: everything goes into a temporary sibling directory that is renamed into place
when complete (``simulator.outputs.atomic_output_dir``), so an interrupted or failed run never
leaves a half-written dataset.

Public names
------------
DatasetWriter, write_dataset, open_dataset, Dataset.
"""

from __future__ import annotations

import json
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

from simulator import columns as col
from simulator.errors import InputError, Problem
from simulator.tables import Table, column, n_rows

if TYPE_CHECKING:
    import pandas as pd


def _units_for(name: str, table: Table, overrides: dict[str, str] | None = None
               ) -> dict[str, str]:
    declared = dict(col.STREAMS.get(name, (None, {}))[1])
    declared.update(overrides or {})
    declared.update(getattr(table, "attrs", {}).get("units", {}))
    names = list(table)
    missing = [c for c in names if c not in declared]
    if missing:
        raise ValueError(f"stream {name!r}: no unit declared for column(s) {missing}; add them "
                         "to simulator/columns.py or frame.attrs['units']")
    return {c: declared[c] for c in names}


def _parquet() -> ModuleType:
    """``simulator.dataset.parquet``, imported on first use (it loads pyarrow)."""
    from simulator.dataset import parquet

    return parquet


def _write(table: Table, path: Path, units: dict[str, str]) -> None:
    _parquet().write_table(table, path, units)


class DatasetWriter:
    """Writes a dataset's streams into ``directory`` (inside
    ``simulator.outputs.atomic_output_dir``), each as soon as it is handed over, two at a time
    (Parquet encoding and compression release the GIL, so the files are written side by side,
    and beside the work that makes the next streams).

    ``write(name, table)`` starts one stream; ``finish(manifest, streams)`` writes those not yet
    started, waits for all and writes the manifest, its ``streams`` block filled from the
    tables. Used as a context manager, which waits for (or, after an error, drops) what is
    still being written.
    """

    def __init__(self, directory: Path, units: dict[str, dict[str, str]] | None = None):
        self.directory = Path(directory)
        self._units = units or {}  # stream -> column -> unit, over columns.STREAMS
        self._pool = ThreadPoolExecutor(max_workers=2)
        self._jobs: dict[str, Future] = {}
        # pyarrow loads in a writer thread while the caller starts making the streams
        self._pool.submit(_parquet)

    def __enter__(self) -> DatasetWriter:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._pool.shutdown(wait=True, cancel_futures=exc_info[0] is not None)

    @staticmethod
    def file_name(name: str) -> str:
        return col.STREAMS[name][0] if name in col.STREAMS else f"{name}.parquet"

    def write(self, name: str, table: Table) -> None:
        self._jobs[name] = self._pool.submit(_write, table,
                                             self.directory / self.file_name(name),
                                             _units_for(name, table, self._units.get(name)))

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
        return _parquet().read_table(self.path / self.manifest["streams"][name]["file"], columns)

    def units(self, name: str) -> dict[str, str]:
        return _parquet().read_units(self.path / self.manifest["streams"][name]["file"])


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
