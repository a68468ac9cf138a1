"""Cho & Choi 2006 reproduced: the DRM1/DRM2 dead-reckoning filters (``dr2d_drm1_ekf``,
``dr2d_drm2_ekf``, ``dr2d_drm2_spkf``) on the shipped scenarios ``cho2006_situation1/2/3.yaml``
and ``cho2006_dr_outage.yaml``, every claim judged as the paper states it
(docs/reproduction_cho2006.md).

The conditions that decide verdicts are named and swept:

* **fix noise**: the paper's filters assume R = 15 m per position axis and 0.3 m/s on the speed
  (eq. 35) for fixes from MATLAB's GPS toolbox with thermal noise, troposphere and multipath;
  landnav's receiver smooths the code with the carrier and gives about 1 m per axis. The
  default of situations I-III is the paper's level: carrier smoothing off and the tracking noise
  scaled 15-fold (``PAPER_FIXES``: about 15 m per axis and 0.5 m/s, measured per seed as
  ``fixes.rms_axis_m``); the variants run landnav's own receiver (``LANDNAV_FIXES``) and an
  intermediate 5-fold scale (``FIVE_M_FIXES``, about 5 m);
* **the SPKF's point set**: the paper's scaled simplex set (L + 2 points, the default) and the
  symmetric 2L + 1 set as a reported variant (the simplex set's third moments move the
  unobservable z-gyro scale factor on the first straight road).

Figures per seed (``LABEL.figure``):

* situation I: ``LABEL.z_scale_converge_s`` and ``LABEL.accel_scale_converge_s``, the time
  (s from the start) after which the scale-factor estimate stays within ``CONVERGED_FRACTION``
  of its true value (the drive's end when it never does); ``LABEL.heading_rms_deg`` and
  ``LABEL.horizontal_rms_m`` from moving off to the end;
* situation II: ``LABEL.heading_rms_deg``, the heading RMS from ``SETTLE_S`` after moving off
  to the end; converged means below ``CONVERGED_DEG``;
* situation III: ``LABEL.outage_growth_m`` and ``LABEL.outage_heading_growth_deg``, how much
  the horizontal and absolute heading errors grow in the 75-90 s outage (largest inside minus
  the value at its start);
* DR outage: ``LABEL.dr_error_m``, the horizontal error ``DR_HORIZON_S`` after GNSS is lost,
  and, for the van runs (DRM2 from -70 and -140 deg), ``LABEL.before_outage_heading_rms_deg``;
* every experiment: ``fixes.rms_axis_m``, the fixes' RMS error per horizontal axis.

Public names
------------
PAPER, SITUATION1, SITUATION2, SITUATION3, DR_OUTAGE, CONVERGED_DEG, SETTLE_S, DR_HORIZON_S,
CONVERGED_FRACTION, PAPER_CONFIG, PAPER_FIXES, LANDNAV_FIXES, FIVE_M_FIXES, track_errors,
heading_label, converge_time, fix_rms.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from simulator.dataset.io import Dataset
from simulator.reproduce import measures as m
from simulator.reproduce.cho2006_figures import figures, history
from simulator.reproduce.evidence import Better
from simulator.reproduce.paper import Claim, Experiment, Figures, Paper, Verdict

CONVERGED_DEG = 3.0  # heading RMS below this from SETTLE_S after moving off: converged
SETTLE_S = 60.0
DR_HORIZON_S = 120.0  # stand-alone DR compared this long after GNSS is lost
CONVERGED_FRACTION = 0.5  # a scale-factor estimate has converged once its error stays
# below half the initial one (the true value: the filters start at 0)
SITUATION_INIT = {"attitude_error": [0.0, -5.0, -10.0]}  # situations I and III (pitch, heading)
SHORT = {"dr2d_drm1_ekf": "drm1", "dr2d_drm2_ekf": "ekf", "dr2d_drm2_spkf": "spkf"}
# the paper's P0, Q and R (eqs. 33-35), named so that the figures do not follow the default
PAPER_CONFIG = {"tuning": "paper"}
SYMMETRIC_CONFIG = {**PAPER_CONFIG, "sigma_set": "symmetric"}
# fixes at the paper's eq. 35 level: no carrier smoothing, tracking noise x15 (~15 m per axis)
PAPER_FIXES = ("sensors.gnss.carrier_smoothing=0", "sensors.gnss.tracking_noise=15")
FIVE_M_FIXES = ("sensors.gnss.carrier_smoothing=0", "sensors.gnss.tracking_noise=5")
LANDNAV_FIXES: tuple[str, ...] = ()  # the scenario's automotive receiver, carrier-smoothed
FIXES_WORDS = {PAPER_FIXES: "fixes at the paper's R level (about 15 m per axis)",
               FIVE_M_FIXES: "fixes of about 5 m per axis",
               LANDNAV_FIXES: "landnav's carrier-smoothed fixes (about 1 m per axis)"}
ANGLES_EKF = (-45.0, -90.0)  # the paper: the EKF performs well below 100 deg
FULL_RUNS = 20  # seeds of a full run for the experiments whose verdicts sit at an edge


def heading_label(name: str, angle_deg: float) -> str:
    """The entry label of ``name`` started with ``angle_deg`` heading error: ``spkf_m140``."""
    return f"{SHORT[name]}_{'m' if angle_deg < 0 else ''}{abs(angle_deg):.0f}"


def track_errors(dataset: Dataset, solution: pd.DataFrame
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times (s), horizontal error (m) and heading error (deg, wrapped) of a solution."""
    e = m.errors(dataset, solution)
    return e["t"].to_numpy(), e["err_h"].to_numpy(), np.degrees(e["err_yaw"].to_numpy())


