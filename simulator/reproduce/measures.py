"""Figures every paper module uses, written once: errors of a solution against the truth (through
``simulator.scoring``), windows from the events table, per-seed spreads in words, paired win
rates, and the verdict of a count or a median against a claim's criterion.

Errors against the truth are those of the scorer (``simulator.scoring.align.solution_errors``:
ECEF difference resolved in the NED frame of the true position, angles wrapped), so a claim's
figure and ``landnav score`` never disagree.

Verdict words follow one rule (``simulator.reproduce.evidence``): a claim's per-seed values give
the evidence (paired effect, bootstrap interval, sign test in the paper's direction) and the word
follows from it. ``paired_judgement`` and ``threshold_judgement`` build such a verdict with its
per-seed values; ``count_verdict``, ``median_verdict`` and ``paired_verdict`` express the older
count and median criteria through the same rule (the count or median bound is the magnitude).

Public names
------------
errors, horizontal_error, outage_scores, moving_off, outages, longest_outage,
inside_windows, at_time, spread_text, count_text, paired_wins, win_rate_text, evidence_verdict,
paired_judgement, threshold_judgement, count_verdict, median_verdict, needed_count, column,
missing_count, least_count, listed, paired_verdict, position_error_3d, satellite_windows,
window_values.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Literal

import numpy as np
import pandas as pd

from simulator.dataset.io import Dataset
from simulator.reproduce import evidence as ev
from simulator.reproduce.paper import Verdict
from simulator.scoring.align import ERR_H, ERR_POS, solution_errors
from simulator.scoring.evaluate import score_solutions
from simulator.scoring.metrics import OUTAGE_KIND

__all__ = ["at_time", "column", "count_text", "count_verdict", "errors", "evidence_verdict",
           "horizontal_error", "inside_windows", "least_count", "listed", "longest_outage",
           "median_verdict", "missing_count", "moving_off", "needed_count", "outage_scores",
           "outages", "paired_judgement", "paired_verdict", "paired_wins", "position_error_3d",
           "satellite_windows", "spread_text", "threshold_judgement", "win_rate_text",
           "window_values"]


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


def _with(reason: str, analysis: str) -> str:
    return f"{reason}. {analysis}".strip() if analysis else reason


def listed(values: Sequence[float] | np.ndarray) -> list[float | None]:
    """Per-seed values for ``Verdict.per_seed``: floats, None where a seed has none."""
    return [float(v) if np.isfinite(v) else None for v in np.asarray(values, float)]


def evidence_verdict(evidence: ev.Evidence, per_seed: Mapping[str, Sequence[float] | np.ndarray],
                     measured: str, what: str, magnitude: ev.Magnitude | None = None,
                     analysis: str = "", compared: tuple[str, ...] = ()) -> Verdict:
    """The verdict the documented rule gives (``evidence.verdict_word``) on ``evidence``, with
    the per-seed values it came from (``compared`` names the ones the evidence compares: by
    default the first one or two of ``per_seed``), the evidence in words and, when the claim is
    not shown, ``analysis``."""
    ok = magnitude.holds(evidence) if magnitude is not None else None
    status = ev.verdict_word(evidence, magnitude_ok=ok)
    reason = f"{what}: {ev.evidence_text(evidence)}"
    if magnitude is not None:
        reason += f"; magnitude ({magnitude.text}) {'met' if ok else 'not met'}"
    return Verdict(status, measured, _with(reason, analysis if status != "shown" else ""),
                   evidence, {k: listed(v) for k, v in per_seed.items()}, magnitude,
                   compared)


def paired_judgement(per_seed: Mapping[str, Sequence[float] | np.ndarray], a: str, b: str, *,
                     better: ev.Better, kind: Literal["difference", "ratio"], unit: str,
                     what: str, magnitude: ev.Magnitude | None = None,
                     analysis: str = "") -> Verdict:
    """The verdict on "``a`` is better than ``b``" (entries of ``per_seed``, paired per seed):
    both spreads, the evidence and the rule's word."""
    evidence = ev.paired_evidence(per_seed[a], per_seed[b], better=better, kind=kind, unit=unit)
    measured = f"{a} {spread_text(per_seed[a], unit)}; {b} {spread_text(per_seed[b], unit)}"
    return evidence_verdict(evidence, per_seed, measured, what, magnitude, analysis, (a, b))


def threshold_judgement(per_seed: Mapping[str, Sequence[float] | np.ndarray], name: str, *,
                        threshold: float, better: ev.Better, unit: str, what: str,
                        magnitude: ev.Magnitude | None = None, analysis: str = "") -> Verdict:
    """The verdict on "``name``'s values are better than ``threshold``" (``better``: lower or
    higher), seed by seed: the spread, the evidence and the rule's word."""
    evidence = ev.one_sample_evidence(per_seed[name], threshold=threshold, better=better,
                                      unit=unit)
    measured = f"{name} {spread_text(per_seed[name], unit)}"
    return evidence_verdict(evidence, per_seed, measured, what, magnitude, analysis, (name,))


def count_verdict(successes: int, n: int, fraction: float, measured: str, what: str,
                  analysis: str = "") -> Verdict:
    """The verdict on "``what``" from how many of ``n`` seeds meet it: the sign test on the
    per-seed indicators (1 met, 0 not) against one half (``fraction``, the old count criterion,
    is no longer the rule; kept for the callers' signature)."""
    indicators = np.array([1.0] * successes + [0.0] * (n - successes))
    evidence = ev.one_sample_evidence(indicators, threshold=0.5, better="higher")
    return evidence_verdict(evidence, {f"{what} (1 met, 0 not; seeds in any order)": indicators},
                            measured, f"{what} in {successes}/{n} seeds", None, analysis)


def median_verdict(values: Iterable[float], bound: float, better: str, no_effect: float,
                   measured: str, what: str, analysis: str = "") -> Verdict:
    """The verdict on "``what`` is ``better`` (``"above"`` or ``"below"``) than ``no_effect``,
    by at least ``bound`` in the median": the sign test of the per-seed values against
    ``no_effect``, the magnitude the median against ``bound``."""
    v = np.asarray(list(values), float)
    side: ev.Better = "higher" if better == "above" else "lower"
    evidence = ev.one_sample_evidence(v, threshold=no_effect, better=side)
    magnitude = (ev.Magnitude(f"median {better} {bound:g}", low=bound) if better == "above"
                 else ev.Magnitude(f"median {better} {bound:g}", high=bound))
    return evidence_verdict(evidence, {what: v}, measured, what, magnitude, analysis)


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
    """The verdict on "``names[0]``'s figure is smaller than ``names[1]``'s" (paired per seed,
    ``paired_judgement``; ``fraction``, the old count criterion, is no longer the rule). A seed
    where either figure is missing counts as one where the claim is not met."""
    return paired_judgement({names[0]: mine, names[1]: theirs}, names[0], names[1],
                            better="lower", kind="difference", unit=unit, what=what,
                            analysis=analysis)


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
