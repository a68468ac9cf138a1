"""Figures every paper module uses, written once: errors of a solution against the truth (through
``simulator.scoring``), windows from the events table, per-seed spreads in words, paired win
rates, and the verdict of a count or a median against a claim's criterion.

Errors against the truth are those of the scorer (``simulator.scoring.align.solution_errors``:
ECEF difference resolved in the NED frame of the true position, angles wrapped), so a claim's
figure and ``landnav score`` never disagree.

Verdict words (``simulator.reproduce.paper.Verdict``), the choice made here:

* a count criterion ("in at least 9 of 10 seeds") is scaled to the seeds run: at least
  ``ceil(fraction x n)`` of n. **shown** when met; **partly** when at least half of the seeds
  succeed but fewer than the criterion asks (the effect is there, not as reliably as claimed);
  **not shown** below half;
* a median criterion ("cut by at least 30 %") is judged on the median over seeds: **shown** when
  the median meets it; **partly** when the median is on the claimed side of no effect but short
  of the bound; **not shown** otherwise.

Public names
------------
errors, horizontal_error, outage_scores, moving_off, outages, longest_outage,
inside_windows, at_time, spread_text, count_text, paired_wins, win_rate_text, count_verdict,
median_verdict, needed_count, column, missing_count, least_count, paired_verdict,
position_error_3d, satellite_windows, window_values.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterable, Mapping, Sequence

import numpy as np
import pandas as pd

from simulator.dataset.io import Dataset
from simulator.reproduce.paper import Verdict
from simulator.scoring.align import ERR_H, ERR_POS, solution_errors
from simulator.scoring.evaluate import score_solutions
from simulator.scoring.metrics import OUTAGE_KIND

__all__ = ["at_time", "column", "count_text", "count_verdict", "errors", "horizontal_error",
           "inside_windows", "least_count", "longest_outage", "median_verdict",
           "missing_count", "moving_off", "needed_count", "outage_scores", "outages",
           "paired_verdict", "paired_wins", "position_error_3d", "satellite_windows",
           "spread_text", "win_rate_text", "window_values"]


# -- against the truth ----------------------------------------------------------------------

def errors(dataset: Dataset, solution: pd.DataFrame) -> pd.DataFrame:
    """Per-row errors of a solution against the dataset's truth: ``t``, ``err_n/e/d``, ``err_h``
    (m), velocity (m/s), ``err_roll/pitch/yaw`` (rad, wrapped) and ``err_<sensor error>``
    (``simulator.scoring.align.solution_errors``)."""
    truth_sensors = dataset.read("truth_sensors") if dataset.has("truth_sensors") else None
    return solution_errors(dataset.read("truth"), solution, truth_sensors).errors


def horizontal_error(dataset: Dataset, solution: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) and horizontal error (m) of a solution's rows inside the truth span."""
    e = errors(dataset, solution)
    return e["t"].to_numpy(), e[ERR_H].to_numpy()


def moving_off(truth: pd.DataFrame, speed_mps: float = 0.1) -> float:
    """Time (s) the truth first moves faster than ``speed_mps``."""
    return float(truth["t"].to_numpy()[np.argmax(truth["speed"].to_numpy() > speed_mps)])


def at_time(t: np.ndarray, values: np.ndarray, when_s: float) -> float:
    """``values`` linearly interpolated at ``when_s`` (s)."""
    return float(np.interp(when_s, t, values))


# -- windows from the events table ------------------------------------------------------------

def outages(events: pd.DataFrame) -> np.ndarray:
    """(start, end) times (s) of every GNSS outage of the events table, shape (n, 2)."""
    rows = events.loc[events["kind"] == OUTAGE_KIND, ["t_start", "t_end"]]
    return rows.to_numpy(float).reshape(-1, 2)


def longest_outage(events: pd.DataFrame) -> tuple[float, float]:
    """(start, end) (s) of the longest GNSS outage."""
    spans = outages(events)
    if not len(spans):
        raise ValueError("the dataset has no GNSS outage")
    t0, t1 = spans[np.argmax(spans[:, 1] - spans[:, 0])]
    return float(t0), float(t1)


def inside_windows(t: np.ndarray, windows: np.ndarray) -> np.ndarray:
    """Boolean mask of the times inside any [start, end) window."""
    mask = np.zeros(len(t), dtype=bool)
    for t0, t1 in windows:
        mask |= (t >= t0) & (t < t1)
    return mask