def converge_time(t: np.ndarray, error: np.ndarray, tolerance: float, end_s: float) -> float:
    """The time (s) after which ``|error|`` stays below ``tolerance``: the first sample after
    the last one at or above it; ``end_s`` (the drive's end) when the last sample is not
    below (never converged: censored at the end, so a pair where neither converges ties)."""
    bad = ~(np.abs(error) < tolerance)
    if not bad.any():
        return float(t[0])
    last = int(np.flatnonzero(bad)[-1])
    return float(t[last + 1]) if last + 1 < len(t) else float(end_s)


def fix_rms(dataset: Dataset) -> float:
    """The fixes' RMS error per horizontal axis (m) against the truth."""
    fixes = dataset.read("gnss_fix")
    e = m.errors(dataset, fixes.assign(roll=np.nan, pitch=np.nan, yaw=np.nan))
    return float(np.sqrt(np.nanmean(np.concatenate([e["err_n"], e["err_e"]]) ** 2)))


def _heading_rms(dataset: Dataset, solutions: Mapping[str, pd.DataFrame]) -> Figures:
    settle = m.moving_off(dataset.read("truth")) + SETTLE_S
    out = {"fixes.rms_axis_m": fix_rms(dataset)}
    for label, solution in solutions.items():
        t, _, d_yaw = track_errors(dataset, solution)
        out[f"{label}.heading_rms_deg"] = float(np.sqrt(np.mean(d_yaw[t >= settle] ** 2)))
    return out


def _dr_error(dataset: Dataset, solutions: Mapping[str, pd.DataFrame]) -> Figures:
    start = m.outages(dataset.read("events"))[0, 0]
    moving = m.moving_off(dataset.read("truth"))
    out = {"fixes.rms_axis_m": fix_rms(dataset)}
    for label, solution in solutions.items():
        t, horizontal, d_yaw = track_errors(dataset, solution)
        out[f"{label}.dr_error_m"] = m.at_time(t, horizontal, start + DR_HORIZON_S)
        before = (t >= moving + 0.5 * (start - moving)) & (t < start)
        out[f"{label}.before_outage_heading_rms_deg"] = float(np.sqrt(np.mean(
            d_yaw[before] ** 2)))
    return out


