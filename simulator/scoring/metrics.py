"""The scores of one solution against the truth (SPEC section 8).

Per solution (metres, m/s, degrees for attitude; ``None`` where nothing could be scored):

* ``horizontal`` {rms, mean, max, cep50, cep95}: statistics of the horizontal error
  sqrt(err_n^2 + err_e^2); cep50 and cep95 are its empirical 50th and 95th percentiles (linear
  interpolation between order statistics): the radius of the circle about the truth that holds
  that share of the solution's epochs;
* ``vertical`` {rms, max}: of |err_d|;
* ``velocity`` {rms}: RMS of the 3-D velocity error norm;
* ``attitude`` {roll_rms, pitch_rms, yaw_rms}: RMS of the wrapped Euler-angle errors, deg;
* ``outages``: one entry per ``gnss_outage`` row of the events table, over the solution rows
  with t_start <= t < t_end (the epoch at t_end already has GNSS again): ``start`` (s),
  ``duration`` (s), ``distance`` (m travelled by the truth), ``max_horizontal``,
  ``end_horizontal`` (the error of the last scored row before t_end) and ``end_percent``
  (end_horizontal as a percentage of distance; ``None`` for a stationary outage);
* ``nees`` (only when the solution has ``std_*`` columns): the mean normalised estimation error
  squared of each 3-axis group, e^T P^-1 e with the diagonal covariance of the 1-sigma columns
  (``position``: std_n/e/d, ``velocity``: std_vn/ve/vd, ``attitude``: std_roll/pitch/yaw;
  ``None`` for a group whose three columns are not all present), and ``expected`` = 3, its value
  for a consistent estimator (Bar-Shalom, Li and Kirubarajan 2001, section 5.4); the file gives
  no cross-covariances, so P is taken diagonal;
* ``runtime`` {seconds, realtime_factor} when the estimator ran inside landnav;
* ``rows`` {total, outside_truth, position, velocity, attitude}: rows in the solution, rows
  dropped outside the truth's time span, and rows scored in each group (a position row is
  scored when its north and east errors are finite, a velocity or attitude row when all three
  of its columns are; each attitude axis's RMS and the vertical error take the rows where that
  one column is finite, so a 2-D solution's NaN height, roll and pitch leave its horizontal
  and yaw scores intact).

Public functions
----------------
score_errors, score_solution.

References
----------
Bar-Shalom, Li, Kirubarajan, *Estimation with Applications to Tracking and Navigation*, Wiley,
2001 (NEES and filter consistency).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from simulator import columns as col
from simulator.scoring.align import ERR_ATT, ERR_H, ERR_POS, ERR_VEL, SolutionErrors
from simulator.scoring.align import solution_errors as _solution_errors

OUTAGE_KIND = "gnss_outage"  # events.parquet kind of a stretch without any GNSS measurement
NEES_DOF = 3  # degrees of freedom of each NEES group (three axes)
_STD = tuple(col.SOLUTION_STD)
_NEES_GROUPS = {"position": (ERR_POS, _STD[0:3]), "velocity": (ERR_VEL, _STD[3:6]),
                "attitude": (ERR_ATT, _STD[6:9])}


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


def _outages(errors: pd.DataFrame, position_ok: np.ndarray, events: pd.DataFrame,
             truth: pd.DataFrame) -> list[dict]:
    rows = events.loc[events["kind"] == OUTAGE_KIND].sort_values("t_start")
    t_truth = truth["t"].to_numpy(float)
    travelled = truth["distance"].to_numpy(float)
    t = errors["t"].to_numpy(float)[position_ok]
    h = errors[ERR_H].to_numpy(float)[position_ok]
    out = []
    for t_start, t_end in zip(rows["t_start"].to_numpy(float), rows["t_end"].to_numpy(float),
                              strict=True):
        distance = float(np.diff(np.interp([t_start, t_end], t_truth, travelled))[0])
        inside = h[(t >= t_start) & (t < t_end)]
        end = _number(inside[-1]) if inside.size else None
        out.append({
            "start": float(t_start), "duration": float(t_end - t_start), "distance": distance,
            "max_horizontal": _max(inside), "end_horizontal": end,
            "end_percent": None if end is None or distance <= 0 else 100.0 * end / distance,
        })
    return out


def _nees(errors: pd.DataFrame) -> dict:
    out: dict = {}
    for group, (err_names, std_names) in _NEES_GROUPS.items():
        if not set(std_names) <= set(errors.columns):
            out[group] = None
            continue
        e = errors[list(err_names)].to_numpy(float)
        s = errors[list(std_names)].to_numpy(float)
        ok = np.isfinite(e).all(axis=1) & np.isfinite(s).all(axis=1) & (s > 0).all(axis=1)
        out[group] = _number(np.mean(np.sum((e[ok] / s[ok]) ** 2, axis=1))) if ok.any() else None
    out["expected"] = float(NEES_DOF)
    return out


def score_errors(errors: SolutionErrors, truth: pd.DataFrame, events: pd.DataFrame,
                 runtime: dict | None = None) -> dict:
    """The scores (module docstring) of one solution from its per-sample errors.

    Parameters
    ----------
    errors : SolutionErrors from ``align.solution_errors``.
    truth : DataFrame, ``truth.parquet`` (``t`` and ``distance`` are used here).
    events : DataFrame, ``events.parquet``.
    runtime : {"runtime_s", "realtime_factor"} of an estimator that ran inside landnav, or None.

    Returns
    -------
    dict, JSON-ready (floats and None, no NaN).
    """
    e = errors.errors
    # each quantity is scored on the rows where it is finite (SPEC section 7: a 2-D filter
    # writes NaN height, roll and pitch, and its horizontal and yaw errors still count)
    pos_ok, vel_ok, att_ok = (_valid(e, names) for names in (ERR_POS[:2], ERR_VEL, ERR_ATT))
    h = e[ERR_H].to_numpy(float)[pos_ok]
    d = e[ERR_POS[2]].to_numpy(float)
    vertical = np.abs(d[pos_ok & np.isfinite(d)])
    vel = np.linalg.norm(e[list(ERR_VEL)].to_numpy(float)[vel_ok], axis=1)
    att = np.degrees(e[list(ERR_ATT)].to_numpy(float))
    scores: dict = {
        "horizontal": _horizontal(h),
        "vertical": {"rms": _rms(vertical), "max": _max(vertical)},
        "velocity": {"rms": _rms(vel)},
        "attitude": {f"{axis}_rms": _rms(att[np.isfinite(att[:, i]), i])
                     for i, axis in enumerate(("roll", "pitch", "yaw"))},
        "outages": _outages(e, pos_ok, events, truth),
    }
    if any(name in e.columns for name in _STD):
        scores["nees"] = _nees(e)
    if runtime is not None:
        scores["runtime"] = {"seconds": _number(runtime["runtime_s"]),
                             "realtime_factor": _number(runtime["realtime_factor"])}
    scores["rows"] = {"total": errors.total_rows, "outside_truth": errors.outside_truth,
                      "position": int(pos_ok.sum()), "velocity": int(vel_ok.sum()),
                      "attitude": int(att_ok.sum())}
    return scores


def score_solution(truth: pd.DataFrame, events: pd.DataFrame, solution: pd.DataFrame,
                   runtime: dict | None = None) -> dict:
    """Score a solution table (SPEC section 7) against a dataset's truth and events tables."""
    return score_errors(_solution_errors(truth, solution), truth, events, runtime)
