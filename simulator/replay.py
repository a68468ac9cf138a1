"""Causal replay of a dataset into one estimator, and the solution file (SPEC sections 6-7).

The replay reads only the streams the estimator ``needs`` and ``uses`` (never ``truth*`` or
``events``), merges them by timestamp and hands the estimator one message at a time in time order.
Messages with equal times come in the fixed stream order ``imu, odometer, baro, mag, gnss_fix,
gnss_base_raw, gnss_raw`` (then any other stream, alphabetically): the inertial step ending at
``t`` is taken before the measurements valid at ``t`` are applied, and a base station's epoch
before the rover's of the same time. A ``gnss_raw`` or ``gnss_base_raw`` message is one whole
epoch.

Solutions are asked for (``solution(T)``) at the ticks ``t0 + k / output_rate_hz`` from the first
message time ``t0``, at every GNSS epoch and at the last message time, each once every message
with time <= ``T`` has been handed; so an estimator that only gets 1 Hz fixes still reports at
10 Hz (holding or predicting its state), and a row always follows each GNSS update.

The framework reads the truth only to build the initial state: the truth at the estimator's
first message time, perturbed by the entry's ``init`` errors (position and velocity in NED,
roll/pitch/yaw added to the Euler angles, ``heading_error`` added to yaw).

Public functions
----------------
run_estimator, initial_state, merge_streams, output_times, write_solution, read_solution,
solution_problems.
"""

from __future__ import annotations

import time
import traceback
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from estimators.base import GNSS_STREAMS, Estimator, InitialState
from estimators.registry import get_estimator
from simulator import columns as col
from simulator.compilation import CompileWatch
from simulator.dataset.io import Dataset
from simulator.dataset.parquet import read_table, write_table
from simulator.earth import (
    ecef_to_geodetic,
    geodetic_to_ecef,
    ned_to_ecef_vector,
    wrap_angle,
)
from simulator.errors import InputError, Problem, Terminated
from simulator.outputs import atomic_output_file
from simulator.progress import progress
from simulator.threads import one_blas_thread

STREAM_ORDER = ("imu", "odometer", "baro", "mag", "gnss_fix", "gnss_base_raw", "gnss_raw")
EPOCH_STREAMS = ("gnss_raw", "gnss_base_raw")  # one message per epoch: its satellites' rows
SPAN_MARGIN_S = 1.0  # how far a stream's times may reach beyond the truth's
# solution rows one replay may ask for (about 30 columns of 8 bytes each: 2.4 GB at most);
# 28 h at 100 Hz, the longest drive a scenario may describe
MAX_SOLUTION_ROWS = 10_000_000


def _stream_rank(name: str) -> tuple[int, str]:
    return (STREAM_ORDER.index(name) if name in STREAM_ORDER else len(STREAM_ORDER), name)


def _entry_fields(entry: Mapping[str, Any] | str) -> tuple[str, str, dict | None, dict | None]:
    if isinstance(entry, str):
        return entry, entry, None, None
    name = entry["name"]
    return name, entry.get("label") or name, entry.get("init"), entry.get("config")


def initial_state(truth: pd.DataFrame, t0: float, init: Mapping[str, Any] | None,
                  drawn_sensor_errors: Mapping[str, Any] | None = None) -> InitialState:
    """The truth at ``t0`` (linear interpolation, yaw unwrapped) perturbed by ``init`` errors.

    Parameters
    ----------
    truth : DataFrame
        The truth table (SPEC section 5): ``t, lat, lon`` (deg), ``alt, vn, ve, vd, roll, pitch,
        yaw`` (SI).
    t0 : float
        Start time, s.
    init : mapping or None
        ``position_error`` [n, e, d] m, ``velocity_error`` [n, e, d] m/s, ``attitude_error``
        [roll, pitch, yaw] deg, ``heading_error`` deg, ``sensor_errors`` ('truth' or a
        mapping); each may be None.
    drawn_sensor_errors : mapping or None
        The dataset's true sensor errors (the manifest's ``sensors`` block), handed on when
        ``sensor_errors`` is 'truth'.
    """
    t = truth["t"].to_numpy()

    def at(name: str) -> float:
        values = truth[name].to_numpy(dtype=float)
        if name == "yaw":
            values = np.unwrap(values)
        return float(np.interp(t0, t, values))

    lat, lon, alt = np.radians(at("lat")), np.radians(at("lon")), at("alt")
    vel = np.array([at("vn"), at("ve"), at("vd")])
    att = np.array([at("roll"), at("pitch"), at("yaw")])
    init = init or {}
    if init.get("position_error") is not None:
        d_ned = np.asarray(init["position_error"], dtype=float)
        ecef = geodetic_to_ecef(lat, lon, alt) + ned_to_ecef_vector(d_ned, lat, lon)
        lat, lon, alt = (float(x) for x in ecef_to_geodetic(ecef))
    if init.get("velocity_error") is not None:
        vel = vel + np.asarray(init["velocity_error"], dtype=float)
    if init.get("attitude_error") is not None:
        att = att + np.radians(np.asarray(init["attitude_error"], dtype=float))
    if init.get("heading_error") is not None:
        att[2] += np.radians(float(init["heading_error"]))
    att[2] = wrap_angle(att[2])
    priors = init.get("sensor_errors")
    if priors == "truth":
        priors = drawn_sensor_errors
    return InitialState(float(t0), np.array([lat, lon, alt]), vel, att, dict(priors or {}))