def _situation1(dataset: Dataset, solutions: Mapping[str, pd.DataFrame]) -> Figures:
    imu = dataset.manifest["sensors"]["imu"]
    true_z, true_ax = imu["gyro"]["scale_factor"][2], imu["accel"]["scale_factor"][0]
    moving = m.moving_off(dataset.read("truth"))
    end = float(dataset.read("truth")["t"].iloc[-1])
    out = {"fixes.rms_axis_m": fix_rms(dataset)}
    for label, sol in solutions.items():
        t = sol["t"].to_numpy()
        out[f"{label}.z_scale_converge_s"] = converge_time(
            t, sol["gyro_scale_factor_z"].to_numpy() - true_z,
            CONVERGED_FRACTION * abs(true_z), end)
        out[f"{label}.accel_scale_converge_s"] = converge_time(
            t, sol["accel_scale_factor_x"].to_numpy() - true_ax,
            CONVERGED_FRACTION * abs(true_ax), end)
        te, horizontal, d_yaw = track_errors(dataset, sol)
        driving = te >= moving
        out[f"{label}.heading_rms_deg"] = float(np.sqrt(np.mean(d_yaw[driving] ** 2)))
        out[f"{label}.horizontal_rms_m"] = float(np.sqrt(np.mean(horizontal[driving] ** 2)))
    return out


def _outage_growth(dataset: Dataset, solutions: Mapping[str, pd.DataFrame]) -> Figures:
    t0, t1 = m.outages(dataset.read("events"))[0]
    out = {"fixes.rms_axis_m": fix_rms(dataset)}
    for label, solution in solutions.items():
        t, horizontal, d_yaw = track_errors(dataset, solution)
        span = (t >= t0) & (t <= t1)
        out[f"{label}.outage_growth_m"] = float(horizontal[span].max()
                                                - m.at_time(t, horizontal, t0))
        out[f"{label}.outage_heading_growth_deg"] = float(
            np.abs(d_yaw[span]).max() - abs(m.at_time(t, d_yaw, t0)))
    return out


def _drm2(init: Mapping, config: Mapping = PAPER_CONFIG, spkf: str = "dr2d_drm2_spkf"
          ) -> dict[str, dict]:
    return {"ekf": {"name": "dr2d_drm2_ekf", "init": init, "config": PAPER_CONFIG},
            "spkf": {"name": spkf, "init": init, "config": config}}


WITH_SYMMETRIC = {**_drm2(SITUATION_INIT),
                  "spkf_sym": {"name": "dr2d_drm2_spkf", "init": SITUATION_INIT,
                               "config": SYMMETRIC_CONFIG}}
SITUATION1 = Experiment(key="situation1", scenario="cho2006_situation1.yaml",
                        entries=WITH_SYMMETRIC, measure=_situation1, overrides=PAPER_FIXES,
                        history=history, full_runs=FULL_RUNS)
SITUATION1_LANDNAV_FIXES = Experiment(key="situation1_landnav_fixes",
                                      scenario="cho2006_situation1.yaml",
                                      entries=_drm2(SITUATION_INIT), measure=_situation1,
                                      full_runs=FULL_RUNS)
SITUATION2 = Experiment(
    key="situation2", scenario="cho2006_situation2.yaml",
    entries={
        **{heading_label("dr2d_drm1_ekf", a): {"name": "dr2d_drm1_ekf",
                                               "init": {"heading_error": a},
                                               "config": PAPER_CONFIG} for a in ANGLES_EKF},
        **{heading_label(name, a): {"name": name, "init": {"heading_error": a},
                                    "config": PAPER_CONFIG}
           for a in (*ANGLES_EKF, -140.0, -160.0)
           for name in ("dr2d_drm2_ekf", "dr2d_drm2_spkf")}},
    measure=_heading_rms, overrides=PAPER_FIXES, history=history)
SITUATION2_LANDNAV_FIXES = Experiment(
    key="situation2_landnav_fixes", scenario="cho2006_situation2.yaml",
    entries={heading_label(n, -140.0): {"name": n, "init": {"heading_error": -140.0},
                                        "config": PAPER_CONFIG}
             for n in ("dr2d_drm2_ekf", "dr2d_drm2_spkf")},
    measure=_heading_rms)
SITUATION3 = Experiment(key="situation3", scenario="cho2006_situation3.yaml",
                        entries=WITH_SYMMETRIC, measure=_outage_growth, overrides=PAPER_FIXES,
                        history=history, full_runs=FULL_RUNS)
SITUATION3_FIVE_M = Experiment(key="situation3_five_m_fixes",
                               scenario="cho2006_situation3.yaml", entries=_drm2(SITUATION_INIT),
                               measure=_outage_growth, overrides=FIVE_M_FIXES,
                               full_runs=FULL_RUNS)
