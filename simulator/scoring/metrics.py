"""The scores of one solution against the truth (docs/scores.md).

Per solution (metres, m/s, degrees for attitude; ``None`` where nothing could be scored):

* ``horizontal`` {rms, mean, max, cep50, cep95}: statistics of the horizontal error
  sqrt(err_n^2 + err_e^2); cep50 and cep95 are its empirical 50th and 95th percentiles (linear
  interpolation between order statistics): the radius of the circle about the truth that holds
  that share of the solution's epochs;
* ``vertical`` {rms, max}: of |err_d|;
* ``velocity`` {rms}: RMS of the 3-D velocity error norm;
* ``attitude`` {roll_rms, pitch_rms, yaw_rms}: RMS of the wrapped Euler-angle errors, deg;
* ``coverage`` {fraction, longest_gap}: the share of the drive from the solution's first row with
  a finite position to the end of the truth during which a row with a finite position lies
  within 1.5 output periods (the period is the median spacing of those rows), and the longest
  stretch without such a row (s), the stretch from the last row to the end of the drive
  included. A solution that stops during an outage is charged here as well as in ``outages``;
* ``outages`` (only for solutions that use GNSS; ``None`` for one that never does, such as
  odometer/gyro dead reckoning): one entry per ``gnss_outage`` row of the events table, over
  the solution rows with t_start <= t < t_end (the epoch at t_end already has GNSS again, and
  the replay's row at t_end follows that update): ``start`` (s), ``duration`` (s),
  ``distance`` (m travelled by the truth), ``max_horizontal`` (over the window's rows),
  ``end_horizontal`` (the error at the window's end time: the error of the window's last row,
  which must lie at most ``END_TOLERANCE_S`` = 1 s before t_end, else ``None``: a solution
  silent at the end of an outage has no end error), ``end_percent`` (end_horizontal as a
  percentage of distance; ``None`` without an end error or for a stationary outage) and
  ``coverage`` {fraction, longest_gap} (the share of the window within 1.5 output periods of
  a row, and its longest stretch without a row, s). An outage in which the solution has no row
  gets ``None`` entries, coverage 0 and the whole window as its gap (never left out);
* ``degraded`` (like ``outages``): one entry per window where GNSS is limited but not gone,
  the events of kinds ``gnss_satellite_limit`` and ``gnss_multipath`` and the zones whose sky
  is ``canyon``, with ``kind`` (the event kind, or ``canyon``) and ``satellites`` (the median
  ``num_sats`` of the receiver's fixes at the epochs inside the window; ``None`` without a
  ``gnss_fix`` stream), so that partial-outage protocols (Karamat et al. 2015; Chan et al.)
  are scored with no extra code;
* ``sensor_errors`` {column: {rms, final}} for every estimated sensor-error column of
  docs/solution-format.md that the dataset's ``truth_sensors`` also has: the RMS of the
  solution minus the true value over the rows where both are finite, and the last such error,
  in the column's own unit (rad/s, m/s^2, dimensionless, m, m/s);
* ``nees`` (only when the solution has ``std_*`` columns): over the whole drive, the mean
  normalised estimation error squared of each 3-axis group, e^T P^-1 e with the diagonal
  covariance of the 1-sigma columns
  (``position``: std_n/e/d, ``velocity``: std_vn/ve/vd, ``attitude``: std_roll/pitch/yaw;
  ``None`` for a group whose three columns are not all present), and ``expected`` = 3, its value
  for a consistent estimator (Bar-Shalom, Li and Kirubarajan 2001, section 5.4); the file gives
  no cross-covariances, so P is taken diagonal;
* ``rtk`` (only when the solution has ``fix_status``): ``simulator.scoring.rtk``.
* ``consistency`` (only when the solution has ``std_*`` columns) and ``nis`` (only when it has
  ``nis_gnss`` and ``nis_gnss_dof``): ``simulator.scoring.consistency``, after the solution's
  first ``CONSISTENCY_SKIP_S`` = 60 s;
* ``runtime`` {seconds, realtime_factor} when the estimator ran inside landnav;
* ``rows`` {total, outside_truth, position, velocity, attitude}: rows in the solution, rows
  dropped outside the truth's time span, and rows with the whole group (a position row: finite
  north and east errors; a velocity or attitude row: all three columns finite).

Every metric uses only the rows where the solution has the quantities it needs
(docs/solution-format.md: a quantity not estimated is NaN and is left out of its own metrics, not
of the others): the horizontal metrics, coverage and windows the rows with finite lat and lon,
the vertical ones finite alt, velocity all three of vn, ve, vd, each attitude angle its own
column (a 2-D filter with NaN height, roll and pitch still has its horizontal and yaw errors
scored).

Public functions
----------------
score_errors, score_solution, degraded_windows.

References
----------
Bar-Shalom, Li, Kirubarajan, *Estimation with Applications to Tracking and Navigation*, Wiley,
2001 (NEES and filter consistency). Karamat, Atia, Noureldin, "Performance Analysis of Code-Phase-
Based Relative GPS Positioning and Its Integration With Land Vehicle's Motion Sensors", IEEE
Sensors Journal 14(9), 2014 / Karamat et al. 2015 (partial GNSS outages with a limited number of
satellites, scored as windows).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from simulator import columns as col
from simulator.scoring.align import (
    ERR_ATT,
    ERR_H,
    ERR_POS,
    ERR_VEL,
    SolutionErrors,
    sensor_error_name,
)
from simulator.scoring.align import solution_errors as _solution_errors
from simulator.scoring.consistency import AXES, BLOCKS, block_nees, consistency_scores, nis_scores
from simulator.scoring.rtk import rtk_scores

OUTAGE_KIND = "gnss_outage"  # events.parquet kind of a stretch without any GNSS measurement
DEGRADED_KINDS = ("gnss_satellite_limit", "gnss_multipath")  # fault kinds that limit GNSS
CANYON = "canyon"  # the kind of a degraded window made by a zone with an urban-canyon sky
COVERAGE_PERIODS = 1.5  # a moment is covered when a row lies within this many output periods
END_TOLERANCE_S = 1.0  # a window's end error needs a row at most this long before its end, s
NEES_DOF = 3  # degrees of freedom of each NEES group (three axes)
_STD = tuple(col.SOLUTION_STD)


def _number(x: float) -> float | None:
    """A JSON-safe float: None for NaN or infinity."""
    x = float(x)
    return x if np.isfinite(x) else None


def _rms(x: np.ndarray) -> float | None:
    return _number(np.sqrt(np.mean(np.square(x)))) if x.size else None


def _max(x: np.ndarray) -> float | None:
    return _number(np.max(x)) if x.size else None


def _valid(errors: pd.DataFrame, names: tuple[str, ...]) -> np.ndarray:
    return np.isfinite(errors[list(names)].to_numpy(float)).all(axis=1)


def _horizontal(h: np.ndarray) -> dict:
    if not h.size:
        return dict.fromkeys(("rms", "mean", "max", "cep50", "cep95"))
    cep50, cep95 = np.percentile(h, [50.0, 95.0])
    return {"rms": _rms(h), "mean": _number(np.mean(h)), "max": _max(h),
            "cep50": _number(cep50), "cep95": _number(cep95)}


def _reach(t_valid: np.ndarray) -> float:
    """How far either side of its time a row covers: 1.5 output periods (median spacing)."""
    return COVERAGE_PERIODS * float(np.median(np.diff(t_valid))) if t_valid.size > 1 else 0.0


def _covered(t_valid: np.ndarray, reach: float, a: float, b: float) -> float:
    """Length of [a, b] within ``reach`` of a row: the union of the rows' intervals
    [t - reach, t + reach] clipped to [a, b] (starts and ends both increase, so each interval
    adds what it reaches beyond the next one's start)."""
    starts = np.clip(t_valid - reach, a, b)
    ends = np.clip(t_valid + reach, a, b)
    if not starts.size:
        return 0.0
    nxt = np.append(starts[1:], np.inf)
    return float(np.maximum(np.minimum(ends, nxt) - starts, 0.0).sum())


def _coverage(t_valid: np.ndarray, t_end: float) -> dict:
    """``coverage`` (module docstring) of the times of the rows with a finite position."""
    if t_valid.size == 0:
        return {"fraction": 0.0, "longest_gap": None}
    span = t_end - t_valid[0]
    longest = float(np.append(np.diff(t_valid), max(t_end - t_valid[-1], 0.0)).max())
    if span <= 0:
        return {"fraction": 1.0, "longest_gap": longest}
    covered = _covered(t_valid, _reach(t_valid), float(t_valid[0]), t_end)
    return {"fraction": float(min(covered / span, 1.0)), "longest_gap": longest}


def _window_coverage(t_valid: np.ndarray, t_start: float, t_end: float) -> dict:
    """``coverage`` {fraction, longest_gap} of one window: the share of [t_start, t_end] within
    1.5 output periods of a row, and the longest stretch of it without a row (s), from the
    window's start to its first row and from its last row to its end included."""
    duration = t_end - t_start
    if duration <= 0:
        return {"fraction": 1.0, "longest_gap": 0.0}
    inside = t_valid[(t_valid > t_start) & (t_valid < t_end)]
    longest = float(np.diff(np.concatenate(([t_start], inside, [t_end]))).max())
    fraction = _covered(t_valid, _reach(t_valid), t_start, t_end) / duration
    return {"fraction": float(min(fraction, 1.0)), "longest_gap": longest}


def _window_scores(t_start: float, t_end: float, t: np.ndarray, h: np.ndarray,
                   truth: pd.DataFrame) -> dict:
    """``start, duration, distance, max_horizontal, end_horizontal, end_percent, coverage`` of
    one window over the scored rows (times ``t``, horizontal errors ``h``) with
    t_start <= t < t_end (module docstring): the end error is the window's last row's, None
    when that row lies more than ``END_TOLERANCE_S`` before the end."""
    travelled = np.interp([t_start, t_end], truth["t"].to_numpy(float),
                          truth["distance"].to_numpy(float))
    distance = float(travelled[1] - travelled[0])
    rows = (t >= t_start) & (t < t_end)
    inside, t_inside = h[rows], t[rows]
    end = (_number(inside[-1]) if inside.size and t_end - t_inside[-1] <= END_TOLERANCE_S
           else None)
    return {"start": float(t_start), "duration": float(t_end - t_start), "distance": distance,
            "max_horizontal": _max(inside), "end_horizontal": end,
            "end_percent": None if end is None or distance <= 0 else 100.0 * end / distance,
            "coverage": _window_coverage(t, t_start, t_end)}


def degraded_windows(events: pd.DataFrame, canyon_zones: set[str] | frozenset[str] = frozenset()
                     ) -> pd.DataFrame:
    """The events rows where GNSS is limited but not gone, sorted by start, with a ``label``
    column: the fault kind, or ``canyon`` for a zone whose sky is an urban canyon."""
    is_fault = events["kind"].isin(DEGRADED_KINDS)
    is_canyon = (events["kind"] == "zone") & events["detail"].isin(canyon_zones)
    rows = events.loc[is_fault | is_canyon].copy()
    rows["label"] = np.where(rows["kind"] == "zone", CANYON, rows["kind"])
    return rows.sort_values("t_start", kind="stable")


def _satellites(t_start: float, t_end: float, fix: pd.DataFrame | None) -> float | None:
    if fix is None:
        return None
    t = fix["t"].to_numpy(float)
    inside = fix["num_sats"].to_numpy(float)[(t >= t_start) & (t < t_end)]
    return _number(np.median(inside)) if inside.size else None


def _sensor_errors(e: pd.DataFrame) -> dict:
    out = {}
    for name in col.SENSOR_ERRORS:
        err_name = sensor_error_name(name)
        if err_name in e:
            x = e[err_name].to_numpy(float)
            x = x[np.isfinite(x)]
            out[name] = {"rms": _rms(x), "final": _number(x[-1]) if x.size else None}
    return out


def _nees(errors: pd.DataFrame) -> dict:
    out: dict = {}
    for block in BLOCKS:
        nees = block_nees(errors, block)
        has = all(AXES[axis][1] in errors for axis in block.axes)
        out[block.name] = _number(np.nanmean(nees)) if has and np.isfinite(nees).any() else None
    out["expected"] = float(NEES_DOF)
    return out


def score_errors(errors: SolutionErrors, truth: pd.DataFrame, events: pd.DataFrame,
                 runtime: dict | None = None, *, uses_gnss: bool = True,
                 canyon_zones: set[str] | frozenset[str] = frozenset(),
                 gnss_fix: pd.DataFrame | None = None) -> dict:
    """The scores (module docstring) of one solution from its per-sample errors.

    Parameters
    ----------
    errors : SolutionErrors from ``align.solution_errors``.
    truth : DataFrame, ``truth.parquet`` (``t`` and ``distance`` are used here).
    events : DataFrame, ``events.parquet``.
    runtime : {"runtime_s", "realtime_factor"} of an estimator that ran inside landnav, or None.
    uses_gnss : whether the solution uses GNSS; without, ``outages`` and ``degraded`` are None.
    canyon_zones : names of the zones whose sky is an urban canyon (degraded windows).
    gnss_fix : the dataset's ``gnss_fix`` stream (for the satellites of degraded windows).

    Returns
    -------
    dict, JSON-ready (floats and None, no NaN).
    """
    e = errors.errors
    pos_ok, vel_ok = _valid(e, ERR_POS[:2]), _valid(e, ERR_VEL)
    h = e[ERR_H].to_numpy(float)[pos_ok]
    t = e["t"].to_numpy(float)[pos_ok]
    down = e[ERR_POS[2]].to_numpy(float)
    vertical = np.abs(down[np.isfinite(down)])
    vel = np.linalg.norm(e[list(ERR_VEL)].to_numpy(float)[vel_ok], axis=1)
    att = np.degrees(e[list(ERR_ATT)].to_numpy(float))
    att_ok = np.isfinite(att)
    scores: dict = {
        "horizontal": _horizontal(h),
        "vertical": {"rms": _rms(vertical), "max": _max(vertical)},
        "velocity": {"rms": _rms(vel)},
        "attitude": {f"{axis}_rms": _rms(att[att_ok[:, i], i])
                     for i, axis in enumerate(("roll", "pitch", "yaw"))},
        "coverage": _coverage(t, float(truth["t"].iloc[-1])),
        "outages": None,
        "degraded": None,
    }
    if uses_gnss:
        outages = events.loc[events["kind"] == OUTAGE_KIND].sort_values("t_start")
        scores["outages"] = [_window_scores(a, b, t, h, truth) for a, b in
                             zip(outages["t_start"], outages["t_end"], strict=True)]
        windows = degraded_windows(events, canyon_zones)
        scores["degraded"] = [
            {"kind": kind, **_window_scores(a, b, t, h, truth),
             "satellites": _satellites(a, b, gnss_fix)}
            for a, b, kind in zip(windows["t_start"], windows["t_end"], windows["label"],
                                  strict=True)]
    sensor_errors = _sensor_errors(e)
    if sensor_errors:
        scores["sensor_errors"] = sensor_errors
    if any(name in e.columns for name in _STD):
        scores["nees"] = _nees(e)
        scores["consistency"] = consistency_scores(e)
    nis = nis_scores(e)
    if nis is not None:
        scores["nis"] = nis
    if "fix_status" in e.columns:
        error_3d = np.sqrt(np.sum(e[list(ERR_POS)].to_numpy(float) ** 2, axis=1))
        outages = events.loc[events["kind"] == OUTAGE_KIND].sort_values("t_start")
        scores["rtk"] = rtk_scores(e["t"].to_numpy(float), error_3d,
                                   e["fix_status"].to_numpy(float),
                                   list(zip(outages["t_start"], outages["t_end"], strict=True)))
    if runtime is not None:
        scores["runtime"] = {"seconds": _number(runtime["runtime_s"]),
                             "realtime_factor": _number(runtime["realtime_factor"])}
    scores["rows"] = {"total": errors.total_rows, "outside_truth": errors.outside_truth,
                      "position": int(pos_ok.sum()), "velocity": int(vel_ok.sum()),
                      "attitude": int(att_ok.all(axis=1).sum())}
    return scores


def score_solution(truth: pd.DataFrame, events: pd.DataFrame, solution: pd.DataFrame,
                   runtime: dict | None = None, *, truth_sensors: pd.DataFrame | None = None,
                   **options: object) -> dict:
    """Score a solution table (docs/solution-format.md) against a dataset's truth and events tables
    (``options`` as for ``score_errors``)."""
    return score_errors(_solution_errors(truth, solution, truth_sensors), truth, events, runtime,
                        **options)