class _Stream:
    """One stream as a float64 array, with the message times and how to index messages."""

    def __init__(self, name: str, frame: pd.DataFrame, units: dict[str, str], where: Path):
        if "system" in frame and not pd.api.types.is_numeric_dtype(frame["system"]):
            # the rows reach an estimator as numbers: the RINEX system letter as its code point
            # (G 71, R 82, E 69, C 67, J 74), ``system_code``
            frame = frame.assign(system_code=frame["system"].astype(str).str[:1].map(ord))
        numeric = [c for c in frame.columns if pd.api.types.is_numeric_dtype(frame[c])]
        if "t" not in numeric:
            raise InputError([Problem(str(where), None, name, "no numeric time column t")])
        self.name = name
        self.data = np.ascontiguousarray(frame[numeric].to_numpy(dtype=np.float64))
        self.data.flags.writeable = False
        self.columns = {c: i for i, c in enumerate(numeric)}
        self.units = {c: units.get(c, "") for c in numeric}
        t = self.data[:, self.columns["t"]]  # increasing: checked when the dataset is read
        if name in EPOCH_STREAMS:  # one message per epoch: a 2-D block of its satellites
            starts = np.flatnonzero(np.r_[True, np.diff(t) > 0])
            bounds = np.r_[starts, len(t)]
            self.times = t[starts]
            self.messages: Any = [self.data[a:b]
                                  for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
        else:
            self.times = t
            self.messages = self.data


def merge_streams(times: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Merge per-stream message times into one time-ordered sequence.

    Parameters
    ----------
    times : list of arrays
        Message times of each stream, in the stream order used for ties.

    Returns
    -------
    t : (n,) merged times; stream : (n,) index of each message's stream; index : (n,) the
    message's position within its stream. Equal times keep the order of ``times``.
    """
    t = np.concatenate(times) if times else np.zeros(0)
    stream = np.concatenate([np.full(len(x), i, dtype=np.int64) for i, x in enumerate(times)]
                            ) if times else np.zeros(0, dtype=np.int64)
    index = np.concatenate([np.arange(len(x)) for x in times]) if times else stream
    order = np.argsort(t, kind="stable")
    return t[order], stream[order], index[order]


def output_times(t: np.ndarray, stream: np.ndarray, gnss: list[int], rate_hz: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    """When to ask for a solution, and how many merged messages to hand before each ask.

    Output instants are the grid ``t[0] + k / rate_hz`` up to the last message, every GNSS
    epoch, and the last message time; a grid instant within 1 ns of a message time takes that
    time exactly. Before asking at time ``T`` every message with time <= ``T`` is handed.

    Returns
    -------
    times : (m,) output times, increasing; upto : (m,) number of messages handed before each.
    """
    if len(t) == 0:
        return np.zeros(0), np.zeros(0, dtype=np.int64)
    n_grid = int(np.floor((t[-1] - t[0]) * rate_hz + 1e-9)) + 1
    grid = t[0] + np.arange(n_grid) / rate_hz
    near = np.searchsorted(t, grid + 1e-9, side="right") - 1
    grid = np.where(np.abs(t[near] - grid) <= 1e-9, t[near], grid)
    times = np.unique(np.concatenate([grid, t[np.isin(stream, gnss)], t[-1:]]))
    return times, np.searchsorted(t, times, side="right")


def _load_streams(dataset: Dataset, cls: type[Estimator], label: str) -> list[_Stream]:
    missing = [s for s in cls.needs if not dataset.has(s)]
    if missing:
        raise InputError([Problem(str(dataset.path), None, "", f"estimator {cls.name!r} "
                                  f"({label}) needs the {s!r} stream, which the dataset does "
                                  f"not have (it has: {', '.join(dataset.stream_names)})")
                          for s in missing])
    # a recording's stream that lacks what estimators need (comma2k19's raw GNSS has no
    # satellite positions: the manifest's ``lacks``) refuses the estimators that need it and
    # is left out for those that would only use it
    lacks = dataset.manifest.get("lacks") or {}
    lacking = [s for s in cls.needs if s in lacks]
    if lacking:
        raise InputError([Problem(str(dataset.path), None, "", f"estimator {cls.name!r} "
                                  f"({label}) needs the {s!r} stream, and this recording's {s} "
                                  f"lacks {lacks[s]}") for s in lacking])
    names = [s for s in dict.fromkeys((*cls.needs, *cls.uses))
             if dataset.has(s) and s not in lacks]
    names.sort(key=_stream_rank)  # scoring-only streams were refused by get_estimator
    streams = [_Stream(s, dataset.read(s), _units(dataset, s), dataset.path) for s in names]
    # a generated dataset's streams lie within its truth; a recording's reference may cover
    # less than its sensors did (the solution-row bound still holds its gaps)
    if dataset.has("truth") and dataset.manifest.get("reference") is not True:
        truth_t = dataset.read("truth", ["t"])["t"].to_numpy(dtype=float)
        span = (truth_t[0], truth_t[-1]) if len(truth_t) else (0.0, 0.0)
        for stream in streams:
            if len(stream.times) and (stream.times[0] < span[0] - SPAN_MARGIN_S
                                      or stream.times[-1] > span[1] + SPAN_MARGIN_S):
                raise InputError([Problem(str(dataset.path), None, stream.name,
                                          f"times run from {stream.times[0]:.6g} s to "
                                          f"{stream.times[-1]:.6g} s, outside the drive "
                                          f"({span[0]:.6g} s to {span[1]:.6g} s in the truth): "
                                          "shifted, or in another unit than seconds?")])
    return streams


def imu_output(dataset: Dataset) -> str | None:
    """What a dataset's IMU rows hold: ``"rate"`` or ``"increment"`` (None without an IMU), from
    the IMU stream's description in the manifest (``imu_output``), else from the resolved
    scenario's ``sensors.imu.output`` (datasets written before the field existed)."""
    stream = dataset.manifest.get("streams", {}).get("imu")
    if stream is None:
        return None
    imu = (dataset.manifest.get("scenario") or {}).get("sensors", {}).get("imu") or {}
    return stream.get("imu_output") or imu.get("output") or "rate"


def _units(dataset: Dataset, name: str) -> dict[str, str]:
    """Column units of a stream; an IMU configured for increment output has rad and m/s
    increments whatever its files say (the manifest's resolved scenario is authoritative):
    datasets written before the writer labelled increments say rad/s and m/s^2 there."""
    units = dataset.units(name)
    imu = (dataset.manifest.get("scenario") or {}).get("sensors", {}).get("imu") or {}
    if name == "imu" and imu.get("output") == "increment":
        units.update({c: u for c, u in col.IMU_INCREMENT_UNITS.items() if c in units})
    return units


@one_blas_thread
def run_estimator(dataset: Dataset, entry: Mapping[str, Any] | str, *,
                  show_progress: bool = True) -> tuple[pd.DataFrame, dict]:
    """Replay a dataset causally into one estimator.

    Parameters
    ----------
    dataset : Dataset
        An opened dataset (``simulator.dataset.io.open_dataset``).
    entry : str or mapping
        A resolved scenario estimator entry: a name (registered or ``module:Class``), or a
        mapping with ``name``, ``label``, ``init`` and ``config``.
    show_progress : bool
        Show a progress bar when stderr is a terminal.

    Returns
    -------
    solution : DataFrame
        ``t`` (strictly increasing) and the estimator's ``output_columns`` (SPEC section 7).
    info : dict
        ``label``, ``name``, ``runtime_s`` (wall time of the replay's message loop, s, less the
        time numba spent compiling kernels in it: ``simulator.compilation``),
        ``realtime_factor`` (data duration / runtime), ``uses_gnss`` (whether a GNSS stream
        reached the estimator) and ``compile_s`` (numba compilation during the run, s; 0 when
        the kernels came from the on-disk cache).

    Raises
    ------
    InputError
        Unknown estimator, failing plug-in import, bad config, missing needed stream.
    """
    name, label, init, config = _entry_fields(entry)
    cls = get_estimator(name)
    streams = _load_streams(dataset, cls, label)
    t, sid, idx = merge_streams([s.times for s in streams])
    if len(t) == 0:
        raise InputError([Problem(str(dataset.path), None, "", f"no messages for estimator "
                                  f"{name!r} in streams {[s.name for s in streams]}")])
    initial = None
    if not cls.initialises_itself:
        if not dataset.has("truth"):
            raise InputError([Problem(str(dataset.path), None, "", f"estimator {name!r} starts "
                                      "from the true state, and the dataset has no truth "
                                      "stream; use an estimator that initialises itself")])
        initial = initial_state(dataset.read("truth"), float(t[0]), init,
                                dataset.manifest.get("sensors"))
    with CompileWatch(label) as compiling:
        try:
            estimator = cls(config, initial, {s.name: s.columns for s in streams},
                            {s.name: s.units for s in streams}, imu_output=imu_output(dataset),
                            datasheet=dataset.manifest.get("datasheet"))
        except BaseException as exc:
            failure = _plugin_failure(cls, "setup", None, exc)
            if failure is None:
                raise
            raise failure from None
        gnss = [i for i, s in enumerate(streams) if s.name in GNSS_STREAMS]
        rows = (t[-1] - t[0]) * float(cls.output_rate_hz) + np.isin(sid, gnss).sum()
        if rows > MAX_SOLUTION_ROWS:
            raise InputError([Problem(str(dataset.path), None, "", f"the streams span "
                                      f"{t[-1] - t[0]:.6g} s: at {cls.output_rate_hz:g} Hz "
                                      f"that is {rows:.3g} solution rows, more than one replay "
                                      f"may hold ({MAX_SOLUTION_ROWS:,}); a gap in the times, "
                                      "or a drive to split into shorter datasets")])
        out_t, upto = output_times(t, sid, gnss, float(cls.output_rate_hz))
        out = np.full((len(out_t), len(cls.output_columns)), np.nan)
        kept = np.zeros(len(out_t), dtype=bool)

        handlers = [getattr(estimator, f"on_{s.name}") for s in streams]
        messages = [s.messages for s in streams]
        t_list, sid_list, idx_list = t.tolist(), sid.tolist(), idx.tolist()
        solution = estimator.solution
        compiled_before = compiling.seconds
        start = time.perf_counter()
        k = 0
        asks = zip(out_t.tolist(), upto.tolist(), strict=True)
        asking: float | None = None  # the solution time being asked for, else None (a message)
        try:
            for j, (t_out, n_before) in enumerate(progress(asks, label, show_progress,
                                                           len(out_t))):
                while k < n_before:
                    s = sid_list[k]
                    handlers[s](t_list[k], messages[s][idx_list[k]])
                    k += 1
                asking = t_out
                row = solution(t_out)
                asking = None
                if row is not None:
                    out[j] = _solution_row(row, cls, t_out)
                    kept[j] = True
        except BaseException as exc:  # which call failed follows from where the loop stood
            method, at = (("solution", asking) if asking is not None
                          else (f"on_{streams[sid_list[k]].name}", t_list[k]))
            failure = _plugin_failure(cls, method, at, exc)
            if failure is None:
                raise
            raise failure from None
        runtime = time.perf_counter() - start - (compiling.seconds - compiled_before)
    position = out[kept][:, [cls.output_columns.index("lat"), cls.output_columns.index("lon")]]
    if not np.isfinite(position).all(axis=1).any():
        raise InputError([Problem(_where(cls), None, "", "gave no solution row with a position "
                                  f"over the whole dataset ({int(kept.sum())} row(s), all "
                                  "without lat/lon); nothing to score")])

    frame = pd.DataFrame(out[kept], columns=list(cls.output_columns))
    frame.insert(0, "t", out_t[kept])
    duration = float(t[-1] - t[0])
    info = {"label": label, "name": name, "runtime_s": runtime,
            "realtime_factor": duration / runtime if runtime > 0 else float("inf"),
            "uses_gnss": bool(gnss), "compile_s": compiling.seconds}
    return frame, info


def _where(cls: type) -> str:
    return f"estimator {cls.name!r} ({cls.__module__}.{cls.__qualname__})"


def _plugin_failure(cls: type, method: str, t: float | None,
                    exc: BaseException) -> InputError | None:
    """What a plug-in raised (``sys.exit`` included) as one ``InputError`` naming the estimator,
    the call, the message time and the reason, with the line of the estimator's code where it
    happened; None for what must pass through (input errors, interruptions)."""
    if isinstance(exc, (InputError, KeyboardInterrupt, Terminated)):
        return None
    when = "" if t is None else f" at t = {t:.6f} s"
    if isinstance(exc, SystemExit):
        reason = f"called sys.exit({exc.code!r}); an estimator must return, not exit"
    else:
        reason = f"{type(exc).__name__}: {exc}"
        frames = [f for f in traceback.extract_tb(exc.__traceback__)
                  if Path(f.filename).resolve() != Path(__file__).resolve()]
        if frames:
            reason += f" ({frames[-1].filename}:{frames[-1].lineno})"
    return InputError([Problem(_where(cls), None, "", f"failed in {method}(){when}: {reason}")])


def _solution_row(row: Any, cls: type, t: float) -> np.ndarray:
    """A solution row as floats, or InputError saying what the estimator returned instead."""
    n = len(cls.output_columns)
    try:
        values = np.asarray(row, dtype=float)
    except (TypeError, ValueError):
        values = None
    if values is None or values.shape != (n,):
        got = (f"a {type(row).__name__}" if values is None or values.ndim != 1
               else f"{values.size} values")
        raise InputError([Problem(_where(cls), None, "",
                                  f"solution({t:.6f}) returned {got}; it must return None or "
                                  f"{n} numbers, one per output column "
                                  f"({', '.join(cls.output_columns)})")])
    return values


def _seconds(t: float) -> str:
    """A time for a message: to the microsecond, or in 6 digits beyond 1e12 s."""
    return f"{t:.6f}" if abs(t) < 1e12 else f"{t:.6g}"


def solution_problems(frame: pd.DataFrame) -> list[str]:
    """What makes a table not a solution (docs/solution-format.md): missing columns, t not
    finite or not increasing; empty when it is one."""
    missing = [c for c in col.SOLUTION if c not in frame.columns]
    if missing:
        return [f"missing column(s) {', '.join(missing)} (a solution needs "
                f"{', '.join(col.SOLUTION)})"]
    t = frame["t"].to_numpy(dtype=float)
    if np.any(~np.isfinite(t)):
        return ["column t has missing or non-finite values"]
    bad = np.flatnonzero(np.diff(t) <= 0)
    if len(bad):
        i = int(bad[0])
        return [f"t is not increasing: row {i + 1} has t = {_seconds(t[i + 1])} s after "
                f"t = {_seconds(t[i])} s"]
    return []


USES_GNSS_KEY = "landnav.uses_gnss"  # Parquet schema metadata of a solution: "true" / "false"


def write_solution(frame: pd.DataFrame, path: str | Path, force: bool = False,
                   inputs: Iterable[Path | str] = (), uses_gnss: bool | None = None) -> None:
    """Write a solution table as Parquet (docs/solution-format.md), atomically; extra columns
    get unit "". An existing file is replaced only with ``force``; a path inside one of
    ``inputs`` (the dataset read) is refused. ``uses_gnss`` (whether the estimator had GNSS) is
    kept in the schema metadata, so that scoring the file later leaves out the outage scores of
    an estimator without GNSS, as scoring the run did."""
    problems = solution_problems(frame)
    if problems:
        raise InputError([Problem(str(path), None, "", p) for p in problems])
    units = {**col.SOLUTION, **col.SOLUTION_STD, **col.SENSOR_ERRORS}
    metadata = None if uses_gnss is None else {USES_GNSS_KEY: "true" if uses_gnss else "false"}
    with atomic_output_file(path, force, inputs, "parquet") as tmp:
        write_table(frame, tmp, {c: units.get(c, "") for c in frame.columns}, metadata)


def read_solution(path: str | Path) -> pd.DataFrame:
    """Read a solution file written by landnav or any other program.

    Raises
    ------
    InputError
        Naming the file, when it is unreadable, lacks a required column or its ``t`` does not
        increase.
    """
    frame = read_table(Path(path))
    problems = solution_problems(frame)
    if problems:
        raise InputError([Problem(str(path), None, "", p) for p in problems])
    return frame