SITUATION3_LANDNAV_FIXES = Experiment(key="situation3_landnav_fixes",
                                      scenario="cho2006_situation3.yaml",
                                      entries=_drm2(SITUATION_INIT), measure=_outage_growth,
                                      full_runs=FULL_RUNS)
DR_OUTAGE = Experiment(
    key="dr_outage", scenario="cho2006_dr_outage.yaml",
    entries={"drm1": {"name": "dr2d_drm1_ekf", "config": PAPER_CONFIG},
             "drm2": {"name": "dr2d_drm2_ekf", "config": PAPER_CONFIG},
             **{heading_label(n, a): {"name": n, "init": {"heading_error": a},
                                      "config": PAPER_CONFIG}
                for a in (-70.0, -140.0) for n in ("dr2d_drm2_ekf", "dr2d_drm2_spkf")}},
    measure=_dr_error, history=history)


# -- judges -------------------------------------------------------------------------------

def _per_seed(tables: Mapping[str, pd.DataFrame], experiment: str,
              names: Mapping[str, str]) -> dict[str, np.ndarray]:
    """Named per-seed values: display name -> column of ``experiment``'s table."""
    return {name: m.column(tables, figure, experiment) for name, figure in names.items()}


def paired(experiment: str, a: str, b: str, figure: str, unit: str, what: str,
           better: Better = "lower", analysis: str = ""):
    """A judge: ``a``'s ``figure`` better than ``b``'s per seed (labels of ``experiment``),
    with the fixes' measured noise beside them."""
    def judge(tables: Mapping[str, pd.DataFrame]) -> Verdict:
        per = _per_seed(tables, experiment, {f"{a} {figure}": f"{a}.{figure}",
                                             f"{b} {figure}": f"{b}.{figure}",
                                             "fix RMS per axis, m": "fixes.rms_axis_m"})
        return m.paired_judgement(per, f"{a} {figure}", f"{b} {figure}", better=better,
                                  kind="difference", unit=unit, what=what, analysis=analysis)
    return judge


def converged(experiment: str, labels: tuple[str, ...], what: str, better: Better = "lower"):
    """A judge: the worst (largest) heading RMS of ``labels`` per seed below
    ``CONVERGED_DEG`` (``better="lower"``: converges) or above it (``"higher"``: does not)."""
    def judge(tables: Mapping[str, pd.DataFrame]) -> Verdict:
        per = _per_seed(tables, experiment, {label: f"{label}.heading_rms_deg"
                                             for label in labels})
        worst = np.max(np.vstack(list(per.values())), axis=0)
        name = ("heading RMS, deg" if len(labels) == 1
                else f"largest heading RMS of {', '.join(labels)}, deg")
        return m.threshold_judgement({name: worst, **per}, name, threshold=CONVERGED_DEG,
                                     better=better, unit="deg", what=what)
    return judge


# -- claims -------------------------------------------------------------------------------

SIMULATED = ("a simulated drive of about 165 s in the paper's spirit (Fig. 6's profile is not "
             "printed): a 10 s standstill, acceleration, turns of 60 and 40 m radius, two 5 % "
             "slopes; rigid body (no lean)")
SENSORS = ("the Crossbow DMU-300CC preset (the paper's van unit; the simulation's sensor "
           "values are not printed): turn-on biases removed at the standstill, white noise, "
           "1 % scale factors drawn per seed; 100 Hz averaged to the 10 Hz DR")
GPS = "landnav's GPS receiver on the 24-slot nominal constellation instead of MATLAB's toolbox"
PAPER_FIXES_WORDS = ("fixes at the paper's R level (carrier smoothing off, tracking noise x15: "
                     "about 15 m per axis and 0.5 m/s; the paper's fix noise itself is not "
                     "printed)")
SIMPLEX = ("the simplex SPKF's alpha 0.3, w0 0, beta 2 are landnav's (the paper prints none)")
CONDITIONS = (SIMULATED, SENSORS, GPS, PAPER_FIXES_WORDS, SIMPLEX)
CONVERGE_WORDS = (f"converged: heading RMS below {CONVERGED_DEG:g} deg from {SETTLE_S:g} s "
                  "after moving off to the end (about 95 s of driving; the paper shows curves)")
