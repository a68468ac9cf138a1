"""RTK on a drive, judged by RTKLIB (Debian rtklib 2.4.3 ``rnx2rtkp``, kinematic, L1+L2, 15 deg
mask, fix-and-hold, ratio 3: the refdata README's options, on GPS, Galileo and BeiDou) against the
exact truth at the antenna: ``scenarios/rtk_open_sky.yaml`` (20 min, GPS + Galileo + BeiDou on
two frequencies, base 5 km away) and ``scenarios/rtk_canyon_tunnel.yaml`` (the same drive through
a street canyon and a tunnel).

CI runs shortened drives of the same receivers, sky and base (about 4 and 3 minutes); the whole
20-minute drives run with ``--runslow``. A fix is wrong when its 3-D error exceeds 10 cm: half the
shortest carrier wavelength (B1I, 19.2 cm), where a wrong integer starts, and three times the
3 cm RMS asked of right fixes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from tests.gnss.rtklib import kinematic, need_rnx2rtkp

WRONG_FIX_M = 0.10
OPEN, CANYON = "rtk_open_sky", "rtk_canyon_tunnel"
# CI: the drives' first straight shortened and their middle left out; the canyon variant keeps
# a canyon street and the tunnel
SHORT_SEGMENTS = {
    OPEN: [{"stop": {"duration": 30}}, {"accelerate": {"to_speed": 15.0, "accel": 1.0}},
           {"straight": {"length": 1500}}, {"turn": {"angle": 90, "radius": 50}},
           {"straight": {"length": 1000}}, {"accelerate": {"to_speed": 0.0, "accel": 1.0}},
           {"stop": {"duration": 10}}],
    CANYON: [{"stop": {"duration": 30}}, {"accelerate": {"to_speed": 15.0, "accel": 1.0}},
             {"straight": {"length": 300}}, {"straight": {"length": 600, "zone": "downtown"}},
             {"straight": {"length": 300}}, {"straight": {"length": 300, "zone": "tunnel"}},
             {"straight": {"length": 600}}, {"accelerate": {"to_speed": 0.0, "accel": 1.0}},
             {"stop": {"duration": 10}}],
}


def rtk_drive(name: str, work: Path, short: bool, seed: int | None = None) -> dict:
    """Generate the scenario (shortened for CI; at ``seed`` if given, else the scenario's),
    export RINEX, run RTKLIB, and score each solution epoch against the true antenna position:
    ``q`` (1 fixed, 2 float), ``error_m`` (3-D), ``epochs`` (of the dataset), the truth and raw
    rover streams."""
    from simulator.dataset.export import export_rinex
    from simulator.dataset.io import open_dataset
    from simulator.pipeline import generate, load_scenario
    from tests.conftest import REPO

    need_rnx2rtkp()
    data = yaml.safe_load((REPO / "scenarios" / f"{name}.yaml").read_text())
    if short:
        data["trajectory"]["segments"] = SHORT_SEGMENTS[name]
    if seed is not None:
        data["seed"] = seed
        work = work / f"seed{seed}"
        work.mkdir()
    path = work / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    generate(load_scenario(path), work / name, show_progress=False)
    dataset = open_dataset(work / name)
    obs, nav = export_rinex(dataset, work / "rinex")
    manifest = json.loads((work / name / "manifest.json").read_text())
    base = manifest["gnss_base"]
    sol = kinematic(obs, obs.with_name(f"{name}_base.obs"), nav,
                    np.array([base["x"], base["y"], base["z"]]), work / f"{name}.pos",
                    systems="GEC")
    truth = dataset.read("truth_gnss")
    antenna = truth.groupby("t")[["antenna_x", "antenna_y", "antenna_z"]].first()
    # RTKLIB's epochs are the rover's time tags (true time + its clock error, < 1 ms)
    t = np.round(sol["tow"] - manifest["gps_time_start"]["tow"], 2)
    known = np.isin(t, antenna.index)
    assert known.mean() > 0.99
    error = np.linalg.norm(sol["xyz"][known] - antenna.loc[t[known]].to_numpy(), axis=1)
    q = sol["q"][known]
    fixed = q == 1
    out = {"q": q, "t": t[known], "error_m": error, "epochs": len(antenna),
           "fix_rate": fixed.sum() / len(antenna),
           "rms_fixed_m": float(np.sqrt(np.mean(error[fixed] ** 2))) if fixed.any() else np.nan,
           "wrong_fixes": int((error[fixed] > WRONG_FIX_M).sum()),
           "truth": truth, "raw": dataset.read("gnss_raw")}
    print(f"\n{name}{' (CI drive)' if short else ''}: {out['epochs']} epochs, "
          f"{fixed.sum()} fixed ({100 * out['fix_rate']:.1f} %), 3-D RMS of the fixes "
          f"{100 * out['rms_fixed_m']:.1f} cm, wrong fixes (> 10 cm) {out['wrong_fixes']}, "
          f"float {int((q == 2).sum())}")
    return out


def new_arc_after_every_gap(truth: pd.DataFrame, raw: pd.DataFrame) -> tuple[int, int]:
    """Over every satellite and signal: the number of tracking gaps (tracked, then not, then
    tracked again) and how many of them resume with a new arc flagged in the RINEX LLI
    (bit 0) and a new arc number in the truth."""
    rows = truth[truth["tracked"] == 1].sort_values(["system", "sv", "signal", "t"])
    rows = rows.merge(raw[["t", "system", "sv", "signal", "lli"]],
                      on=["t", "system", "sv", "signal"])
    same = ((rows["system"] == rows["system"].shift()) & (rows["sv"] == rows["sv"].shift())
            & (rows["signal"] == rows["signal"].shift()))
    step = rows["t"].diff()
    gap = same & (step > 1.5 * step[same].min())
    resumed = rows[gap]
    new_arc = (resumed["arc"].to_numpy() != rows["arc"].shift()[gap].to_numpy()) & (
        (resumed["lli"].to_numpy() & 1) > 0)
    return int(gap.sum()), int(new_arc.sum())


@pytest.fixture(scope="module")
def short_drives(tmp_path_factory):
    work = tmp_path_factory.mktemp("rtk")
    return {name: rtk_drive(name, work, short=True) for name in (OPEN, CANYON)}


def test_open_sky_ci_drive_fixes_90_percent_within_3_cm(short_drives):
    run = short_drives[OPEN]
    assert run["fix_rate"] >= 0.90
    assert run["rms_fixed_m"] <= 0.03
    assert run["wrong_fixes"] == 0


@pytest.fixture(scope="module")
def canyon_more_seeds(tmp_path_factory):
    work = tmp_path_factory.mktemp("rtk_seeds")
    return [rtk_drive(CANYON, work, short=True, seed=seed) for seed in (2, 3)]


def _right_fix_rms_m(run: dict) -> float:
    right = run["error_m"][(run["q"] == 1) & (run["error_m"] <= WRONG_FIX_M)]
    return float(np.sqrt(np.mean(right ** 2)))


def test_canyon_and_tunnel_ci_drive_slips_at_every_blockage_and_fixes_less(short_drives,
                                                                          canyon_more_seeds):
    """Every fix is scored against the truth: the wrong ones are counted, the right ones are
    held to the 3 cm RMS asked of the open-sky fixes. That RMS is mostly an offset held over
    the drive (seed 1's right fixes all lie 2.8-3.4 cm off), so one seed is one draw of it
    (seeds 1-3: 3.00, 2.76, 1.76 cm); the bound is on the median over seeds 1-3. About half
    of it is the atmosphere RTKLIB runs without here (ionosphere and troposphere off): on the
    20-minute drive at seed 1, the truth's rover-minus-base ionosphere and troposphere alone
    put a fixed solution (weighted least squares of the double differences on L1 and L2, line
    of sight above 15 deg) 1.1 cm east and 0.7 cm up, the same in open sky: the absolute
    ionosphere shortens the 5 km baseline by 3.5 ppm (+1.7 cm toward the base), the
    troposphere lengthens it (-0.6 cm) and lifts it; the orbit, multipath and phase noise
    give under 2 mm. The canyon's rest is not traced."""
    run, open_sky = short_drives[CANYON], short_drives[OPEN]
    truth = run["truth"]
    in_tunnel = truth["tracked"].groupby(truth["t"]).sum() == 0
    assert in_tunnel.sum() >= 15  # 300 m at 15 m/s
    gaps, new_arcs = new_arc_after_every_gap(truth, run["raw"])
    print(f"tracking gaps {gaps}, each resumed on a new arc: {new_arcs}")
    assert gaps > 50 and new_arcs == gaps
    assert run["fix_rate"] < open_sky["fix_rate"]
    rms = [_right_fix_rms_m(r) for r in (run, *canyon_more_seeds)]
    print("right fixes' 3-D RMS, seeds 1-3:", [round(100 * r, 2) for r in rms], "cm")
    assert np.median(rms) <= 0.03


@pytest.fixture(scope="module")
def full_drives(tmp_path_factory):
    work = tmp_path_factory.mktemp("rtk_full")
    return {name: rtk_drive(name, work, short=False) for name in (OPEN, CANYON)}


@pytest.mark.slow
def test_open_sky_20_minutes_fixes_90_percent(full_drives):
    assert full_drives[OPEN]["fix_rate"] >= 0.90


@pytest.mark.slow
def test_open_sky_20_minutes_fixes_within_3_cm_rms(full_drives):
    run = full_drives[OPEN]
    assert run["rms_fixed_m"] <= 0.03 and run["wrong_fixes"] == 0


@pytest.mark.slow
def test_canyon_and_tunnel_20_minutes_slip_at_every_blockage(full_drives):
    run = full_drives[CANYON]
    gaps, new_arcs = new_arc_after_every_gap(run["truth"], run["raw"])
    print(f"tracking gaps {gaps}, each resumed on a new arc: {new_arcs}")
    assert gaps > 50 and new_arcs == gaps


@pytest.mark.slow
def test_canyon_and_tunnel_20_minutes_right_fixes_within_3_cm_rms(full_drives):
    """Seed 1: 2.2 cm (with the GNSS draws before each error process had its own stream it
    was 3.5 cm, a strict expected failure then; docs/gnss-carrier.md)."""
    run = full_drives[CANYON]
    right = run["error_m"][(run["q"] == 1) & (run["error_m"] <= WRONG_FIX_M)]
    assert np.sqrt(np.mean(right ** 2)) <= 0.03


@pytest.mark.slow
def test_canyon_and_tunnel_20_minutes_fix_less_than_open_sky(full_drives):
    assert full_drives[CANYON]["fix_rate"] < full_drives[OPEN]["fix_rate"]
