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

import numpy as np

from simulator import columns as col
from simulator.errors import (
    InputError,
    Problem,
    not_regular,
    refuse_undecodable,
    refuse_unless_regular,
)
from simulator.tables import Table, column, n_rows

MAX_MANIFEST_BYTES = 64 * 2**20  # a manifest is read whole: a larger one is no manifest

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

    def finish(self, manifest: dict, streams: dict[str, Table],
               described: dict[str, dict] | None = None) -> None:
        """Write what is left, then the manifest with its ``streams`` block: each stream's file,
        rows and rate, and the fields of ``described[name]`` (the IMU's ``imu_output``)."""
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
            # one row per satellite and signal: no rate (the epochs' rate is the receiver's)
            if "t" in table and rows > 1 and name not in ("gnss_raw", "truth_gnss",
                                                           "gnss_base_raw", "truth_gnss_base"):
                t = column(table, "t")
                rate = round(float((rows - 1) / (t[-1] - t[0])), 6)
            manifest["streams"][name] = {"file": self.file_name(name), "rows": rows,
                                         "rate_hz": rate, **(described or {}).get(name, {})}
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
        entry = self.manifest["streams"][name]
        path = self.path / entry["file"]
        frame = _parquet().read_table(path, columns)
        problem = (stream_problem(name, frame, columns)
                   or _unit_problem(name, _parquet().read_units(path))
                   or _rate_problem(frame, entry.get("rate_hz")))
        if problem:
            raise InputError([Problem(str(path), None, "", f"corrupt {name} stream: {problem}")])
        return frame

    def field(self, *keys: str) -> object:
        """A manifest value by key path (``field("gps_time_start", "week")``); InputError
        naming the manifest and the key when it is absent."""
        node: object = self.manifest
        for key in keys:
            node = node.get(key) if isinstance(node, dict) else None
        if node is None:
            raise InputError([Problem(str(self.path / "manifest.json"), None, ".".join(keys),
                                      "missing; this command needs it")])
        return node

    def units(self, name: str) -> dict[str, str]:
        return _parquet().read_units(self.path / self.manifest["streams"][name]["file"])


def stream_problem(name: str, frame: pd.DataFrame, columns: list[str] | None = None
                   ) -> str | None:
    """What is wrong with a stream table read from a dataset, or None: a required column
    missing, a column that should be numeric and is not, times that are not finite or run
    backwards, an IMU or truth without samples, an IMU sample with no value or beyond any
    IMU's range, a truth position missing or where none can be."""
    from pandas.api.types import is_numeric_dtype

    wanted = col.REQUIRED.get(name, ())
    missing = [c for c in wanted if c not in frame and (columns is None or c in columns)]
    if missing:
        return f"column(s) {', '.join(missing)} missing"
    if name == "imu" and columns is None and not any(a in frame for a in col.IMU_AXES):
        return f"no IMU axis column (one of {', '.join(col.IMU_AXES)})"
    for c in frame.columns:
        if c not in col.TEXT_COLUMNS and not is_numeric_dtype(frame[c].dtype):
            return f"column {c} holds {frame[c].dtype} values, not numbers"
    for c in ("t", "t_start", "t_end"):
        if c not in frame:
            continue
        t = frame[c].to_numpy(dtype=float)
        if not np.isfinite(t).all():
            return f"column {c} has a missing or infinite value at row {_first(~np.isfinite(t))}"
        # the truth's time strictly increases; a stream's may repeat (a raw epoch's satellites)
        backwards = np.diff(t) <= 0 if name == "truth" else np.diff(t) < 0
        if c == "t" and backwards.any():
            return (f"time runs backwards at row {_first(backwards) + 1}: "
                    f"t = {t[_first(backwards) + 1]:.6f} s after {t[_first(backwards)]:.6f} s")
    if name == "events" and {"t_start", "t_end"} <= set(frame):
        reversed_rows = frame["t_end"].to_numpy(float) < frame["t_start"].to_numpy(float)
        if reversed_rows.any():
            return f"row {_first(reversed_rows)} ends before it starts"
    if name in ("imu", "truth") and columns is None and len(frame) == 0:
        return "no samples"
    if name == "truth":
        return _position_problem(frame)
    if name == "imu":
        axes = frame[[a for a in col.IMU_AXES if a in frame]].to_numpy(dtype=float)
        bad = ~np.isfinite(axes).all(axis=1)
        if bad.any():
            return (f"{int(bad.sum())} sample(s) have no value, the first at row {_first(bad)} "
                    f"(t = {frame['t'].iloc[_first(bad)]:.6f} s); an IMU log has none")
        return _imu_range_problem(frame)
    return None


