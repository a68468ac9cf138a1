"""rtk_ins_ekf (tightly coupled RTK/INS) against the truth and against RTKLIB's rnx2rtkp
kinematic solution of the same measurements (the dataset exported as RINEX), on the shipped
scenario rtk_open_road.yaml: 20 minutes of open road, two 30 s tunnels, a base 5 km east of the
start; rover and base on GPS L1 C/A + L2C, Galileo E1 + E5b and BeiDou B1I + B2I at 10 Hz (the
acceptance drive; ``tests/rtk_drive.py``).

Claims (docs/rtk-ins.md): at least 95 % of the epochs fixed, a fixed-solution 3-D RMS of at most
3 cm, under 1 % wrong fixes (3-D error over 10 cm), at least RTKLIB's fix rate on the same files;
after each tunnel a re-fix faster than RTKLIB's (median over the tunnels) in at least 8 of 10
seeds; the position's mean (error / sigma)^2 per axis in 0.3-3 (seed mean) and none above 10
(SPEC section 8's consistency, after 60 s). The default run drives a few minutes of the same
road (one tunnel) at seed 1 with the three systems; ``--runslow`` the ten 20-minute seeds and
the short GPS-only drive."""

from __future__ import annotations

import numpy as np
import pytest

from tests.gnss.rtklib import need_rnx2rtkp
from tests.rtk_drive import median_refix, process

AXES = ("n", "e", "d")
THREE_SYSTEMS = ("gps", "galileo", "beidou")
EPOCH_S = 0.1  # the 10 Hz epochs: the finest resolution of a re-fix time


def _check_seed(fig: dict) -> None:
    ours, theirs = fig["rtk_ins_ekf"], fig["rtklib"]
    print(f"\nseed {fig['seed']}: rtk_ins_ekf {ours}\n  rtklib {theirs}\n  cpu {fig['cpu_s']}"
          f"\n  position (error/sigma)^2 {fig['consistency']['position']['nse']}")
    assert ours["fix_rate"] >= 0.95
    assert ours["fixed_rms"] <= 0.03
    assert ours["wrong_fix_rate"] < 0.01
    nse = fig["consistency"]["position"]["nse"]
    assert all(nse[a] <= 10.0 for a in AXES), nse


def _refix_epochs(fig: dict, name: str) -> float:
    """The median re-fix over a run's tunnels in whole 10 Hz epochs (RTKLIB's times carry
    its output's rounding, 5e-8 s)."""
    return round(median_refix(fig[name]) / EPOCH_S, 3)


@pytest.fixture(scope="module")
def short_drive(tmp_path_factory):
    need_rnx2rtkp()
    return process(tmp_path_factory.mktemp("rtk_short"), seed=1, short=True,
                   systems=THREE_SYSTEMS)


def test_short_drive_fixes_precisely(short_drive):
    """Seed 1 of the short drive, three systems: the per-seed claims (fixed epochs, fixed RMS,
    wrong fixes, (error/sigma)^2 under 10)."""
    _check_seed(short_drive)


def test_short_drive_fixes_as_often_as_rtklib(short_drive):
    """Seed 1 of the short drive, three systems: at least RTKLIB's fix rate on the same files,
    and a re-fix after the tunnel no later than RTKLIB's (both at its first epoch:
    docs/rtk-ins.md)."""
    assert short_drive["rtk_ins_ekf"]["fix_rate"] >= short_drive["rtklib"]["fix_rate"]
    assert (_refix_epochs(short_drive, "rtk_ins_ekf")
            <= _refix_epochs(short_drive, "rtklib"))


def test_short_drive_is_consistent(short_drive):
    """The position's (error/sigma)^2 within 0.3-3 per axis. It failed (east 0.22-0.40 on the
    GPS seeds) while the IMU's scale-factor noise was driven by every flush's change of the
    readings, the car body's vibration included (docs/rtk-ins.md, 'Consistency')."""
    nse = short_drive["consistency"]["position"]["nse"]
    assert all(0.3 <= nse[a] <= 3.0 for a in AXES), nse


