"""Trajectory kind ``recorded``: drive the simulator along a logged drive, a time series of
positions read from CSV or Parquet and fitted into a smooth ``RoadProfile`` by the same code as
SUMO drives (``simulator.trajectory.fit``).

The scenario block::

    trajectory:
      kind: recorded
      file: drive.csv          # or .parquet; relative to the scenario file
      fit: {knot_spacing: 3.0, knot_time: null, time_window: null}

File columns: ``t`` (s, any origin, increasing), ``lat``, ``lon`` (deg), ``alt`` (m, ellipsoidal
height), optionally ``roll`` (rad) and ``zone`` (a zone name per row, empty outside zones). Other
columns (pitch, yaw, velocities) are allowed and ignored. The truth's attitude follows the
fitted road: yaw is the path heading and pitch the grade (a car does not slip), and roll is the
road bank minus ``limits.roll_gradient`` v^2 kappa. With a ``roll`` column, the bank is fitted
so that the truth's roll reproduces the logged roll: bank = roll + roll_gradient v^2 kappa at the
moving samples, smoothed along the road (P-spline, knots every ``_BANK_KNOTS_M`` or two sample
spacings). Rows with a missing
position are dropped. The drive starts at the first row: the scenario's ``start`` lat, lon, alt
and heading are replaced by the log's (``start.utc`` still sets the time).

For sparse logs the fit adapts to the sample interval dt (median): knots are at least 1.5 dt of
travel apart and the distance is smoothed over at least dt, so the path does not follow the
chords between samples.

Public names
------------
RECORDED_FIELD, LogError, read_log, build_recorded_profile.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from simulator.errors import not_regular
from simulator.schema import Context, Number, Record, Text
from simulator.trajectory.fit import (
    fit_along,
    fit_drive,
    local_frame,
    start_block,
    zone_intervals,
)
from simulator.trajectory.segments import RoadProfile

if TYPE_CHECKING:
    import pandas as pd

REQUIRED_COLUMNS = ("t", "lat", "lon", "alt")
_BANK_KNOTS_M = 10.0  # smallest knot spacing of the bank fitted to a logged roll, m
_BANK_MIN_SPEED = 1.0  # samples slower than this (m/s) do not set the bank

RECORDED_FIELD = Record({
    "file": Text(doc="CSV or Parquet log with columns t, lat, lon, alt (and optionally zone)"),
    "fit": Record({
        "knot_spacing": Number("m", 3.0, min=2.0, max=100.0,
                               doc="smallest knot spacing of the path splines"),
        "knot_time": Number("s", None, min=0, max=30.0,
                            doc="knots at least this much travel time apart (default: 1.5 dt)"),
        "time_window": Number("s", None, gt=0, max=30.0,
                              doc="half-width of the distance smoothing (default: dt, >= 0.5 s)"),
        "standstill_speed": Number("m/s", 0.05, min=0, max=2.0,
                                   doc="slower than this between two samples is standing"),
    }, default={}),
    "rate": Number("Hz", None, gt=0, max=10000,
                   doc="base rate of the truth table (default: the IMU rate, or 100 Hz)"),
})


class LogError(Exception):
    """A log that cannot be read or used; ``key`` names the scenario key at fault."""

    def __init__(self, key: tuple, message: str):
        super().__init__(message)
        self.key = key


def read_log(path: Path) -> pd.DataFrame:
    """The rows of a position log (CSV or Parquet) that have a complete position.

    Raises
    ------
    LogError
        Missing or unreadable file, missing columns, too few rows, times not increasing.
    """
    import pandas as pd

    kind = not_regular(path)
    if kind is not None:
        raise LogError(("file",), f"log file not found: {path}" if kind == "missing"
                       else f"log file {path} is {kind}, not a regular file")
    try:
        if path.suffix.lower() in (".parquet", ".pq"):
            table = pd.read_parquet(path)
        else:
            table = pd.read_csv(path)
    except Exception as exc:  # pandas and pyarrow raise many types for a malformed file
        raise LogError(("file",), f"cannot read {path}: {exc}") from None
    missing = [c for c in REQUIRED_COLUMNS if c not in table.columns]
    if missing:
        raise LogError(("file",), f"{path} lacks the column(s) {', '.join(missing)} "
                                  f"(needed: {', '.join(REQUIRED_COLUMNS)})")
    table = table.dropna(subset=list(REQUIRED_COLUMNS)).reset_index(drop=True)
    if len(table) < 4:
        raise LogError(("file",), f"{path} has fewer than 4 rows with a position")
    bad = np.flatnonzero(np.diff(table["t"].to_numpy(float)) <= 0)
    if len(bad):
        raise LogError(("file",), f"{path}: times must increase; row {bad[0] + 2} has "
                                  f"t = {table['t'].iloc[bad[0] + 1]!r} after "
                                  f"{table['t'].iloc[bad[0]]!r}")
    return table


def build_recorded_profile(scenario: dict, ctx: Context | None) -> RoadProfile | None:
    """The ``PROFILE_BUILDERS`` entry of kind ``recorded`` (see the module docstring).

    With a ``Context``, problems are reported there and None returned; without one, a
    ValueError is raised.
    """
    traj = scenario["trajectory"]
    base = Path(ctx.file).resolve().parent if ctx is not None else Path.cwd()
    traj["file"] = str((base / traj["file"]).resolve())
    fit = traj["fit"]
    try:
        log = read_log(Path(traj["file"]))
        t = log["t"].to_numpy(float)
        dt = float(np.median(np.diff(t)))
        frame = local_frame(np.radians(log["lat"].to_numpy(float)),
                            np.radians(log["lon"].to_numpy(float)), log["alt"].to_numpy(float))
        zone = (log["zone"].fillna("").astype(str).to_numpy(object) if "zone" in log.columns
                else np.full(len(t), "", dtype=object))
        knot_time = fit["knot_time"] if fit["knot_time"] is not None else max(0.4, 1.5 * dt)
        window = fit["time_window"] if fit["time_window"] is not None else max(0.5, dt)
        fitted = fit_drive(t, frame.enu, fit["knot_spacing"], window, knot_time,
                           standstill_m=fit["standstill_speed"] * dt,
                           zones=zone_intervals(t, zone), convergence=frame.convergence)
    except (LogError, ValueError) as exc:
        key = ("trajectory",) + (exc.key if isinstance(exc, LogError) else ())
        if ctx is None:
            raise ValueError(f"{'.'.join(key)}: {exc}") from None
        ctx.error(key, str(exc))
        return None
    if "roll" in log.columns:
        fitted.profile.bank = _bank_from_roll(fitted.profile, t - t[0],
                                              log["roll"].to_numpy(float),
                                              scenario["limits"]["roll_gradient"])
    fitted.profile.start = start_block(frame, fitted)
    return fitted.profile


def _bank_from_roll(profile: RoadProfile, t: np.ndarray, roll: np.ndarray,
                    roll_gradient: float):
    """Road bank along s that makes the kinematic roll (bank - roll_gradient v^2 kappa) the
    logged roll at the moving samples."""
    s = profile.distance_of_time(t)
    v = profile.distance_of_time(t, 1)
    use = (v > _BANK_MIN_SPEED) & np.isfinite(roll)
    use[1:] &= np.diff(s) > 0
    if use.sum() < 10:
        return profile.bank
    s, v, roll = s[use], v[use], roll[use]
    bank = roll + roll_gradient * v**2 * profile.curvature(s)
    spacing = max(_BANK_KNOTS_M, 2.0 * float(np.median(np.diff(s))))
    # resampled every metre along the whole road (held constant before the first and after
    # the last moving sample), so every knot interval of the spline has data
    grid = np.arange(0.0, float(profile.distance_of_time(t[-1])) + spacing, 1.0)
    return fit_along(grid, np.interp(grid, s, bank), spacing)