# largest magnitude an IMU sample may have: above every MEMS full scale (4000 deg/s, 200 g),
# in rad/s and m/s^2 (increments, per sample, are smaller still)
IMU_LIMITS = {"gyro": 100.0, "accel": 2000.0}


def _imu_range_problem(frame: pd.DataFrame) -> str | None:
    for axis in col.IMU_AXES:
        if axis not in frame:
            continue
        values = np.abs(frame[axis].to_numpy(dtype=float))
        limit = IMU_LIMITS[axis.partition("_")[0]]
        if len(values) and values.max() > limit:
            i = int(values.argmax())
            return (f"{axis} = {frame[axis].iloc[i]:.6g} at row {i} is beyond any IMU's range "
                    f"(|{axis}| <= {limit:g} in SI units)")
    return None


def _position_problem(frame: pd.DataFrame) -> str | None:
    """A truth position that is missing or lies where no position can (``POSITION_SPANS``)."""
    for name, (low, high) in col.POSITION_SPANS.items():
        if name not in frame:
            continue
        values = frame[name].to_numpy(dtype=float)
        bad = ~((values >= low) & (values <= high))
        if bad.any():
            i = _first(bad)
            when = f" (t = {frame['t'].iloc[i]:.6f} s)" if "t" in frame else ""
            return (f"{name} = {values[i]:.6g} at row {i}{when} is "
                    f"no position (outside [{low:g}, {high:g}] in degrees and metres)")
    return None


def _unit_problem(name: str, units: dict[str, str]) -> str | None:
    """A column whose unit in the file differs from SPEC's (an IMU may also hold increments)."""
    declared = col.STREAMS.get(name, (None, {}))[1]
    for c, unit in units.items():
        allowed = {declared.get(c)}
        if name == "imu":
            allowed.add(col.IMU_INCREMENT_UNITS.get(c))
        if unit and c in declared and unit not in allowed:
            return (f"column {c} is in {unit!r}; the dataset format has it in "
                    f"{declared[c]!r} (convert it)")
    return None


def _rate_problem(frame: pd.DataFrame, rate_hz: object) -> str | None:
    """Times that do not advance at the manifest's rate (times in milliseconds, say)."""
    if not isinstance(rate_hz, (int, float)) or rate_hz <= 0 or "t" not in frame \
            or len(frame) < 10:
        return None
    step = float(np.median(np.diff(frame["t"].to_numpy(dtype=float))))
    # the manifest's rate is the mean over the stream (dropouts lower it): a factor of ten
    # either way is another unit, not gaps
    if not 0.1 <= step * rate_hz <= 10.0:
        return (f"times advance by {step:.6g} per sample where the manifest's rate "
                f"{rate_hz:g} Hz means {1 / rate_hz:.6g} s: times in another unit than "
                "seconds?")
    return None


def _first(mask: np.ndarray) -> int:
    return int(mask.nonzero()[0][0])