# -- over seeds ---------------------------------------------------------------------------------

def column(tables: dict[str, pd.DataFrame] | pd.DataFrame, name: str,
           experiment: str | None = None) -> np.ndarray:
    """The per-seed values of figure ``name`` (of ``experiment`` when given a mapping of
    experiment tables), one per seed that ran, in seed order: NaN where the seed has no figure
    (e.g. the scorer's none for a solution silent at an outage's end), counted by the texts
    and verdicts below, never dropped (two columns stay paired seed by seed)."""
    table = tables[experiment] if experiment is not None else tables
    return table[name].to_numpy(float) if name in table else np.array([])


def missing_count(*values: Sequence[float] | np.ndarray) -> int:
    """Seeds (positions) where any of the equally long ``values`` has no figure (NaN)."""
    present = np.ones(len(values[0]), dtype=bool)
    for v in values:
        present &= np.isfinite(np.asarray(v, float))
    return int((~present).sum())


def _without(missing: int) -> str:
    return f", {missing} without a figure" if missing else ""


def spread_text(values: Sequence[float] | np.ndarray, unit: str = "", digits: int = 3) -> str:
    """Median, interquartile range and extremes over seeds: ``median 17.8 m (IQR 12.1-25.0,
    range 9.0-31.2; 10 seeds)``, the seeds without a figure (NaN) counted:
    ``...; 8 seeds, 2 without a figure)``."""
    v = np.asarray(values, float)
    missing = missing_count(v)
    v = v[np.isfinite(v)]
    if not len(v):
        return f"no figure (none of {missing} seeds has one)" if missing else \
            "no figure (every seed failed)"
    q1, med, q3 = np.percentile(v, [25, 50, 75])
    u = f" {unit}" if unit else ""

    def f(x: float) -> str:
        return f"{x:.{digits}g}"

    return (f"median {f(med)}{u} (IQR {f(q1)}-{f(q3)}, range {f(v.min())}-{f(v.max())}; "
            f"{len(v)} seeds{_without(missing)})")


def count_text(successes: int, n: int) -> str:
    """``7/10 seeds``."""
    return f"{successes}/{n} seeds"


def paired_wins(a: np.ndarray, b: np.ndarray) -> tuple[int, int]:
    """Seeds where ``a`` is smaller than ``b`` (paired per seed; seeds where either is missing
    left out) and the number of seeds compared."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    ok = np.isfinite(a) & np.isfinite(b)
    return int(np.sum(a[ok] < b[ok])), int(ok.sum())


def win_rate_text(wins: int, n: int, who: str, missing: int = 0) -> str:
    """``dr3d_ekf better in 5/10 seeds (50 %)``, and ``, 2 without a figure`` for the seeds
    that could not be compared."""
    rate = f" ({100 * wins / n:.0f} %)" if n else ""
    return f"{who} better in {wins}/{n} seeds{rate}{_without(missing)}"


# -- verdicts -------------------------------------------------------------------------------

def needed_count(fraction: float, n: int) -> int:
    """Seeds out of ``n`` a criterion of ``fraction`` (9 of 10 -> 0.9) asks for."""
    return math.ceil(fraction * n - 1e-9)


def count_verdict(successes: int, n: int, fraction: float, measured: str, what: str,
                  analysis: str = "") -> Verdict:
    """The verdict on "``what`` in at least ``fraction`` of the seeds" (module docstring);
    ``analysis`` is added to the reason when the claim is not (fully) shown."""
    need = needed_count(fraction, n)
    if n == 0:
        return Verdict("not shown", measured, "no seed produced the figure")
    if successes >= need:
        return Verdict("shown", measured, f"{what} in {successes}/{n} seeds; the criterion "
                                          f"asks for {need}/{n}")
    status = "partly" if successes >= n / 2 else "not shown"
    reason = f"{what} in only {successes}/{n} seeds; the criterion asks for {need}/{n}"
    return Verdict(status, measured, f"{reason}. {analysis}".strip())


def median_verdict(values: Iterable[float], bound: float, better: str, no_effect: float,
                   measured: str, what: str, analysis: str = "") -> Verdict:
    """The verdict on "the median of ``what`` is ``better`` (``"above"`` or ``"below"``) than
    ``bound``", with ``no_effect`` the value meaning no effect at all (module docstring)."""
    v = np.asarray(list(values), float)
    missing = missing_count(v)
    v = v[np.isfinite(v)]
    if not len(v):
        return Verdict("not shown", measured, "no seed produced the figure")
    med = float(np.median(v))
    over = f" over {len(v)} seeds{_without(missing)}" if missing else ""
    sign = 1.0 if better == "above" else -1.0
    if sign * (med - bound) >= 0:
        return Verdict("shown", measured,
                       f"median {what} {med:.3g} is {better} {bound:g}{over}")
    status = "partly" if sign * (med - no_effect) > 0 else "not shown"
    reason = f"median {what} {med:.3g} is not {better} {bound:g}{over}"
    return Verdict(status, measured, f"{reason}. {analysis}".strip())