@pytest.mark.slow
def test_short_gps_drive(tmp_path):
    """The short drive on GPS L1 C/A + L2C alone, seed 1: the per-seed claims, at least
    RTKLIB's fix rate, the re-fix no later than RTKLIB's and (error/sigma)^2 within 0.3-3.
    With the code weighted as white it failed: 37.6 % of the fixes wrong, partial fixes of a
    biased float (docs/rtk-ins.md, 'Wrong fixes at seed 1')."""
    need_rnx2rtkp()
    fig = process(tmp_path, 1, short=True)
    _check_seed(fig)
    assert fig["rtk_ins_ekf"]["fix_rate"] >= fig["rtklib"]["fix_rate"]
    assert _refix_epochs(fig, "rtk_ins_ekf") <= _refix_epochs(fig, "rtklib")
    nse = fig["consistency"]["position"]["nse"]
    assert all(0.3 <= nse[a] <= 3.0 for a in AXES), nse


ACCEPTANCE_SEEDS = tuple(range(1, 11))


@pytest.fixture(scope="module")
def acceptance(tmp_path_factory):
    """The acceptance drive: 20 minutes, three systems on two bands, ten seeds
    (about half an hour of CPU: 75 s of replay and 80 s of rnx2rtkp per seed)."""
    need_rnx2rtkp()
    work = tmp_path_factory.mktemp("rtk_acceptance")
    return [process(work, seed, short=False, systems=THREE_SYSTEMS)
            for seed in ACCEPTANCE_SEEDS]


@pytest.mark.slow
def test_acceptance_drive(acceptance):
    """Each seed's claims and a fix rate at least RTKLIB's on its files (seeds 1-7: 99.96-100 %
    fixed against RTKLIB's 97.98-99.89 %, 0.52-1.13 cm against 0.97-2.15 cm, no wrong fix)."""
    failed = []
    for fig in acceptance:
        try:
            _check_seed(fig)
            assert fig["rtk_ins_ekf"]["fix_rate"] >= fig["rtklib"]["fix_rate"]
        except AssertionError as error:
            failed.append(f"seed {fig['seed']}: {error}")
    assert not failed, failed


@pytest.mark.slow
def test_acceptance_drive_consistent(acceptance):
    """The seed mean of the position's (error/sigma)^2 within 0.3-3 per axis (seeds 1-7: 0.60 /
    0.58 / 1.01; seed 1 0.52 / 0.40 / 0.97 before the scale-factor noise's window)."""
    nse = {a: np.mean([f["consistency"]["position"]["nse"][a] for f in acceptance])
           for a in AXES}
    print(f"position (error/sigma)^2, seed mean: {nse}")
    assert all(0.3 <= nse[a] <= 3.0 for a in AXES), nse


@pytest.mark.slow
def test_acceptance_drive_refixes_no_later_than_rtklib(acceptance):
    """The median re-fix over the two tunnels, in 10 Hz epochs, at most RTKLIB's at every
    seed (seeds 1-7: both at the first epoch after each tunnel)."""
    ours = [_refix_epochs(f, "rtk_ins_ekf") for f in acceptance]
    theirs = [_refix_epochs(f, "rtklib") for f in acceptance]
    print(f"re-fix, epochs after the tunnel: rtk_ins_ekf {ours}, rtklib {theirs}")
    assert all(a <= b for a, b in zip(ours, theirs, strict=True)), (ours, theirs)


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="not shown, a tie: both re-fix at the first epoch after "
                   "each tunnel at every seed run, so faster cannot be decided at the 10 Hz "
                   "epochs; the simulator re-locks every signal at the tunnel's end "
                   "(docs/rtk-ins.md, 'The acceptance drive')")
def test_acceptance_drive_refixes_before_rtklib(acceptance):
    faster = [_refix_epochs(f, "rtk_ins_ekf") < _refix_epochs(f, "rtklib")
              for f in acceptance]
    assert sum(faster) >= 8, faster
