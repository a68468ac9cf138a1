"""Park et al. 2019 reproduced: the proposed 3-D DR/GPS (``dr3d_ekf``) against the 2-D DR/GPS
(``dr2d_odo_ekf``) and the INS/GPS/odometer EKF (``ins_odo_ekf``) in an underground garage
(Table 3, Fig. 19), the same garage made flat with a perfect odometer, the odometer scale
factor at garage entry (Fig. 9), the open-sky blockage (Figs. 14-15), the multilevel garage
(Table 3, area 2) and the curved tunnel (Fig. 18), and the INS baseline on a
automotive body (a working filter that uses its NHC at the rear axle), with issue 14's criteria
(docs/reproduction_park2019.md, docs/reproduction_park2019_ins.md).

Figures per seed and filter label, over the dataset's longest GNSS outage (horizontal errors
from the scorer, ``simulator.reproduce.measures``):

* ``LABEL.exit_horizontal_m``: at the last solution row before GNSS returns;
* ``LABEL.max_horizontal_m``: the largest inside the outage;
* ``LABEL.height_change_error_m``: |estimated - true height change from outage start to exit|
  (NaN for a filter without height);
* ``LABEL.scale_at_entry``: estimated odometer scale factor at the outage start over the true
  one, minus 1 (NaN for a filter without the state);
* ``LABEL.rms_outside_m``: horizontal RMS over the rows outside every GNSS outage.

Public names
------------
PAPER, GARAGE, FLAT, SCALE_097, OPEN_SKY, MULTILEVEL, TUNNEL, INS_PARK_GARAGE,
INS_PARKING_GARAGE, PAPER_FILTERS, FLAT_PERFECT, SHORT, garage_figures.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pandas as pd

from simulator.dataset.io import Dataset
from simulator.reproduce import measures as m
from simulator.reproduce.paper import Claim, Experiment, Figures, Paper, Verdict

PAPER_FILTERS = ("dr2d_odo_ekf", "ins_odo_ekf", "dr3d_ekf")
# the reproduction runs each filter with the paper's own noise values and states (``tuning:
# paper``), so that its figures do not move with the datasheet tuning the filters use by default
PAPER_ENTRIES = {name: {"name": name, "config": {"tuning": "paper"}} for name in PAPER_FILTERS}
# the same garage made flat (helices become level circles, ramps level straights) with a
# perfect odometer (no scale-factor error, drift, quantisation or latency)
FLAT_PERFECT = ("trajectory.segments.8.helix.rise=0", "trajectory.segments.25.helix.rise=0",
                "trajectory.segments.10.slope.grade=0", "trajectory.segments.23.slope.grade=0",
                "sensors.odometer.preset=ideal", "sensors.odometer.scale_factor=1.0")
# the CI length of the garage: the open road before it and after it shorter, the parking stop
# shorter; the garage's helices, ramps and laps unchanged (425 s -> about 300 s)
SHORT = ("trajectory.segments.0.stop.duration=5", "trajectory.segments.2.straight.length=120",
         "trajectory.segments.4.straight.length=120",
         "trajectory.segments.6.straight.length=100", "trajectory.segments.17.stop.duration=5",
         "trajectory.segments.27.straight.length=60",
         "trajectory.segments.29.straight.length=60")
WIN_FRACTION = 0.8  # dr3d_ekf better in >= 8 of 10 seeds
FLAT_RATIO = (0.7, 1.3)  # flat garage: the median ratio lies here (no advantage)
HEIGHT_TOLERANCE_M = 2.0
SCALE_TOLERANCE = 0.005
RMS_OUTSIDE_M = 5.0
OPEN_SKY_MAX_M = 7.0


def _true_scale(dataset: Dataset, t: float) -> float:
    """The true odometer scale factor at ``t``: ``truth_sensors`` (or the manifest's value)."""
    if dataset.has("truth_sensors"):
        ts = dataset.read("truth_sensors")
        if "odometer_scale_factor" in ts:
            return float(np.interp(t, ts["t"], ts["odometer_scale_factor"]))
    return float(dataset.manifest["sensors"]["odometer"].get("scale_factor", 1.0))


def garage_figures(dataset: Dataset, solutions: Mapping[str, pd.DataFrame]) -> Figures:
    """The figures of the module docstring for every solution, over the longest outage."""
    truth = dataset.read("truth")
    windows = m.outages(dataset.read("events"))
    t0, t1 = m.longest_outage(dataset.read("events"))
    out = {}
    for label, sol in solutions.items():
        e = m.errors(dataset, sol)
        t, err = e["t"].to_numpy(), e["err_h"].to_numpy()
        inside = (t >= t0) & (t < t1)
        exit_row = np.flatnonzero(t < t1)[-1]
        entry_row = np.flatnonzero(t <= t0)[-1]
        outside = ~m.inside_windows(t, windows)
        alt = np.interp(t[[entry_row, exit_row]], truth["t"], truth["alt"])
        sol_at = sol.set_index("t")
        est_dh = float(sol_at["alt"].loc[t[exit_row]] - sol_at["alt"].loc[t[entry_row]])
        scale = math.nan
        if "odometer_scale_factor" in sol:
            scale = (float(sol_at["odometer_scale_factor"].loc[t[entry_row]])
                     / _true_scale(dataset, t[entry_row]) - 1.0)
        out.update({f"{label}.exit_horizontal_m": float(err[exit_row]),
                    f"{label}.max_horizontal_m": float(np.max(err[inside])),
                    f"{label}.height_change_error_m": abs(est_dh - float(alt[1] - alt[0])),
                    f"{label}.scale_at_entry": scale,
                    f"{label}.rms_outside_m": float(np.sqrt(np.nanmean(err[outside] ** 2)))})
    return out


GARAGE = Experiment(key="garage", scenario="park2019_underground_garage.yaml",
                    entries=PAPER_ENTRIES,
                    measure=garage_figures, quick_overrides=SHORT)
FLAT = Experiment(key="flat_garage", scenario="park2019_underground_garage.yaml",
                  entries=PAPER_ENTRIES,
                  measure=garage_figures, overrides=FLAT_PERFECT, quick_overrides=SHORT)
SCALE_097 = Experiment(key="garage_scale_097", scenario="park2019_underground_garage.yaml",
                       entries={"dr3d_ekf": PAPER_ENTRIES["dr3d_ekf"]}, measure=garage_figures,
                       overrides=("sensors.odometer.scale_factor=0.97",),
                       quick_overrides=SHORT)
OPEN_SKY = Experiment(key="open_sky", scenario="park2019_open_sky_blockage.yaml",
                      entries={"dr3d_ekf": PAPER_ENTRIES["dr3d_ekf"]}, measure=garage_figures)
MULTILEVEL = Experiment(key="multilevel_garage", scenario="park2019_multilevel_garage.yaml",
                        entries=PAPER_ENTRIES,
                        measure=garage_figures)
TUNNEL = Experiment(key="curved_tunnel", scenario="park2019_curved_tunnel.yaml",
                    entries=PAPER_ENTRIES,
                    measure=garage_figures)
_INS_ENTRIES = {"nhc": {"name": "ins_odo_ekf", "config": {"tuning": "paper"}},
                "no_nhc": {"name": "ins_odo_ekf", "config": {"tuning": "paper", "nhc": False}}}
INS_PARK_GARAGE = Experiment(key="ins_park_garage", scenario="park2019_underground_garage.yaml",
                             entries=_INS_ENTRIES, measure=garage_figures, quick_overrides=SHORT)
INS_PARKING_GARAGE = Experiment(key="ins_parking_garage", scenario="parking_garage.yaml",
                                entries=_INS_ENTRIES, measure=garage_figures)


def _beats(tables: Mapping[str, pd.DataFrame], other: str, analysis: str = "",
           experiment: str = "garage",
           keys: tuple[str, ...] = ("exit_horizontal_m", "max_horizontal_m")) -> Verdict:
    parts, counts = [], []
    for key in keys:
        mine = m.column(tables, f"dr3d_ekf.{key}", experiment)
        theirs = m.column(tables, f"{other}.{key}", experiment)
        wins, n = m.paired_wins(mine, theirs)
        missing = m.missing_count(mine, theirs)  # a seed without both figures is no win
        counts.append((wins, n + missing))
        parts.append(f"{key.split('_')[0]}: {m.win_rate_text(wins, n, 'dr3d_ekf', missing)}, "
                     f"dr3d_ekf "
                     f"{m.spread_text(mine, 'm')} vs {other} {m.spread_text(theirs, 'm')}")
    wins, n = min(counts)
    what = " and ".join(k.split("_")[0] for k in keys)
    return m.count_verdict(wins, n, WIN_FRACTION, "; ".join(parts),
                           f"dr3d_ekf beats {other} on {what} error", analysis)


def _flat(tables: Mapping[str, pd.DataFrame], other: str, analysis: str = "") -> Verdict:
    parts, inside = [], []
    for key in ("exit_horizontal_m", "max_horizontal_m"):
        ratio = (tables["flat_garage"][f"dr3d_ekf.{key}"]
                 / tables["flat_garage"][f"{other}.{key}"]).to_numpy(float)
        finite = ratio[np.isfinite(ratio)]  # the seeds without one are counted in the text
        med = float(np.median(finite)) if len(finite) else math.nan
        inside.append(FLAT_RATIO[0] <= med <= FLAT_RATIO[1])
        parts.append(f"{key.split('_')[0]} ratio dr3d_ekf / {other} {m.spread_text(ratio)}")
    measured = "; ".join(parts)
    if all(inside):
        return Verdict("shown", measured, "both median ratios lie in 0.7-1.3: without ramps and "
                       "odometer error the 3-D filter has no advantage")
    status = "partly" if any(inside) else "not shown"
    return Verdict(status, measured, f"a median ratio lies outside 0.7-1.3. {analysis}".strip())


def _worst(*verdicts: Verdict) -> Verdict:
    """Several verdicts of one claim as one: the worst word, every figure and reason."""
    order = {"shown": 0, "partly": 1, "not shown": 2}
    status = max((v.status for v in verdicts), key=order.__getitem__)
    return Verdict(status, " / ".join(v.measured for v in verdicts),
                   " / ".join(v.reason for v in verdicts))


def _every_seed(values: np.ndarray, bound: float, measured: str, what: str,
                analysis: str = "") -> Verdict:
    return m.count_verdict(int(np.sum(values < bound)), len(values), 1.0, measured, what,
                           analysis)


def _judge_height(tables: Mapping[str, pd.DataFrame]) -> Verdict:
    err = m.column(tables, "dr3d_ekf.height_change_error_m", "garage")
    ins = m.column(tables, "ins_odo_ekf.height_change_error_m", "garage")
    return _every_seed(err, HEIGHT_TOLERANCE_M, f"dr3d_ekf {m.spread_text(err, 'm')}; "
                       f"ins_odo_ekf {m.spread_text(ins, 'm')}",
                       "dr3d_ekf's height-change error is under 2 m")


def _judge_scale(tables: Mapping[str, pd.DataFrame]) -> Verdict:
    per = {"1.03": m.column(tables, "dr3d_ekf.scale_at_entry", "garage"),
           "0.97": m.column(tables, "dr3d_ekf.scale_at_entry", "garage_scale_097")}
    ok, n = m.least_count(per, lambda v: np.abs(v) < SCALE_TOLERANCE)
    measured = "; ".join(f"true {k}: relative error {m.spread_text(100 * v, '%')}"
                         for k, v in per.items())
    return m.count_verdict(ok, n, 1.0, measured, "the scale factor is within 0.5 % at entry "
                           "for both true values")


def _judge_rms(tables: Mapping[str, pd.DataFrame]) -> Verdict:
    per = {name: m.column(tables, f"{name}.rms_outside_m", "garage") for name in PAPER_FILTERS}
    ok, n = m.least_count(per, lambda v: v < RMS_OUTSIDE_M)
    measured = "; ".join(f"{k} {m.spread_text(v, 'm')}" for k, v in per.items())
    return m.count_verdict(ok, n, 1.0, measured, "all three filters are under 5 m RMS outside "
                           "the outages (automotive body)",
                           "a filter above 5 m in some seed: see "
                           "docs/reproduction_park2019_ins.md and docs/reproduction_park2019.md")


def _judge_ins_working(tables: Mapping[str, pd.DataFrame]) -> Verdict:
    per = {k: m.column(tables, "nhc.rms_outside_m", k)
           for k in ("ins_park_garage", "ins_parking_garage")}
    ok = sum(int(np.sum(v < RMS_OUTSIDE_M)) for v in per.values())
    n = sum(len(v) for v in per.values())
    measured = "; ".join(f"{k}: {m.spread_text(v, 'm')}" for k, v in per.items())
    return m.count_verdict(ok, n, 1.0, measured, "ins_odo_ekf is under 5 m RMS outside the "
                           "outages (automotive body, both garages)")


def _judge_ins_nhc(tables: Mapping[str, pd.DataFrame]) -> Verdict:
    parts, better = [], []
    for k in ("ins_park_garage", "ins_parking_garage"):
        with_nhc = m.column(tables, "nhc.max_horizontal_m", k)
        without = m.column(tables, "no_nhc.max_horizontal_m", k)
        wins, n = m.paired_wins(with_nhc, without)
        missing = m.missing_count(with_nhc, without)
        better.append(bool(n and np.nanmedian(with_nhc) < np.nanmedian(without)))
        parts.append(f"{k}: max error with NHC {m.spread_text(with_nhc, 'm')}, odometer only "
                     f"{m.spread_text(without, 'm')}; "
                     f"{m.win_rate_text(wins, n, 'with NHC', missing)}")
    measured = "; ".join(parts)
    if all(better):
        return Verdict("shown", measured, "the median garage error is smaller with the NHC in "
                       "both garages")
    return Verdict("partly" if any(better) else "not shown", measured,
                   "the NHC does not lower the median garage error in every garage")


def _judge_open_sky(tables: Mapping[str, pd.DataFrame]) -> Verdict:
    worst = m.column(tables, "dr3d_ekf.max_horizontal_m", "open_sky")
    return _every_seed(worst, OPEN_SKY_MAX_M, f"largest error in the blockage "
                       f"{m.spread_text(worst, 'm')}", "dr3d_ekf stays under 7 m")


CONDITIONS = ("simulated garage after the paper's description (helical ramps down and up, 15 % "
              "ramps, exit away from the entry, 4.5 min without GNSS) instead of the paper's "
              "Seoul drive; SMI130 with the calibrated accelerometer offset at 20 Hz, drawn per "
              "seed; automotive vehicle body (suspension, side slip)",)
DR2D_ANALYSIS = ("Both DR filters' heading error is dominated by the z-gyro scale factor "
                 "(0.5 % 1-sigma, about 5 deg over the helix turns), which neither filter "
                 "estimates; with it set to zero as a diagnostic dr3d_ekf wins 10/10 "
                 "(docs/reproduction_park2019.md).")
MULTILEVEL_ANALYSIS = ("Not analysed here: this garage has helices too, so the unestimated "
                       "z-gyro scale factor found in the underground garage is the likely "
                       "cause (not measured).")
TUNNEL_ANALYSIS = ("Not analysed to the end: the tunnel has only 60 deg of turns, so the gyro "
                   "scale factor is not the cause; part of the drift comes from the z-gyro's "
                   "effective bias as estimated from about 100 s of GPS course before the "
                   "tunnel (docs/reproduction_park2019.md).")
INS_FLAT_ANALYSIS = ("Against ins_odo_ekf the 3-D DR keeps its advantage on flat ground too: "
                     "the INS velocity error from the accelerometer bias does not need ramps "
                     "(the paper's own argument in section I).")
PAPER = Paper(
    key="park2019",
    title="MEMS 3D DR/GPS Integrated System for Land Vehicle Application Robust to GPS Outages",
    citation="W. J. Park, J. W. Song, C. H. Kang, J. H. Lee, M. H. Seo, S. Y. Park, J. Y. Yeo, "
             "C. G. Park, IEEE Access 7, 2019 (seeds/004_45cf7e5461f4cee8)",
    experiments=(GARAGE, FLAT, SCALE_097, OPEN_SKY, MULTILEVEL, TUNNEL, INS_PARK_GARAGE,
                 INS_PARKING_GARAGE),
    claims=(
        Claim("garage_beats_2d",
              "Underground garage: dr3d_ekf beats dr2d_odo_ekf on exit and maximum horizontal "
              "error in >= 8 of 10 seeds (paired)",
              "Table 3, area 1 (409 s): 2-D DR 13.72 m; the proposed filter's column is lost "
              "from our copy; text: 'the proposed algorithm showed smaller position errors'",
              CONDITIONS, lambda t: _beats(t, "dr2d_odo_ekf", DR2D_ANALYSIS)),
        Claim("garage_beats_ins",
              "Underground garage: dr3d_ekf beats ins_odo_ekf on exit and maximum horizontal "
              "error in >= 8 of 10 seeds (paired)",
              "Table 3, area 1: INS/GPS/odometer 23.69 m", CONDITIONS,
              lambda t: _beats(t, "ins_odo_ekf")),
        Claim("flat_no_advantage_2d",
              "The same garage made flat with a perfect odometer: the advantage over "
              "dr2d_odo_ekf disappears (median ratio of exit and max error in 0.7-1.3)",
              "sections III-E and IV-B: the gain comes from the 3-D geometry and the odometer "
              "scale factor (no number)", (*CONDITIONS, "helices and ramps levelled"),
              lambda t: _flat(t, "dr2d_odo_ekf")),
        Claim("flat_no_advantage_ins",
              "The same against ins_odo_ekf (median ratio in 0.7-1.3)",
              "sections III-E and IV-B (no number)", (*CONDITIONS, "helices and ramps levelled"),
              lambda t: _flat(t, "ins_odo_ekf", INS_FLAT_ANALYSIS)),
        Claim("height_change",
              "dr3d_ekf's height change through the garage is within 2 m of the true one, "
              "every seed",
              "Fig. 19: 3-D DR height change 1.22 m, INS/GPS/odometer 22.34 m", CONDITIONS,
              _judge_height),
        Claim("scale_factor_at_entry",
              "The odometer scale factor (true 1.03 and 0.97) is estimated within 0.5 % at "
              "garage entry, every seed",
              "Fig. 9: the scale factor converges to the true value", CONDITIONS,
              _judge_scale),
        Claim("working_filters",
              "All three filters have horizontal RMS under 5 m outside the outages, every seed",
              "not printed", CONDITIONS, _judge_rms, kind="check"),
        Claim("ins_working",
              "ins_odo_ekf on the automotive body is under 5 m RMS outside the outages of "
              "Park's garage and parking_garage.yaml, every seed",
              "not printed", ("NHC at the rear axle (the datasheet's installation geometry), "
                              "its noise from the bicycle model's tyre slip; parking_garage.yaml "
                              "has a 100 Hz IMU",), _judge_ins_working, kind="check"),
        Claim("ins_uses_nhc",
              "ins_odo_ekf's NHC lowers its median garage error (automotive body, both garages)",
              "section II-A, eqs. 12-14: the NHC bounds the INS error (no number)",
              ("NHC at the rear axle",), _judge_ins_nhc, kind="check"),
        Claim("multilevel_beats_both",
              "Multilevel garage (not an issue-14 criterion): dr3d_ekf beats dr2d_odo_ekf and "
              "ins_odo_ekf on exit error in >= 8 of 10 seeds (paired)",
              "Table 3, area 2 (182 s): INS/GPS/odometer 24.20 m, 2-D DR 9.60 m; the proposed "
              "filter smaller (its column is lost from our copy)",
              ("simulated multilevel garage (four-floor helix up, rooftop lap, helix down; the "
               "real geometry is not published), 203 s without GNSS instead of 182 s; sensors "
               "as in the underground garage",),
              lambda t: _worst(_beats(t, "dr2d_odo_ekf", MULTILEVEL_ANALYSIS, "multilevel_garage",
                                      ("exit_horizontal_m",)),
                               _beats(t, "ins_odo_ekf", "", "multilevel_garage",
                                      ("exit_horizontal_m",)))),
        Claim("tunnel_beats_2d",
              "Curved tunnel, 159 s without GNSS (not an issue-14 criterion): dr3d_ekf's error "
              "at the exit is smaller than dr2d_odo_ekf's in >= 8 of 10 seeds (paired)",
              "Fig. 18: error after the exit 1.91 m (3-D DR/GPS) vs 5.74 m (2-D DR/GPS)",
              ("simulated 2.6 km tunnel with a gentle S-curve and a 3 % climb (the real "
               "geometry is not published); error at the last epoch before GNSS returns, "
               "against the truth (the paper used a map)",),
              lambda t: _beats(t, "dr2d_odo_ekf", TUNNEL_ANALYSIS, "curved_tunnel",
                               ("exit_horizontal_m",))),
        Claim("open_sky_bounded",
              "Open-sky 40 s blockage on an interchange ramp: dr3d_ekf's horizontal error stays "
              "under 7 m, every seed",
              "Figs. 14-15: the 3-D DR/GPS stays within 7 m of the GPS position",
              ("simulated interchange loop ramp (8 % grade, 270 deg) in open sky, GNSS blocked "
               "for 40 s by a fault; errors against the truth (the paper: against GPS); sensors "
               "as in the garage; automotive vehicle body",),
              _judge_open_sky),
    ))