def outage_scores(dataset: Dataset, solution: pd.DataFrame) -> list[dict]:
    """The scorer's per-outage scores of a solution (SPEC section 8 ``outages``: ``start``,
    ``duration``, ``distance``, ``max_horizontal``, ``end_horizontal``, ``end_percent``), one
    entry per GNSS outage of the dataset's events."""
    return score_solutions(dataset, {"solution": (solution, None)}).results["solution"] \
        .scores["outages"]


def least_count(per: Mapping[str, np.ndarray], passes: Callable[[np.ndarray], np.ndarray]
                ) -> tuple[int, int]:
    """For a claim over several groups of per-seed values (filters, true values): the smallest
    number of seeds passing ``passes`` in any group, and the smallest number of seeds (a seed
    without a figure, NaN, is counted and fails any comparison)."""
    return (min(int(np.sum(passes(v))) for v in per.values()),
            min(len(v) for v in per.values()))


def paired_verdict(mine: np.ndarray, theirs: np.ndarray, names: tuple[str, str],
                   fraction: float, unit: str, what: str, analysis: str = "") -> Verdict:
    """The verdict on "``names[0]``'s figure is smaller than ``names[1]``'s in at least
    ``fraction`` of the seeds" (paired per seed), with both spreads and the win rate. A seed
    where either figure is missing counts as one where the claim is not met (never dropped)."""
    wins, n = paired_wins(mine, theirs)
    missing = missing_count(mine, theirs)
    measured = (f"{win_rate_text(wins, n, names[0], missing)}; {names[0]} "
                f"{spread_text(mine, unit)}; {names[1]} {spread_text(theirs, unit)}")
    return count_verdict(wins, n + missing, fraction, measured, what, analysis)


# -- partial-outage windows (Chan, Karamat) ----------------------------------------------------

SATELLITE_LIMIT_KIND = "gnss_satellite_limit"  # events.parquet kind of a partial outage


def position_error_3d(dataset: Dataset, solution: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) and 3-D position error (m, the norm of ``err_n/e/d``) of a solution's rows
    inside the truth span."""
    e = errors(dataset, solution)
    return e["t"].to_numpy(), np.linalg.norm(e[list(ERR_POS)].to_numpy(), axis=1)


def satellite_windows(events: pd.DataFrame) -> pd.DataFrame:
    """The partial-outage windows of an events table with the satellites each leaves: every
    ``gnss_satellite_limit`` row (its ``count``), and every GNSS outage that overlaps none of
    them as a 0-satellite window (a limit to 0 satellites is also an outage row: counted once,
    as the limit). Columns ``t_start``, ``t_end`` (s), ``satellites``; sorted by start."""
    limits = events.loc[events["kind"] == SATELLITE_LIMIT_KIND]
    rows = [(float(r.t_start), float(r.t_end), int(json.loads(r.detail)["count"]))
            for r in limits.itertuples()]
    for t0, t1 in outages(events):
        if not ((limits["t_start"] < t1) & (limits["t_end"] > t0)).any():
            rows.append((float(t0), float(t1), 0))
    table = pd.DataFrame(rows, columns=["t_start", "t_end", "satellites"])
    return table.sort_values("t_start", kind="stable").reset_index(drop=True)


def window_values(t: np.ndarray, values: np.ndarray, windows: pd.DataFrame,
                  reduce: Callable[[np.ndarray], float]) -> np.ndarray:
    """``reduce`` (``np.mean``, ``np.max``, ...) of the ``values`` at times ``t`` inside each
    [t_start, t_end) window of ``windows``, one per window (NaN for a window without a row)."""
    out = np.full(len(windows), np.nan)
    for k, (t0, t1) in enumerate(windows[["t_start", "t_end"]].to_numpy(float)):
        inside = values[(t >= t0) & (t < t1)]
        if inside.size:
            out[k] = float(reduce(inside))
    return out
