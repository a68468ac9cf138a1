"""Karamat, Atia, Noureldin 2015, "An Enhanced Error Model for EKF-Based Tightly-Coupled
Integration of GPS and Land Vehicle's Motion Sensors" (seeds/002): the partial-outage protocol of
issue 15 on ``scenarios/karamat2015_partial_outages.yaml`` (ten sites, each passed four times
with 3, 2, 1 and 0 satellites for 60 s), paired per seed.

One experiment, ``partial_outages`` (on the default automotive body since session 5, when the
filter began to mechanise the rear axle; it ran on a rigid body before): ``riss3d_tc_ekf`` as
the paper builds it (``tight``), its
loosely coupled variant on the receiver's fixes (``loose``, no GNSS below four satellites) and the
earlier error model the paper improves on (``simplified``), replaying the same dataset. Figures
per seed (``measure_protocol``):

* ``w{k}.satellites`` and ``LABEL.w{k}.max_h_m``: the maximum horizontal error inside window k
  (the paper's criterion, section 4.2), windows numbered by start;
* ``LABEL.sats{c}.mean_max_h_m``: their mean over the seed's windows with c satellites;
* ``tight.sats0.rms_{n,e,d}_m``: the RMS north, east, down errors over the 0-satellite windows
  (the quantity of the paper's Table 2, whose averages are 5.48, 4.65, 3.32 m);
* ``LABEL.gyro_bias_error_300s_deg_s``: the vertical-gyro bias estimate minus the true bias at
  300 s (``true_gyro_bias_z``).

``--quick`` keeps site 1 (390 s into loops 1-4: four windows after 390 s of open sky) and the
first four loops (``protocol_overrides``).

Claims and verdicts (issue 15's criteria decide "shown"; ``measures`` for the words):

* section 4.3.1: the mean over the windows of the maximum horizontal error is under 12 m at every
  satellite count ("partly": at some counts);
* issue 15: tight beats ``coupling: loose`` in at least 80 % of the windows with 1-3 satellites,
  paired per window ("partly": in at least half);
* sections 4.3.1 and 5: the enhanced model's gain over the earlier one, one minus the ratio of the
  means of the window maxima, at least 16 % with no satellite and 40 % over all counts
  ("partly": a gain, smaller);
* section 4.3.3: the vertical-gyro bias estimate within 0.05 deg/s of the truth at 300 s, in
  every seed ("partly": in at least half).

Figures and analysis: docs/reproduction_karamat2015.md.

Public names
------------
PAPER, PROTOCOL, VARIANTS, COUNTS, LOOP_S, SITE1_OFFSET_S, protocol_overrides, measure_protocol,
true_gyro_bias_z, window_maxima, seed_maxima, window_wins, gain.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from functools import partial

import numpy as np
import pandas as pd
import yaml

from simulator.dataset.io import Dataset
from simulator.reproduce import measures as m
from simulator.reproduce.paper import Claim, Experiment, Figures, Paper, Verdict, scenario_path
from simulator.scoring.align import ERR_POS

__all__ = ["COUNTS", "LOOP_S", "PAPER", "PROTOCOL", "SITE1_OFFSET_S", "VARIANTS", "gain",
           "measure_protocol", "protocol_overrides", "seed_maxima", "true_gyro_bias_z",
           "window_maxima", "window_wins"]

SCENARIO = "karamat2015_partial_outages.yaml"
LOOP_S = 523.95  # one loop of the scenario's drive, s (the scenario's comment; a test checks it)
SITE1_OFFSET_S = 390.0  # site 1's windows: this far into loops 1-4
COUNTS = (3, 2, 1, 0)  # satellites left in a site's four passes
UNDER_M = 12.0  # section 4.3.1: "the maximum position error is always less than 12 m"
BIAS_AT_S = 300.0  # section 4.3.3: the gyro bias converges in about 300 s
BIAS_WITHIN_DEG_S = 0.05  # issue 15: within 0.05 deg/s of the truth by then
TRUE_BIAS_SMOOTH_S = 20.0
# the paper's P0 and Q (its Table 1 figures) and white R: ``tuning: paper``
VARIANTS = {"tight": {"tuning": "paper"}, "loose": {"coupling": "loose", "tuning": "paper"},
            "simplified": {"model": "simplified", "tuning": "paper"}}


def protocol_overrides(loops: int, site_offset_s: float | None = None) -> list[str]:
    """``--set`` overrides cutting the drive to its first ``loops`` loops with the windows that
    end within them, only those ``site_offset_s`` into a loop when given (site 1: 390 s)."""
    faults = yaml.safe_load(scenario_path(SCENARIO).read_text())["faults"]

    def keep(fault: dict) -> bool:
        if fault["start"] + fault["duration"] > loops * LOOP_S:
            return False
        if site_offset_s is None:
            return True
        phase = (fault["start"] - site_offset_s) / LOOP_S
        return abs(phase - round(phase)) < 1e-3

    return [f"trajectory.segments.0.repeat.times={loops}",
            f"faults={json.dumps([f for f in faults if keep(f)])}"]


def true_gyro_bias_z(dataset: Dataset, t: np.ndarray,
                     smooth_s: float = TRUE_BIAS_SMOOTH_S) -> np.ndarray:
    """The true z-gyro bias (rad/s, FRD) at times ``t``: the reading minus the true rate scaled
    by the run's drawn scale factor, averaged over ``smooth_s`` to remove the white noise. This
    is the effective bias a filter can estimate (the drawn turn-on and in-run bias with what the
    body's motion adds through g-sensitivity and misalignment), which
    ``truth_sensors.gyro_bias_z`` (the drawn bias alone) is not."""
    imu, truth = dataset.read("imu"), dataset.read("truth")
    scale_factor = dataset.manifest["sensors"]["imu"]["gyro"]["scale_factor"][2]
    t_imu = imu["t"].to_numpy()
    rate = np.interp(t_imu, truth["t"], truth["wz"])
    err = imu["gyro_z"].to_numpy() - (1.0 + scale_factor) * rate
    n = max(1, int(round(smooth_s / float(t_imu[1] - t_imu[0]))))
    smooth = np.convolve(err, np.ones(n) / n, mode="same")
    return np.interp(t, t_imu, smooth)


def measure_protocol(dataset: Dataset, solutions: Mapping[str, pd.DataFrame]) -> Figures:
    """The protocol's figures of one seed (module docstring)."""
    windows = m.satellite_windows(dataset.read("events"))
    counts = windows["satellites"].to_numpy()
    out: Figures = {f"w{k:02d}.satellites": float(c) for k, c in enumerate(counts)}
    bias_true = float(true_gyro_bias_z(dataset, np.array([BIAS_AT_S]))[0])
    for label, solution in solutions.items():
        e = m.errors(dataset, solution)
        t = e["t"].to_numpy()
        maxima = m.window_values(t, e["err_h"].to_numpy(), windows, np.max)
        out.update({f"{label}.w{k:02d}.max_h_m": float(x) for k, x in enumerate(maxima)})
        for c in np.unique(counts):
            out[f"{label}.sats{c}.mean_max_h_m"] = float(np.mean(maxima[counts == c]))
        if label == "tight" and np.any(counts == 0):
            inside = m.inside_windows(t, windows.loc[counts == 0, ["t_start", "t_end"]]
                                      .to_numpy(float))
            for axis, name in zip("ned", ERR_POS, strict=True):
                out[f"tight.sats0.rms_{axis}_m"] = float(
                    np.sqrt(np.nanmean(e[name].to_numpy()[inside] ** 2)))
        estimate = np.interp(BIAS_AT_S, solution["t"], solution["gyro_bias_z"])
        out[f"{label}.gyro_bias_error_300s_deg_s"] = float(np.degrees(estimate - bias_true))
    return out


def _window_keys(figures: pd.DataFrame, counts: Iterable[int]) -> list[str]:
    wanted = set(counts)
    return [c.split(".")[0] for c in figures.columns
            if c.endswith(".satellites") and set(figures[c].dropna().astype(int)) <= wanted
            and len(figures[c].dropna())]


def window_maxima(figures: pd.DataFrame, label: str, count: int) -> np.ndarray:
    """Every window maximum (m) of ``label`` with ``count`` satellites over all seeds."""
    keys = _window_keys(figures, [count])
    return figures[[f"{label}.{w}.max_h_m" for w in keys]].to_numpy(float).ravel()


def seed_maxima(figures: pd.DataFrame, label: str, count: int) -> np.ndarray:
    """Per seed, the mean of ``label``'s window maxima (m) with ``count`` satellites."""
    return figures[f"{label}.sats{count}.mean_max_h_m"].to_numpy(float)


def window_wins(figures: pd.DataFrame, a: str, b: str, counts: Iterable[int]) -> tuple[int, int]:
    """Windows (over seeds) with ``counts`` satellites where ``a``'s maximum is below ``b``'s,
    and the windows compared (``measures.paired_wins``)."""
    keys = _window_keys(figures, counts)
    return m.paired_wins(figures[[f"{a}.{w}.max_h_m" for w in keys]].to_numpy(float).ravel(),
                         figures[[f"{b}.{w}.max_h_m" for w in keys]].to_numpy(float).ravel())


def gain(figures: pd.DataFrame, counts: Iterable[int]) -> float:
    """The enhanced model's gain over the simplified one: 1 - enhanced / simplified, each the
    mean over ``counts`` of the mean over seeds of the per-seed window maxima (the paper's
    "improvement" in maximum horizontal error; its earlier filter is an LKF, here the same EKF
    with the earlier states)."""
    counts = list(counts)
    enhanced = np.mean([seed_maxima(figures, "tight", c).mean() for c in counts])
    simplified = np.mean([seed_maxima(figures, "simplified", c).mean() for c in counts])
    return float(1.0 - enhanced / simplified)


def judge_under_12(figures: Mapping[str, pd.DataFrame]) -> Verdict:
    """Section 4.3.1: the mean window maximum under 12 m at every satellite count."""
    table = figures["partial_outages"]
    means = {c: float(seed_maxima(table, "tight", c).mean()) for c in COUNTS}
    measured = "mean window maximum " + ", ".join(
        f"{means[c]:.1f} m ({c} sat.)" for c in COUNTS)
    if {f"tight.sats0.rms_{a}_m" for a in "ned"} <= set(table.columns):
        measured += ("; RMS N/E/D in the 0-satellite windows " + " / ".join(
            f"{table[f'tight.sats0.rms_{a}_m'].mean():.2f}" for a in "ned") + " m")
    under = [c for c in COUNTS if means[c] < UNDER_M]
    if len(under) == len(COUNTS):
        return Verdict("shown", measured, "under 12 m at 3, 2, 1 and 0 satellites")
    over = ", ".join(str(c) for c in COUNTS if c not in under)
    status = "partly" if under else "not shown"
    return Verdict(status, measured, f"over 12 m with {over} satellites: the synthetic loop's "
                   "sites include sharp turns and slopes that are harder to dead-reckon than "
                   "site 1 (docs/reproduction_karamat2015.md)")


def judge_tight_beats_loose(figures: Mapping[str, pd.DataFrame]) -> Verdict:
    """Issue 15: tight below loose in at least 80 % of the windows with 1-3 satellites."""
    table = figures["partial_outages"]
    wins, n = window_wins(table, "tight", "loose", (1, 2, 3))
    per_count = ", ".join("{} sat. {}/{}".format(c, *window_wins(table, "tight", "loose", [c]))
                          for c in (3, 2, 1))
    measured = f"tight better in {wins}/{n} windows ({100 * wins / max(n, 1):.0f} %; {per_count})"
    if n and wins >= 0.8 * n:
        return Verdict("shown", measured, "at least 80 % of the windows")
    status = "partly" if n and wins >= 0.5 * n else "not shown"
    return Verdict(status, measured, "below 80 %: with one satellite the two measurements are "
                   "mostly absorbed by the two clock states, so there is little to gain over "
                   "dead reckoning, and hard passes are hard for both variants "
                   "(docs/reproduction_karamat2015.md)")


def judge_gain(figures: Mapping[str, pd.DataFrame], counts: tuple[int, ...],
               least: float) -> Verdict:
    """The enhanced model's gain over the simplified one, at least ``least`` over ``counts``."""
    table = figures["partial_outages"]
    g = gain(table, counts)
    measured = f"gain {100 * g:.0f} %"
    if len(counts) > 1:
        measured += " (" + ", ".join(f"{100 * gain(table, [c]):.0f} % with {c}"
                                     for c in counts) + ")"
    if g >= least:
        return Verdict("shown", measured, f"at least {100 * least:.0f} %")
    status = "partly" if g > 0.0 else "not shown"
    return Verdict(status, measured, f"below {100 * least:.0f} %: the paper's earlier filter is "
                   "an LKF with an over-approximated model, here the same EKF with the earlier "
                   "states, so part of the paper's gain is in both (docs/"
                   "reproduction_karamat2015.md)")


def judge_gyro_bias(figures: Mapping[str, pd.DataFrame]) -> Verdict:
    """Section 4.3.3: |bias error| at 300 s below 0.05 deg/s in every seed."""
    err = figures["partial_outages"]["tight.gyro_bias_error_300s_deg_s"].to_numpy(float)
    ok = int(np.sum(np.abs(err) < BIAS_WITHIN_DEG_S))
    measured = f"error at 300 s {m.spread_text(err, 'deg/s')}"
    return m.count_verdict(ok, len(err), 1.0, measured, "within 0.05 deg/s at 300 s",
                           "the bias is observed only through the turns and the GNSS "
                           "updates, and some seeds' first 300 s turn little")


PROTOCOL = Experiment(
    "partial_outages", SCENARIO,
    {label: {"name": "riss3d_tc_ekf", "config": config} for label, config in VARIANTS.items()},
    measure_protocol,
    quick_overrides=tuple(protocol_overrides(4, SITE1_OFFSET_S)))

CONDITIONS = ("a synthetic drive of sixteen identical loops whose ten sites are three places of "
              "the loop (Kingston downtown is not available), the automotive body (side slip, "
              "suspension; docs/reproduction_karamat2015.md gives the rigid body's too), the "
              "IMU300CC preset with an assumed in-run Gauss-Markov bias, a 10 Hz ABS wheel-speed "
              "odometer (the paper: OBD-II), the highest satellites kept; the Gauss-Markov "
              "parameters (printed as lost images) chosen from Table 1",)

PAPER = Paper(
    key="karamat2015",
    title=("An Enhanced Error Model for EKF-Based Tightly-Coupled Integration of GPS and Land "
           "Vehicle's Motion Sensors"),
    citation=("Karamat, Atia, Noureldin, Sensors 15, 2015 (seeds/002); estimator riss3d_tc_ekf "
              "(model enhanced | simplified, coupling tight | loose)"),
    experiments=(PROTOCOL,),
    claims=(
        Claim("under_12_m", "On average the maximum horizontal error in a 60 s window is under "
              "12 m with 3, 2, 1 and 0 satellites", "< 12 m (section 4.3.1, Figure 8); RMS in "
              "full outages 5.48 / 4.65 / 3.32 m lat / lon / alt (Table 2 average)",
              CONDITIONS, judge_under_12),
        Claim("tight_beats_loose", "The tightly coupled filter beats coupling: loose in at "
              "least 80 % of the windows with 1-3 satellites (issue 15)",
              "TC better than LC in every case (Figures 8, 16; LC-LKF 57 % worse with 0)",
              (*CONDITIONS, "the loose variant is the same filter on the receiver's fixes"),
              judge_tight_beats_loose),
        Claim("enhanced_gain_0", "The enhanced model beats the earlier one with no satellite",
              "16 % better than TC-LKF (section 4.3.1)",
              (*CONDITIONS, "the earlier model is this EKF with its eleven earlier states"),
              partial(judge_gain, counts=(0,), least=0.16)),
        Claim("enhanced_gain_overall", "The enhanced model beats the earlier one in overall "
              "maximum horizontal error", "40 % (section 5)",
              (*CONDITIONS, "the earlier model is this EKF with its eleven earlier states"),
              partial(judge_gain, counts=COUNTS, least=0.40)),
        Claim("gyro_bias_300_s", "The vertical-gyro bias estimate is within 0.05 deg/s of the "
              "truth by 300 s", "converges to about -0.24 deg/s in about 300 s (section 4.3.3, "
              "Figure 13)", (*CONDITIONS, "the true bias is drawn from Table 1's 2 deg/s"),
              judge_gyro_bias),
    ),
)
