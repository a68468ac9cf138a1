"""rtk_ins_ekf (tightly coupled RTK/INS) against the truth and against RTKLIB's rnx2rtkp
kinematic solution of the same measurements (the dataset exported as RINEX), on the shipped
scenario rtk_open_road.yaml: 20 minutes of open road, two 30 s tunnels, a base 5 km east of the
start, GPS L1 C/A + L2C at 10 Hz (and, in one slow case, GPS, Galileo and BeiDou on two bands).

Claims (docs/rtk-ins.md): at least 95 % of the epochs fixed, a fixed-solution 3-D RMS of at most
3 cm, under 1 % wrong fixes (3-D error over 10 cm), at least RTKLIB's fix rate; after each tunnel
a re-fix faster than RTKLIB's (median over the tunnels) in at least 8 of 10 seeds; the position's
mean (error / sigma)^2 per axis in 0.3-3 (seed mean) and none above 10 (SPEC section 8's
consistency, after 60 s). CI runs a few minutes of the same road (one tunnel) at one seed; three
20-minute seeds and the three-system short drive run with --runslow."""

from __future__ import annotations

import numpy as np
import pytest

from tests.gnss.rtklib import need_rnx2rtkp
from tests.rtk_drive import median_refix, process

AXES = ("n", "e", "d")


def _check_seed(fig: dict) -> None:
    ours, theirs = fig["rtk_ins_ekf"], fig["rtklib"]
    print(f"\nseed {fig['seed']}: rtk_ins_ekf {ours}\n  rtklib {theirs}\n  cpu {fig['cpu_s']}")
    assert ours["fix_rate"] >= 0.95
    assert ours["fixed_rms"] <= 0.03
    assert ours["wrong_fix_rate"] < 0.01
    nse = fig["consistency"]["position"]["nse"]
    assert all(nse[a] <= 10.0 for a in AXES), nse


@pytest.fixture(scope="module")
def short_drive(tmp_path_factory):
    need_rnx2rtkp()
    return process(tmp_path_factory.mktemp("rtk_short"), seed=1, short=True)


def test_short_drive_fixes_precisely(short_drive):
    """Seed 1 of the short drive: the per-seed claims (fixed epochs, fixed RMS, wrong fixes,
    (error/sigma)^2 under 10). With the code weighted as white it failed: 37.6 % of the fixes
    wrong, partial fixes of a biased float (docs/rtk-ins.md, 'Wrong fixes at seed 1')."""
    _check_seed(short_drive)


def test_short_drive_fixes_as_often_as_rtklib_and_refixes_first(short_drive):
    """Seed 1 of the short drive: at least RTKLIB's fix rate (99.96 % against 99.36 %) and the
    re-fix after the tunnel before RTKLIB's (0.1 s against 0.2 s). It failed (96.8 %, 2.3 s)
    before the fixed failure-rate ratio test, the code arc's first epoch at its marginal sigma
    and the ionosphere states kept through the tunnel (docs/rtk-ins.md, 'First fix, re-fix and
    the phase budget')."""
    assert short_drive["rtk_ins_ekf"]["fix_rate"] >= short_drive["rtklib"]["fix_rate"]
    assert median_refix(short_drive["rtk_ins_ekf"]) < median_refix(short_drive["rtklib"])


@pytest.mark.xfail(strict=True, reason="not shown at seed 1: the east (error/sigma)^2 is 0.22 "
                   "(north 0.78, down 0.29): the rover's phase 1-sigma of 3 mm at zenith "
                   "against the truth's 1.7-1.9 mm; 2 mm gave 1.13 / 0.30 / 0.61 here but "
                   "97.2 % fixed on the three-system drive (docs/rtk-ins.md)")
def test_short_drive_is_consistent(short_drive):
    nse = short_drive["consistency"]["position"]["nse"]
    assert all(0.3 <= nse[a] <= 3.0 for a in AXES), nse


SLOW_SEEDS = (1, 2, 3)


@pytest.fixture(scope="module")
def twenty_minutes(tmp_path_factory):
    need_rnx2rtkp()
    work = tmp_path_factory.mktemp("rtk_twenty")
    return [process(work, seed, short=False) for seed in SLOW_SEEDS]


@pytest.mark.slow
def test_three_seeds_of_twenty_minutes(twenty_minutes):
    """Each seed's claims and the seed mean of the fix rate at least RTKLIB's (99.98 / 99.98 /
    99.97 % against 99.46 / 99.99 / 100 %, no wrong fix, fixed 3-D RMS 0.6 / 1.1 / 1.0 cm)."""
    failed = []
    for fig in twenty_minutes:
        try:
            _check_seed(fig)
        except AssertionError as error:
            failed.append(f"seed {fig['seed']}: {error}")
    ours = np.array([f["rtk_ins_ekf"]["fix_rate"] for f in twenty_minutes])
    theirs = np.array([f["rtklib"]["fix_rate"] for f in twenty_minutes])
    print(f"fix rate: rtk_ins_ekf {ours.round(4)}, rtklib {theirs.round(4)}")
    nse = {a: np.mean([f["consistency"]["position"]["nse"][a] for f in twenty_minutes])
           for a in AXES}
    print(f"position (error/sigma)^2, seed mean: {nse}")
    assert not failed, failed
    assert ours.mean() >= theirs.mean()


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="not shown: the seed mean of the position's "
                   "(error/sigma)^2 is 0.30 / 0.36 / 0.37 (north 0.295, under 0.3; the rover's "
                   "phase 1-sigma of 3 mm at zenith against the truth's 1.7-1.9 mm: 0.43 / "
                   "0.60 / 0.74 at 2 mm, docs/rtk-ins.md)")
def test_twenty_minutes_consistent(twenty_minutes):
    nse = {a: np.mean([f["consistency"]["position"]["nse"][a] for f in twenty_minutes])
           for a in AXES}
    assert all(0.3 <= nse[a] <= 3.0 for a in AXES), nse


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="not shown: both re-fix within 0.2 s of each tunnel's "
                   "end, RTKLIB mostly at the first epoch (rtk_ins_ekf / RTKLIB: seed 1 0.0, "
                   "0.2 / 0.0, 0.0 s; seed 2 0.1, 0.1 / 0.1, 0.0 s; seed 3 0.1, 0.2 / 0.0, "
                   "0.0 s): a re-fix at the first epoch cannot be beaten (docs/rtk-ins.md)")
def test_twenty_minutes_refix_before_rtklib(twenty_minutes):
    faster = [median_refix(f["rtk_ins_ekf"]) < median_refix(f["rtklib"]) - 1e-3
              for f in twenty_minutes]
    assert sum(faster) >= 0.8 * len(twenty_minutes), faster


@pytest.mark.slow
def test_three_systems_short_drive_against_rtklib(tmp_path):
    """GPS, Galileo and BeiDou on two bands each: double differences within each system and
    band against its own reference satellite (no inter-system term). The same claims as the
    GPS drive, and the fix rate at least RTKLIB's on the same files (GPS + Galileo + BeiDou)."""
    need_rnx2rtkp()
    fig = process(tmp_path, 1, short=True, systems=("gps", "galileo", "beidou"))
    _check_seed(fig)
    assert fig["rtk_ins_ekf"]["fix_rate"] >= fig["rtklib"]["fix_rate"]
