"""Chan et al., "Robust Navigation System for a Land Vehicle" (seeds/001): the claims of issue 15
on the shipped scenarios, paired per seed.

Experiments (each seed's dataset replayed by every entry):

* ``partial_outages`` (``chan_partial_outages.yaml``): ``tc_ukf`` with and without the
  non-holonomic constraint through 60 s windows leaving 0-4 satellites; per seed and satellite
  count, the mean over that count's windows of the mean 3-D position error inside each window
  (``measure_windows``). ``--quick`` keeps the warm-up and the first five windows, one per
  count (``short_partial_overrides``).
* ``complete_outages`` (``chan_complete_outages.yaml``): the same pair through three 60 s
  outages without any satellite (the 0-satellite row of Table 1 on its own drive).
* ``initial_error`` (``chan_initial_error.yaml``): both filters from 100 m of position error
  on each axis (told their 100 m uncertainty), and both from the truth on the same dataset
  (``measure_initial_error``: the time to settle below 10 m, and the RMS 3-D error).

Claims and verdicts (issue 15's criteria decide "shown"):

* Table 1: the NHC cuts the mean 3-D error over the windows (``table1``: one minus the ratio of
  the means over all seeds, as the paper's "average reduction") by >= 40 % with 0 satellites,
  >= 25 % with 1, 2 and 3, and with 4 by less than with 0 (paper: 54.4, 53.2, 52.6, 52.4,
  22.6 %). "partly" when the constraint still cuts the error (a positive pooled cut, and a
  positive cut in at least half of the seeds, as ``measures.count_verdict`` asks of a count)
  but by less than the criterion; "not shown" otherwise.
* Figure 2: from 100 m per axis both filters are below 10 m within 10 s and the UKF no later
  than the EKF + 1 s, in every seed ("partly": both settle within 10 s in every seed but the UKF
  is later in some, or both conditions hold in more than half of the seeds).
* Figure 1: on the nominal drive the median over seeds of the UKF's RMS over the EKF's lies in
  [0.8, 1.05] ("partly": the median is outside, but more than half of the seeds are inside).
* The complete-outage cut >= 40 % (the 0-satellite row of Table 1), judged as Table 1.

The errors are the scorer's (``simulator.scoring.align.solution_errors``: ECEF difference
against the truth interpolated at each solution time); a window is the half-open [start, end)
of its event, as faults act (docs/faults.md). Figures and analysis: docs/reproduction_chan.md.

Public names
------------
PAPER, PARTIAL_OUTAGES, COMPLETE_OUTAGES, INITIAL_ERROR, LEVER_ARM, short_partial_overrides,
short_complete_overrides, measure_windows, measure_initial_error, table1, judge_cut,
settle_time, initial_error_figures, run_filter.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from functools import partial

import numpy as np
import pandas as pd
import yaml

from simulator.dataset.io import Dataset
from simulator.replay import run_estimator
from simulator.reproduce import measures as m
from simulator.reproduce.paper import Claim, Experiment, Figures, Paper, Verdict, scenario_path

__all__ = ["COMPLETE_OUTAGES", "INITIAL_ERROR", "LEVER_ARM", "PAPER", "PARTIAL_OUTAGES",
           "initial_error_figures", "judge_cut", "measure_initial_error", "measure_windows",
           "run_filter", "settle_time", "short_complete_overrides", "short_partial_overrides",
           "table1"]

LEVER_ARM = [0.5, 0.0, -1.2]  # the Chan scenarios' antenna lever arm (body FRD), m
SETTLE_BOUND_M = 10.0  # Figure 2's criterion: below 10 m ...
SETTLE_WITHIN_S = 10.0  # ... within 10 s
SETTLE_SLACK_S = 1.0  # the UKF no later than the EKF + 1 s
RATIO_RANGE = (0.8, 1.05)  # nominal UKF RMS / EKF RMS
NHC, NO_NHC = "tc_ukf_nhc", "tc_ukf_no_nhc"
INIT_ERROR = {"position_error": [100.0, 100.0, 100.0]}  # NED, m: the paper's 100 m per axis


def _entry(name: str, **config) -> dict:
    """The reproduction's entry: the paper's setting (``tuning: paper``, the values chosen
    where the paper prints none) so that the figures do not move with the datasheet tuning."""
    return {"name": name, "config": {"lever_arm": LEVER_ARM, "tuning": "paper", **config}}


NHC_PAIR = {NHC: _entry("tc_ukf"), NO_NHC: _entry("tc_ukf", nhc=False)}
INITIAL_ERROR_ENTRIES = {
    "tc_ukf_init": {**_entry("tc_ukf", initial_position_std=100.0), "init": INIT_ERROR},
    "tc_ekf_init": {**_entry("tc_ekf", initial_position_std=100.0), "init": INIT_ERROR},
    "tc_ukf": _entry("tc_ukf"),
    "tc_ekf": _entry("tc_ekf"),
}


def run_filter(dataset: Dataset, name: str, **config) -> tuple[pd.DataFrame, np.ndarray]:
    """One replay of ``name`` (``tc_ukf``, ``tc_ekf``) with the Chan scenarios' lever arm and
    ``config``: its solution and the 3-D position error of each row (m)."""
    solution, _ = run_estimator(dataset, _entry(name, **config), show_progress=False)
    return solution, m.position_error_3d(dataset, solution)[1]


def short_partial_overrides(seed: int) -> list[str]:
    """``--set`` overrides cutting the partial-outage drive after its warm-up and first two and a
    half laps (straight, two loops, straight, two loops, straight) with its first five 60 s
    windows; the satellite counts are 0, 1, 2, 3, 4 in window order for even seeds, shifted by
    one window for odd seeds, so that over several seeds each count but 4 falls on straight and
    on curved road. (Halving the windows to 30 s instead does not keep the claim's meaning: the
    errors then stay at the 1-3 m of the pseudorange solution.)"""
    data = yaml.safe_load(scenario_path("chan_partial_outages.yaml").read_text())
    segments = data["trajectory"]["segments"]
    faults = data["faults"][:5]
    for k, fault in enumerate(faults):
        fault["count"] = (k + seed % 2) % 5
    return [f"trajectory.segments={json.dumps(segments[:12] + segments[-2:])}",
            f"faults={json.dumps(faults)}"]


def short_complete_overrides() -> list[str]:
    """``--set`` overrides cutting the complete-outage drive to its first outage (60 s from a
    straight into the first 40 m loop) and the loop the other way after it."""
    data = yaml.safe_load(scenario_path("chan_complete_outages.yaml").read_text())
    segments = data["trajectory"]["segments"]
    return [f"trajectory.segments={json.dumps(segments[:6] + segments[-2:])}",
            f"faults={json.dumps(data['faults'][:1])}"]


def measure_windows(dataset: Dataset, solutions: Mapping[str, pd.DataFrame]) -> Figures:
    """Per label and satellite count c: ``LABEL.sats{c}.mean_3d_m``, the mean over the count's
    windows of the mean 3-D position error inside each window (Table 1's quantity), and
    ``sats{c}.windows``, how many windows the count has (complete outages count as 0)."""
    windows = m.satellite_windows(dataset.read("events"))
    counts = windows["satellites"].to_numpy()
    out: Figures = {f"sats{c}.windows": float(np.sum(counts == c)) for c in np.unique(counts)}
    for label, solution in solutions.items():
        means = m.window_values(*m.position_error_3d(dataset, solution), windows, np.mean)
        for c in np.unique(counts):
            out[f"{label}.sats{c}.mean_3d_m"] = float(np.mean(means[counts == c]))
    return out


def settle_time(t: np.ndarray, error: np.ndarray, bound_m: float = SETTLE_BOUND_M) -> float:
    """Seconds from the first solution time ``t[0]`` until the error stays below ``bound_m``
    (0 when it never reaches the bound, inf when it is still above it at the end)."""
    above = np.flatnonzero(error >= bound_m)
    if len(above) == 0:
        return 0.0
    if above[-1] + 1 >= len(t):
        return float("inf")
    return float(t[above[-1] + 1] - t[0])


def measure_initial_error(dataset: Dataset, solutions: Mapping[str, pd.DataFrame]) -> Figures:
    """``LABEL.settle_s`` (``settle_time`` below 10 m) and ``LABEL.rms_3d_m`` (RMS 3-D error
    over the drive) of every label."""
    out: Figures = {}
    for label, solution in solutions.items():
        t, err = m.position_error_3d(dataset, solution)
        out[f"{label}.settle_s"] = settle_time(t, err)
        out[f"{label}.rms_3d_m"] = float(np.sqrt(np.mean(err**2)))
    return out


def table1(figures: pd.DataFrame) -> dict[int, dict[str, float]]:
    """Table 1 from the per-seed window figures (index seed, ``measure_windows``' columns): per
    satellite count, ``cut`` (%): one minus the mean over seeds with the NHC over the mean
    without (the paper's "average reduction"); ``median``, ``min``, ``max`` of the per-seed cuts;
    ``positive``: the share of seeds the NHC improves; ``nhc_m``, ``no_nhc_m``: the means."""
    out = {}
    counts = sorted(int(c.split(".")[1][4:]) for c in figures.columns
                    if c.startswith(NHC + ".sats"))
    for c in counts:
        a = figures[f"{NHC}.sats{c}.mean_3d_m"].to_numpy(float)
        b = figures[f"{NO_NHC}.sats{c}.mean_3d_m"].to_numpy(float)
        per_seed = 100.0 * (1.0 - a / b)
        out[c] = {"cut": float(100.0 * (1.0 - a.mean() / b.mean())),
                  "median": float(np.median(per_seed)), "min": float(per_seed.min()),
                  "max": float(per_seed.max()), "positive": float(np.mean(per_seed > 0.0)),
                  "nhc_m": float(a.mean()), "no_nhc_m": float(b.mean()), "seeds": len(a)}
    return out


def _cut_words(row: dict[str, float]) -> str:
    return (f"cut {row['cut']:.1f} % ({row['nhc_m']:.2f} m with the NHC vs {row['no_nhc_m']:.2f} "
            f"m without; per seed median {row['median']:.1f} %, {row['min']:.1f} to "
            f"{row['max']:.1f}; {round(row['positive'] * row['seeds'])}/{row['seeds']} seeds cut)")


def judge_cut(figures: Mapping[str, pd.DataFrame], experiment: str, count: int, least: float,
              why: str) -> Verdict:
    """The verdict on "the NHC cuts the mean 3-D error with ``count`` satellites by at least
    ``least`` %" on the pooled cut of ``table1`` and the seeds it cuts in (module docstring);
    ``why`` is the analysis given when it does not show."""
    rows = table1(figures[experiment])
    if count not in rows:
        return Verdict("not shown", "no window with this count", "the drive has none")
    row = rows[count]
    measured = _cut_words(row)
    if row["cut"] >= least:
        return Verdict("shown", measured, f"the pooled cut is at least {least:.0f} %")
    if row["cut"] > 0.0 and row["positive"] >= 0.5:
        return Verdict("partly", measured, f"the constraint cuts the error, by less than "
                       f"{least:.0f} %: {why}")
    return Verdict("not shown", measured, f"the constraint does not cut the error: {why}")


WHY_ALONG = ("with few satellites the remaining error is mostly along track, from the forward "
             "accelerometer's unmodelled scale factor and misalignment, which the constraint "
             "cannot reach (docs/reproduction_chan.md)")
WHY_GEOMETRY = ("with three pseudoranges and range rates the filter already bounds most of the "
                "drift, and the satellites kept are the highest (poor horizontal geometry; "
                "docs/reproduction_chan.md)")
WHY_SLIP = ("in the 40 m loops at 10 m/s the car's side slip is largest, and the constraint "
            "holds least there (docs/reproduction_chan.md)")


def judge_four_smaller(figures: Mapping[str, pd.DataFrame]) -> Verdict:
    """Table 1's last row: with 4 satellites the NHC's cut is smaller than with 0."""
    rows = table1(figures["partial_outages"])
    if 0 not in rows or 4 not in rows:
        return Verdict("not shown", "no figure", "the drive lacks a 0- or 4-satellite window")
    measured = f"{rows[4]['cut']:.1f} % with 4 satellites vs {rows[0]['cut']:.1f} % with 0"
    if rows[4]["cut"] < rows[0]["cut"]:
        return Verdict("shown", measured, "four satellites leave the constraint less to cut")
    return Verdict("not shown", measured, "the cut with 0 satellites is the smaller here: "
                   + WHY_ALONG)


def initial_error_figures(figures: pd.DataFrame) -> dict[str, np.ndarray]:
    """The per-seed arrays of the initial-error experiment: ``ukf_settle``, ``ekf_settle`` (s)
    and ``ratio`` (nominal RMS of the UKF over the EKF's)."""
    return {"ukf_settle": figures["tc_ukf_init.settle_s"].to_numpy(float),
            "ekf_settle": figures["tc_ekf_init.settle_s"].to_numpy(float),
            "ratio": (figures["tc_ukf.rms_3d_m"] / figures["tc_ekf.rms_3d_m"]).to_numpy(float)}


def judge_settling(figures: Mapping[str, pd.DataFrame]) -> Verdict:
    """Figure 2, in every seed: both below 10 m within 10 s and the UKF no later than the
    EKF + 1 s (``measures.count_verdict``: partly when at least half of the seeds meet it)."""
    f = initial_error_figures(figures["initial_error"])
    ukf, ekf = f["ukf_settle"], f["ekf_settle"]
    ok = (ukf <= SETTLE_WITHIN_S) & (ekf <= SETTLE_WITHIN_S) & (ukf <= ekf + SETTLE_SLACK_S)
    measured = (f"below 10 m after: UKF {m.spread_text(ukf, 's')}; EKF "
                f"{m.spread_text(ekf, 's')}; {m.count_text(int(ok.sum()), len(ok))} meet both")
    verdict = m.count_verdict(int(ok.sum()), len(ok), 1.0, measured,
                              "both settle within 10 s and the UKF no later than the EKF + 1 s",
                              "the filters settle late or the EKF first")
    if verdict.status == "shown" and np.all(ukf == ekf):
        return Verdict("shown", measured, verdict.reason + "; the UKF's advantage the paper "
                       "shows does not appear: 173 m is small against the ranges, so both pull "
                       "in at the first epochs")
    return verdict


def judge_nominal_ratio(figures: Mapping[str, pd.DataFrame]) -> Verdict:
    """Figure 1: the median over seeds of the nominal UKF RMS / EKF RMS in [0.8, 1.05];
    "partly" below 0.8 (the UKF better, as the paper says, but by more than slightly), "not
    shown" above 1.05 (the UKF worse)."""
    ratio = initial_error_figures(figures["initial_error"])["ratio"]
    lo, hi = RATIO_RANGE
    measured = f"UKF RMS / EKF RMS {m.spread_text(ratio)}"
    med = float(np.median(ratio))
    if lo <= med <= hi:
        return Verdict("shown", measured, f"the median {med:.3f} lies in [{lo}, {hi}]: land "
                       "navigation is mildly nonlinear, the two filters agree")
    if med < lo:
        return Verdict("partly", measured, f"the median {med:.3f} is below {lo}: the UKF is "
                       "better by more than the paper's 'slightly'")
    return Verdict("not shown", measured, f"the median {med:.3f} is above {hi}: the UKF is worse")


def _cut(count: int, least: float, why: str, experiment: str = "partial_outages") -> partial:
    return partial(judge_cut, experiment=experiment, count=count, least=least, why=why)


CONDITIONS = ("a synthetic drive (the paper's Seoul campus log is not available) with the "
              "automotive body (suspension, side slip), the automotive MEMS IMU preset (the paper "
              "names a 'low grade IMU'), the nominal GPS constellation (9 satellites in view; the "
              "partial-outage faults keep the highest ones), a TCXO clock; P0, Q, R and the NHC "
              "noise are landnav's choices (not printed)",)

PARTIAL_OUTAGES = Experiment("partial_outages", "chan_partial_outages.yaml", NHC_PAIR,
                             measure_windows,
                             quick_overrides=tuple(short_partial_overrides(0)))
COMPLETE_OUTAGES = Experiment("complete_outages", "chan_complete_outages.yaml", NHC_PAIR,
                              measure_windows, quick_overrides=tuple(short_complete_overrides()))
INITIAL_ERROR = Experiment("initial_error", "chan_initial_error.yaml", INITIAL_ERROR_ENTRIES,
                           measure_initial_error)

PAPER = Paper(
    key="chan",
    title="Robust Navigation System for a Land Vehicle",
    citation=("Ye Chan, Lwin Lwin Aung, Win Win Thar, Jang Gyu Lee, Pho Kaung: Robust Navigation "
              "System for a Land Vehicle (seeds/001); estimators tc_ukf and tc_ekf"),
    experiments=(PARTIAL_OUTAGES, COMPLETE_OUTAGES, INITIAL_ERROR),
    claims=(
        Claim("table1_0_satellites", "With no satellite the NHC cuts tc_ukf's mean 3-D error "
              "over the 60 s windows by at least 40 %", "54.4 % (Table 1)", CONDITIONS,
              _cut(0, 40.0, WHY_ALONG)),
        Claim("table1_1_satellite", "With 1 satellite the NHC cuts the mean 3-D error by at "
              "least 25 %", "53.2 % (Table 1)", CONDITIONS, _cut(1, 25.0, WHY_ALONG)),
        Claim("table1_2_satellites", "With 2 satellites the NHC cuts the mean 3-D error by at "
              "least 25 %", "52.6 % (Table 1)", CONDITIONS,
              _cut(2, 25.0, WHY_GEOMETRY)),
        Claim("table1_3_satellites", "With 3 satellites the NHC cuts the mean 3-D error by at "
              "least 25 %", "52.4 % (Table 1)", CONDITIONS,
              _cut(3, 25.0, WHY_GEOMETRY)),
        Claim("table1_4_satellites", "With 4 satellites the NHC's cut is smaller than with 0",
              "22.6 % vs 54.4 % (Table 1)", CONDITIONS, judge_four_smaller),
        Claim("complete_outages", "In complete 60 s outages (straight and loops) the NHC cuts "
              "the mean 3-D error by at least 40 %", "54.4 % (Table 1, Figures 3-4)",
              (*CONDITIONS, "three outages at fixed times, loops of 40 m radius"),
              _cut(0, 40.0, WHY_SLIP, "complete_outages")),
        Claim("initial_error_settling", "From 100 m of position error on each axis both "
              "filters are below 10 m within 10 s, the UKF no later than the EKF + 1 s",
              "the UKF converges faster than the EKF (Figure 2; no time printed)",
              (*CONDITIONS, "the 100 m are on north, east, down (the paper's on ECEF X, Y, Z: "
              "the same 173 m); both filters are told their 100 m uncertainty"),
              judge_settling),
        Claim("nominal_rms_ratio", "On a nominal drive the UKF's RMS 3-D error is 0.8 to 1.05 "
              "times the EKF's", "the UKF slightly better than the EKF (Figure 1)", CONDITIONS,
              judge_nominal_ratio),
    ),
)