SCALE_WORDS = ("time to converge: from then on the estimate's error stays below half its "
               "initial value (the true scale factor; the drive's end if never; the paper "
               "shows curves)")
VAN = ("a simulated curved drive with two 4 % slopes (the van's Daejeon route is not "
       "published), GPS lost 50 s after moving off for 150 s; landnav's carrier-smoothed fixes "
       "(the van had real receivers); DMU-300CC errors drawn per seed")


def _variant(claim: Claim, key: str, variant: str, experiment: str, judge,
             extra: tuple[str, ...]) -> Claim:
    return Claim(key, claim.text, claim.paper_figure,
                 tuple(c for c in claim.conditions if c != PAPER_FIXES_WORDS) + extra, judge,
                 kind=claim.kind, variant_of=claim.key, variant=variant,
                 experiments=(experiment,))


def _spkf_vs_ekf(key: str, text: str, paper_figure: str, measure_words: str, experiment: str,
                 figure: str, unit: str, what: str) -> Claim:
    """A paper claim that the simplex SPKF's ``figure`` is smaller than the EKF's."""
    return Claim(key, text, paper_figure, (*CONDITIONS, measure_words),
                 paired(experiment, "spkf", "ekf", figure, unit, what),
                 experiments=(experiment,))


S1_Z = _spkf_vs_ekf("situation1_z_scale_faster",
                    "Situation I: the SPKF estimates the z-gyro scale factor faster than the EKF",
                    "Fig. 7(d): 'The scale factor error of the z-axis gyro in the SPKF is "
                    "estimated faster than that in the EKF' (curves, no time printed)",
                    f"{SCALE_WORDS}; scale factors fixed at eq. 36's values", "situation1",
                    "z_scale_converge_s", "s", "SPKF converges sooner")
S1_HEADING = _spkf_vs_ekf("situation1_heading",
                          "Situation I: the EKF's heading error is larger than the SPKF's",
                          "Fig. 7(b): 'This phenomenon causes the larger heading error in the "
                          "EKF than in the SPKF'", "heading RMS from moving off to the end",
                          "situation1", "heading_rms_deg", "deg", "SPKF heading error smaller")
S1_POSITION = _spkf_vs_ekf("situation1_position",
                           "Situation I: the EKF's position error is larger than the SPKF's",
                           "Fig. 7(a): 'The position error in the EKF is larger than that in "
                           "the SPKF'", "horizontal RMS from moving off to the end",
                           "situation1", "horizontal_rms_m", "m", "SPKF position error smaller")
S1_ACCEL = Claim("situation1_accel_scale_slower",
                 "Situation I: the SPKF's accelerometer scale-factor error decreases more "
                 "slowly than the EKF's",
                 "Fig. 7(c): 'The estimation error of the accelerometer scale factor error in "
                 "the SPKF decreases slowly'", (*CONDITIONS, SCALE_WORDS),
                 paired("situation1", "ekf", "spkf", "accel_scale_converge_s", "s",
                        "EKF converges sooner"), experiments=("situation1",))
S2_EKF = Claim("situation2_ekf_diverges_140",
               "Situation II: from -140 deg initial heading error the EKF's errors diverge",
               "Fig. 8: 'the EKF errors diverge with time'", (*CONDITIONS, CONVERGE_WORDS),
               converged("situation2", ("ekf_m140",), "the EKF does not converge", "higher"),
               experiments=("situation2",))
S2_SPKF = Claim("situation2_spkf_converges_140",
                "Situation II: from -140 deg the SPKF's errors converge to near zero",
                "Fig. 8: 'the errors of SPKF converge to the neighbor of 0 with time'",
                (*CONDITIONS, CONVERGE_WORDS),
                converged("situation2", ("spkf_m140",), "the SPKF converges"),
                experiments=("situation2",))
S3 = _spkf_vs_ekf("situation3_position",
                  "Situation III (GPS blocked 75-90 s): the EKF's position error grows more "
                  "than the SPKF's in the blockage",
                  "Fig. 9: 'the position and heading errors of the EKF increase more than that "
                  "of the SPKF in the blockage section'",
                  "growth: largest horizontal error in the outage minus its value at the "
                  "outage's start", "situation3", "outage_growth_m", "m",
                  "SPKF error grows less")
