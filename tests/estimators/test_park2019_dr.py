"""Park et al. 2019 dead-reckoning filters (``dr2d_odo_ekf``, ``dr3d_ekf``): the navigation
processor against exact kinematics, the error model's Jacobians against finite differences, and the
paper's garage claims over seeds 1-3 (ten with ``--runslow``; figures in
docs/reproduction_park2019.md), computed by ``simulator.reproduce.park2019`` (what ``landnav
reproduce park2019`` runs)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from estimators.builtin.park2019_dr import _dr3d_navigate
from estimators.registry import BUILTINS
from estimators.toolbox.nav_error import euler_error_jacobian
from simulator.dataset.generate import build_truth
from simulator.earth import dcm_to_euler, euler_to_dcm, euler_to_quat, radii_of_curvature, skew
from simulator.pipeline import load_scenario
from simulator.reproduce import park2019
from simulator.reproduce.measures import needed_count
from simulator.reproduce.paper import scenario_path
from simulator.reproduce.runner import run_experiment
from tests.conftest import CI_SEEDS, seed_sets

pytestmark = pytest.mark.usefixtures("shared_experiments")  # each (experiment, seed) once

SEEDS = list(range(1, 11))


@pytest.mark.parametrize("attitude_deg", [(0, 0, 30), (5, -8, 120), (-12, 15, -100)])
def test_euler_error_jacobian_matches_finite_differences(attitude_deg):
    """d(roll, pitch, yaw)/d psi for C(estimate) = (I + [psi x]) C, by central differences of
    the Euler angles of exp([psi x]) C (the exponential, not the linearisation)."""
    from scipy.linalg import expm

    c = euler_to_dcm(*np.radians(attitude_deg))
    jac = euler_error_jacobian(c)
    eps = 1e-6
    numeric = np.zeros((3, 3))
    for k in range(3):
        d = np.zeros(3)
        d[k] = eps
        plus = np.array(dcm_to_euler(expm(skew(d)) @ c))
        minus = np.array(dcm_to_euler(expm(skew(-d)) @ c))
        numeric[:, k] = (plus - minus) / (2 * eps)
    np.testing.assert_allclose(jac, numeric, atol=1e-7)


def test_navigation_processor_follows_exact_kinematics():
    """Eqs. 3 and 20-21 fed with the true body rates and the true speed (trapezoidal, 200 Hz)
    follow the exact truth of the garage (helices, 15 % ramps, speed bumps) to centimetres.
    At the paper's 20 Hz the speed bumps' pitch-rate pulses are undersampled and the same
    integration leaves 0.8 m horizontal and 4 m height error (a finding noted in the docs)."""
    # a rigid body: the speed used is the truth's along-body speed, which only a rigid body's
    # velocity equals (the automotive body slips and heaves: 3.4 m after the drive)
    scenario = load_scenario(scenario_path(park2019.GARAGE.scenario),
                             ["sensors.imu.preset=ideal", "trajectory.rate=200", "vehicle=rigid"],
                             1)
    truth = build_truth(scenario.data).table()  # the truth table a dataset holds
    t = truth["t"].to_numpy()
    rates = truth[["wx", "wy", "wz"]].to_numpy()
    speed = truth["speed"].to_numpy()
    c = euler_to_dcm(*truth[["roll", "pitch", "yaw"]].iloc[0].to_numpy())
    quat = euler_to_quat(*truth[["roll", "pitch", "yaw"]].iloc[0].to_numpy())
    pos = np.array([math.radians(truth["lat"].iloc[0]), math.radians(truth["lon"].iloc[0]),
                    truth["alt"].iloc[0]])
    v = np.zeros(3)
    f = np.zeros((10, 10))
    out = np.empty((len(t), 3))
    out[0] = pos
    for k in range(1, len(t)):
        dt = t[k] - t[k - 1]
        dtheta = 0.5 * (rates[k] + rates[k - 1]) * dt
        quat, c, pos, v, _ = _dr3d_navigate(quat, c, pos, v, dtheta,
                                            np.array([0.5 * (speed[k] + speed[k - 1]), 0, 0]),
                                            0.0, dt, f)
        out[k] = pos
    rn, re = radii_of_curvature(out[:, 0])
    d_n = (out[:, 0] - np.radians(truth["lat"])) * rn
    d_e = (out[:, 1] - np.radians(truth["lon"])) * re * np.cos(out[:, 0])
    horizontal = np.hypot(d_n, d_e)
    assert truth["distance"].iloc[-1] > 2500
    assert horizontal.max() < 0.05
    assert np.abs(out[:, 2] - truth["alt"]).max() < 0.2
    yaw = np.arctan2(c[1, 0], c[0, 0])
    assert abs(math.remainder(yaw - truth["yaw"].iloc[-1], 2 * math.pi)) < math.radians(0.01)




@pytest.fixture(scope="module", params=[
    pytest.param(("short", CI_SEEDS), id="short-3seeds"),
    pytest.param(("short", SEEDS), id="short-10seeds", marks=pytest.mark.slow),
    pytest.param(("full", SEEDS), id="full-10seeds", marks=pytest.mark.slow)])
def drive(request) -> tuple[bool, range]:
    """The drive length and the seeds: the shortened CI drive (``park2019.SHORT``, the
    experiments' quick overrides: 425 s -> about 300 s, the garage unchanged) over seeds 1-3;
    with --runslow also over ten seeds, and the scenario as shipped over ten seeds."""
    length, seeds = request.param
    return length == "short", seeds


@pytest.fixture(scope="module")
def quick(drive) -> bool:
    return drive[0]


@pytest.fixture(scope="module")
def seeds(drive) -> range:
    return drive[1]


@pytest.fixture(scope="module")
def garage(quick, seeds, tmp_path_factory) -> pd.DataFrame:
    """The garage (true odometer scale factor 1.03), the paper's three filters."""
    return run_experiment(park2019.GARAGE, seeds, tmp_path_factory.mktemp("garage"), quick)


@pytest.fixture(scope="module")
def flat_garage(quick, tmp_path_factory) -> pd.DataFrame:
    """The same garage made flat with a perfect odometer (``park2019.FLAT_PERFECT``), ten seeds
    in every run: its claim is a median of per-seed ratios that spread from 0.5 to 2.6, which
    three seeds do not pin (seeds 1-3 give medians of 2.13 and 0.51 on the shortened drive)."""
    return run_experiment(park2019.FLAT, SEEDS, tmp_path_factory.mktemp("flat"), quick)


def _column(table: pd.DataFrame, name: str, key: str) -> np.ndarray:
    return table[f"{name}.{key}"].to_numpy()


DR2D_NOT_SHOWN = (
    "not shown: dr3d_ekf beats dr2d_odo_ekf in 5/10 seeds (exit error medians 14.6 m vs 12.0 m); "
    "the unestimated z-gyro scale factor (0.5 % 1-sigma) over six helix turns dominates both "
    "filters' heading error; without it dr3d_ekf wins 10/10 (docs/reproduction_park2019.md)")


INS_NOT_SHOWN = (
    "not shown on the shortened CI drive since ins_odo_ekf applies its NHC at the rear axle "
    "(issue 14): dr3d_ekf beats it in 7/10 seeds at the exit and 5/10 on the maximum (medians "
    "10.3 m vs 18.6 m exit, 16.8 m vs 20.2 m max); on the full drive it does (10/10, 9/10 in "
    "the session-5 reproduce run)")


def _case(name: str, xfail: str | None = None, strict: bool = False) -> object:
    """A filter as a test parameter: skipped when not registered, expected to fail with a
    reason (the measured figures) when ``xfail`` is given."""
    marks = [pytest.mark.skipif(name not in BUILTINS,
                                reason=f"{name} is not registered")]
    if xfail:
        marks.append(pytest.mark.xfail(strict=strict, reason=xfail))
    return pytest.param(name, marks=marks)


@pytest.mark.parametrize("other", [_case("dr2d_odo_ekf"), _case("ins_odo_ekf")])
def test_dr3d_beats_the_baselines_in_the_garage(garage, quick, other, request):
    """Park Table 3: dr3d_ekf beats the baseline on exit and maximum horizontal error in at
    least 8 of 10 seeds (paired per seed; 3 of 3 on three seeds). Against ins_odo_ekf an expected
    failure on the shortened drive only (its short open-road stretches leave the INS less to
    drift over); against dr2d_odo_ekf an expected failure over ten seeds, and not asserted on
    three (seeds 1-3: 3 of 3 before the GNSS error streams were drawn apart, 2 of 3 since)."""
    if other == "ins_odo_ekf" and quick:
        request.applymarker(pytest.mark.xfail(strict=True, reason=INS_NOT_SHOWN))
    if other == "dr2d_odo_ekf":  # three seeds can go either way (3 of 3 on the older draws)
        request.applymarker(pytest.mark.xfail(strict=len(garage) == len(SEEDS),
                                              reason=DR2D_NOT_SHOWN))
    for key in ("exit_horizontal_m", "max_horizontal_m"):
        wins = _column(garage, "dr3d_ekf", key) < _column(garage, other, key)
        assert wins.sum() >= needed_count(0.8, len(wins)), (key, wins.sum())


@pytest.mark.parametrize("other", [_case("dr2d_odo_ekf"), _case("ins_odo_ekf")])
def test_flat_garage_with_perfect_odometer_removes_the_advantage(flat_garage, other):
    """Without ramps and odometer scale-factor error, the median per-seed ratio of dr3d_ekf's
    exit and maximum error to the baseline's lies between 0.7 and 1.3. Against ins_odo_ekf
    with its NHC at the rear axle (issue 14): 0.93 exit, 0.96 max (it was 0.66 and 0.28 with
    the NHC at the IMU, an expected failure then)."""
    for key in ("exit_horizontal_m", "max_horizontal_m"):
        ratio = _column(flat_garage, "dr3d_ekf", key) / _column(flat_garage, other, key)
        assert 0.7 <= np.median(ratio) <= 1.3, (key, np.median(ratio))


def test_dr3d_height_change_through_the_garage(garage):
    """Park Fig. 19: the height change from garage entry to exit within 2 m of the truth
    (paper: 1.22 m change for the 3-D DR, 22.34 m for INS/GPS/odometer), every seed."""
    err = _column(garage, "dr3d_ekf", "height_change_error_m")
    assert np.all(err < 2.0), err


@pytest.mark.parametrize("scale", [1.03, 0.97])
def test_odometer_scale_factor_at_garage_entry(tmp_path, garage, quick, seeds, scale):
    """Park section III-E, Fig. 9: the odometer scale factor (true 1.03 and 0.97) estimated
    within 0.5 % when GNSS is lost at the garage entry, every seed."""
    if scale == 1.03:
        rel = _column(garage, "dr3d_ekf", "scale_at_entry")
    else:
        runs = run_experiment(park2019.SCALE_097, seeds, tmp_path, quick)
        rel = _column(runs, "dr3d_ekf", "scale_at_entry")
    assert np.all(np.abs(rel) < 0.005), rel


@pytest.mark.parametrize("name", [_case("dr2d_odo_ekf"), _case("ins_odo_ekf"), "dr3d_ekf"])
def test_filters_work_outside_the_outages(garage, name):
    """Horizontal RMS outside the GNSS outages: median over seeds under 5 m, every seed under
    7 m (a working filter, not a paper claim; with the receiver's carrier-phase and
    multi-system model one dr3d_ekf seed is at 5.0006 m, the median 2.7 m)."""
    rms = _column(garage, name, "rms_outside_m")
    assert np.median(rms) < 5.0 and np.all(rms < 7.0), rms


@pytest.mark.parametrize("seeds", seed_sets(SEEDS))
def test_open_sky_blockage_stays_bounded(tmp_path, seeds):
    """Park Figs. 14-15: GNSS blocked for 40 s on an interchange ramp in open sky, the 3-D
    DR/GPS's horizontal error stays under 7 m, every seed (measured on ten: at most 4.0 m)."""
    runs = run_experiment(park2019.OPEN_SKY, seeds, tmp_path)
    worst = _column(runs, "dr3d_ekf", "max_horizontal_m")
    assert np.all(worst < 7.0), worst