_MANIFEST_FIELDS = {  # key path -> the JSON types it may have
    ("gps_time_start",): (dict,),
    ("origin",): (dict,),
    ("gps_time_start", "week"): (int,),
    ("gps_time_start", "tow"): (int, float),
    ("origin", "lat"): (int, float),
    ("origin", "lon"): (int, float),
    ("origin", "alt"): (int, float),
    ("utc_start",): (str,),
    ("scenario",): (dict,),
    ("scenario", "sensors"): (dict,),
    ("sensors",): (dict,),
    ("sensors", "gnss", "broadcast_iono"): (dict,),
    ("sensors", "gnss", "time_corrections"): (dict,),
    ("datasheet",): (dict,),
}
_MAPPINGS_OF_MAPPINGS = (("scenario", "sensors"), ("sensors",))  # each entry is a mapping


def _manifest_problems(path: Path, manifest: dict) -> list[Problem]:
    where = str(path / "manifest.json")
    problems = []
    for keys, types in _MANIFEST_FIELDS.items():
        node: object = manifest
        for key in keys:
            node = node.get(key) if isinstance(node, dict) else None
        if node is None:  # optional here; a command that needs it asks Dataset.field
            continue
        if isinstance(node, bool) or not isinstance(node, types):
            kinds = " or ".join({int: "an integer", float: "a number", dict: "a mapping"}
                                .get(t, "text") for t in types)
            problems.append(Problem(where, None, ".".join(keys),
                                    f"not {kinds} (got {node!r})"))
    for keys in _MAPPINGS_OF_MAPPINGS:
        node = manifest
        for key in keys:
            node = node.get(key) if isinstance(node, dict) else None
        for name, entry in (node.items() if isinstance(node, dict) else ()):
            if entry is not None and not isinstance(entry, dict):
                problems.append(Problem(where, None, ".".join((*keys, str(name))),
                                        f"not a mapping (got {entry!r})"))
    streams = manifest.get("streams")
    if not isinstance(streams, dict):
        return [*problems, Problem(where, None, "streams", "missing or malformed")]
    root = path.resolve()
    for name, entry in streams.items():
        file = entry.get("file") if isinstance(entry, dict) else None
        if not isinstance(file, str) or not file:
            problems.append(Problem(where, None, f"streams.{name}.file",
                                    f"missing or not a file name (got {file!r})"))
            continue
        target = (path / file).resolve()
        if Path(file).name != file or target.parent != root:
            problems.append(Problem(where, None, f"streams.{name}.file",
                                    f"{file!r} is not a file inside the dataset folder"))
        elif (kind := not_regular(target)) is not None:
            problems.append(Problem(where, None, f"streams.{name}",
                                    f"its file {file!r} is missing" if kind == "missing"
                                    else f"its file {file!r} is {kind}, not a regular file"))
    return problems


def open_dataset(path: str | Path) -> Dataset:
    """Open a dataset directory; raise InputError if it is not a landnav dataset."""
    path = Path(path)
    refuse_undecodable(path, "dataset's name")
    manifest_path = path / "manifest.json"
    refuse_unless_regular(path, "dataset directory", folder=True)
    if not_regular(manifest_path) == "missing":
        raise InputError([Problem(str(path), None, "", "not a landnav dataset (no manifest.json;"
                                  " make one with `landnav generate SCENARIO -o DIR`)")])
    refuse_unless_regular(manifest_path, "manifest file")  # a pipe or a device: unread
    try:
        with manifest_path.open("rb") as stream:
            text = stream.read(MAX_MANIFEST_BYTES + 1)
        if len(text) > MAX_MANIFEST_BYTES:
            raise ValueError(f"larger than a manifest may be ({MAX_MANIFEST_BYTES // 2**20} "
                             "MiB)")
        manifest = json.loads(text.decode("utf-8"))
    except (OSError, ValueError) as exc:
        raise InputError([Problem(str(manifest_path), None, "", f"corrupt manifest: {exc}")]
                         ) from None
    if not isinstance(manifest, dict) or manifest.get("format") != col.DATASET_FORMAT:
        raise InputError([Problem(str(manifest_path), None, "format",
                                  f"not a {col.DATASET_FORMAT} manifest")])
    problems = _manifest_problems(path, manifest)
    if problems:
        raise InputError(problems)
    return Dataset(path, manifest)