S3_HEADING = _spkf_vs_ekf("situation3_heading",
                          "Situation III: the EKF's heading error grows more than the SPKF's in "
                          "the blockage", "Fig. 9 (as above)",
                          "growth: largest absolute heading error in the outage minus its value "
                          "at the outage's start", "situation3", "outage_heading_growth_deg",
                          "deg", "SPKF heading error grows less")

PAPER = Paper(
    key="cho2006",
    title="Performance Enhancement of Low-Cost Land Navigation System for Location-Based "
          "Service",
    citation="S. Y. Cho and W. S. Choi, ETRI Journal 28(2), 2006 (seeds/000_3f05ebbf41b6e448)",
    experiments=(SITUATION1, SITUATION1_LANDNAV_FIXES, SITUATION2, SITUATION2_LANDNAV_FIXES,
                 SITUATION3, SITUATION3_FIVE_M, SITUATION3_LANDNAV_FIXES, DR_OUTAGE),
    figures=figures,
    claims=(
        Claim("fig2_drm1_bias_observability",
              "DRM2/GPS: the gyro-bias covariance decreases with time on any trajectory; "
              "DRM1/GPS: only on the turns",
              "Fig. 2 (gyro-bias covariance over time, simulated)", (),
              untestable="the filters' solutions carry no gyro-bias standard deviation (the "
                         "solution format has no column for it), and the standstill "
                         "calibration removes the biases before the drive"),
        Claim("fig3_drm2_beats_drm1",
              "Section II: DRM2/GPS's heading converges from 45 and 90 deg initial error; "
              "DRM1/GPS's depends on the trajectory and the error (DRM2 better)",
              "Fig. 3 (heading error from 45 and 90 deg, two trajectories)",
              (*CONDITIONS, "heading RMS from 60 s after moving off, from -90 deg (the paper: "
                            "+45 and +90 deg on its own turning drives)"),
              paired("situation2", "ekf_m90", "drm1_m90", "heading_rms_deg", "deg",
                     "DRM2 heading error smaller"), experiments=("situation2",)),
        Claim("fig3_ekf_below_100_deg",
              "The DRM2/GPS EKF performs well when the initial heading error is less than "
              "100 deg (it converges from -45 and -90 deg)",
              "Section IV.1.B text and Fig. 3", (*CONDITIONS, CONVERGE_WORDS),
              converged("situation2", ("ekf_m45", "ekf_m90"), "the EKF converges"),
              experiments=("situation2",)),
        S1_Z,
        _variant(S1_Z, "situation1_z_scale_faster_landnav_fixes", FIXES_WORDS[LANDNAV_FIXES],
                 "situation1_landnav_fixes",
                 paired("situation1_landnav_fixes", "spkf", "ekf", "z_scale_converge_s", "s",
                        "SPKF converges sooner"), (FIXES_WORDS[LANDNAV_FIXES],)),
        _variant(S1_Z, "situation1_z_scale_faster_symmetric", "symmetric SPKF point set",
                 "situation1",
                 paired("situation1", "spkf_sym", "ekf", "z_scale_converge_s", "s",
                        "symmetric-set SPKF converges sooner"),
                 (PAPER_FIXES_WORDS, "the SPKF with the symmetric 2L + 1 point set instead of "
                                     "the paper's simplex set")),
        S1_HEADING,
        _variant(S1_HEADING, "situation1_heading_landnav_fixes", FIXES_WORDS[LANDNAV_FIXES],
                 "situation1_landnav_fixes",
                 paired("situation1_landnav_fixes", "spkf", "ekf", "heading_rms_deg", "deg",
                        "SPKF heading error smaller"), (FIXES_WORDS[LANDNAV_FIXES],)),
        S1_POSITION,
        S1_ACCEL,
        Claim("fig7e_spkf_covariance_larger",
              "Situation I: the SPKF's estimation-error covariance is slightly larger than the "
              "EKF's in the initial section of movement",
              "Fig. 7(e)", (),
              untestable="the covariance plotted in Fig. 7(e) is that of the scale-factor "
                         "states, which the solutions do not carry"),
        S2_EKF,
        _variant(S2_EKF, "situation2_ekf_diverges_140_landnav_fixes",
                 FIXES_WORDS[LANDNAV_FIXES],
                 "situation2_landnav_fixes",
                 converged("situation2_landnav_fixes", ("ekf_m140",),
                           "the EKF does not converge", "higher"),
                 (FIXES_WORDS[LANDNAV_FIXES],)),
        S2_SPKF,
        Claim("abstract_spkf_converges_160",
              "The DR/GPS system with the SPKF gives a stable solution even when the initial "
              "heading error is as large as 160 deg",
              "Abstract (no figure)", (*CONDITIONS, CONVERGE_WORDS, "from -160 deg"),
              converged("situation2", ("spkf_m160",), "the SPKF converges"),
              experiments=("situation2",)),
        S3,
        _variant(S3, "situation3_position_five_m_fixes", FIXES_WORDS[FIVE_M_FIXES],
                 "situation3_five_m_fixes",
                 paired("situation3_five_m_fixes", "spkf", "ekf", "outage_growth_m", "m",
                        "SPKF error grows less"), (FIXES_WORDS[FIVE_M_FIXES],)),
        _variant(S3, "situation3_position_landnav_fixes", FIXES_WORDS[LANDNAV_FIXES],
                 "situation3_landnav_fixes",
                 paired("situation3_landnav_fixes", "spkf", "ekf", "outage_growth_m", "m",
                        "SPKF error grows less"), (FIXES_WORDS[LANDNAV_FIXES],)),
        _variant(S3, "situation3_position_symmetric", "symmetric SPKF point set",
                 "situation3",
                 paired("situation3", "spkf_sym", "ekf", "outage_growth_m", "m",
                        "symmetric-set SPKF error grows less"),
                 (PAPER_FIXES_WORDS, "the SPKF with the symmetric 2L + 1 point set")),
        S3_HEADING,
        Claim("fig12_drm2_beats_drm1",
              "Stand-alone DR: only DRM2 keeps the trajectory's shape; DRM1 cannot sense the "
              "centrifugal force on curves (DRM2's error the smaller)",
              "Fig. 12 (van data, trajectories only)",
              (VAN, "horizontal error 120 s after GNSS is lost"),
              paired("dr_outage", "drm2", "drm1", "dr_error_m", "m",
                     "DRM2 error smaller"), experiments=("dr_outage",)),
        Claim("van_70_converges",
              "Van, initial heading 70 deg (true about 140): both filters converge to the "
              "right heading with GPS",
              "Figs. 13-14: 'the erroneous initial heading angle is converged into the right "
              "heading angle'",
              (VAN, "initial heading error -70 deg; converged: heading RMS over the second "
                    f"half of the 50 s before the loss below {CONVERGED_DEG:g} deg"),
              lambda t: _before_outage(t, ("ekf_m70", "spkf_m70")), experiments=("dr_outage",)),
        Claim("van_70_blockage",
              "Van from 70 deg: in the GPS blockage the EKF's position error becomes large, "
              "the SPKF's stays small (SPKF smaller)",
              "Figs. 13(a), 14(a) (trajectories, no number)",
              (VAN, "initial heading error -70 deg; error 120 s after the loss"),
              paired("dr_outage", "spkf_m70", "ekf_m70", "dr_error_m", "m",
                     "SPKF error smaller"), experiments=("dr_outage",)),
        Claim("van_0_blockage",
              "Van from 0 deg (true about 140): the SPKF gives a satisfactory solution, the "
              "EKF a somewhat large error in the blockage (SPKF smaller)",
              "Fig. 15 (trajectories, no number)",
              (VAN, "initial heading error -140 deg; error 120 s after the loss"),
              paired("dr_outage", "spkf_m140", "ekf_m140", "dr_error_m", "m",
                     "SPKF error smaller"), experiments=("dr_outage",)),
    ))


def _before_outage(tables: Mapping[str, pd.DataFrame], labels: tuple[str, ...]) -> Verdict:
    per = _per_seed(tables, "dr_outage", {label: f"{label}.before_outage_heading_rms_deg"
                                          for label in labels})
    worst = np.max(np.vstack(list(per.values())), axis=0)
    name = "largest heading RMS before the loss, deg"
    return m.threshold_judgement({name: worst, **per}, name, threshold=CONVERGED_DEG,
                                 better="lower", unit="deg", what="both filters converge")
