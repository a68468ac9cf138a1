"""riss3d_tc_ekf (Karamat et al. 2015): the error model against numerical differentiation, the
RISS mechanisation against the exact truth, and the paper's claims on its partial-outage
protocol over ten seeds (figures in docs/reproduction_karamat2015.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from estimators.builtin.karamat2015 import STATES, riss_rates, system_matrix
from simulator.dataset.io import open_dataset
from simulator.errors import InputError
from simulator.replay import run_estimator
from simulator.scenario import validate_data
from tests.estimators.karamat_protocol import (
    generate,
    horizontal_error,
    run_protocol,
    run_protocol_dataset,
    short_scenario,
)


def test_system_matrix_is_the_jacobian_of_the_derivative_form():
    """F of eqs. 13-38 against central differences of the rates it linearises; the only
    entries that differ are the pitch terms of the velocity rows, which the paper's eqs. 24, 28
    and 31 leave out (its eq. 23 differentiates by a_od, A, v_n (v_e) and b_z only)."""
    x = np.zeros(len(STATES))
    x[:9] = [math.radians(51.0), math.radians(-114.0), 1000.0, 8.0, -5.0, 0.3,
             math.radians(122.0), -0.8, 0.01]
    x[12] = 0.05
    wz = 0.3
    f = system_matrix(x[0], x[2], x[3], x[4], x[6], x[12], x[7], wz - x[8])
    jac = np.zeros_like(f)
    for j in range(len(x)):
        step = 1e-9 if j < 2 else 1e-6 * max(1.0, abs(x[j]))
        up, down = x.copy(), x.copy()
        up[j] += step
        down[j] -= step
        jac[:, j] = (riss_rates(up, wz) - riss_rates(down, wz)) / (2.0 * step)
    differ = {(STATES[a], STATES[b]) for a, b in zip(*np.nonzero(
        ~np.isclose(f, jac, rtol=1e-6, atol=1e-6)), strict=True)}
    assert differ == {("ve", "p"), ("vn", "p"), ("vu", "p")}
    assert f[STATES.index("ve"), STATES.index("vn")] == pytest.approx(
        jac[STATES.index("ve"), STATES.index("vn")])
    # the simplified model is the leading block of the enhanced one
    np.testing.assert_array_equal(
        system_matrix(x[0], x[2], x[3], x[4], x[6], x[12], x[7], wz - x[8], 11), f[:11, :11])


@pytest.mark.parametrize("output", ["rate", "increment"])
def test_mechanisation_closes_on_the_truth(tmp_path, output):
    """Ideal reduced IMU and odometer, no GNSS: eqs. 1-9 alone follow the first 5.5 km loop of
    the scenario (slopes, turns, a lane change, a stop). A sign error in eq. 1's Earth-rate term
    (as our copy prints it) would turn the yaw by 2 omega_e sin(lat) t, 1.3 deg in the 430 s."""
    data = short_scenario(1, loops=1, site_s=None)
    raw = {k: data[k] for k in ("name", "seed", "start", "trajectory", "vehicle")}
    raw["sensors"] = {"imu": {"preset": "ideal", "rate": 100, "axes": "riss3d", "output": output},
                      "odometer": {"preset": "ideal", "rate": 10}}
    ds = open_dataset(generate(tmp_path / "ideal", validate_data(raw, "ideal")))
    truth = ds.read("truth")
    solution, _ = run_estimator(ds, "riss3d_tc_ekf", show_progress=False)
    distance = truth["distance"].iloc[-1]
    assert distance > 5000.0
    assert horizontal_error(solution, truth).max() < 5e-4 * distance  # 2.3 m measured
    yaw = np.interp(solution["t"], truth["t"], np.unwrap(truth["yaw"]))
    assert np.abs(np.angle(np.exp(1j * (solution["yaw"] - yaw)))).max() < math.radians(0.2)
    assert np.abs(solution["alt"] - np.interp(solution["t"], truth["t"], truth["alt"])).max() < 1.0
    assert solution["clock_bias"].isna().all()  # no GNSS: the clock is not estimated


def test_unknown_model_is_one_clear_error(tmp_path):
    data = short_scenario(1, loops=1, site_s=None)
    ds = open_dataset(generate(tmp_path / "d", data))
    with pytest.raises(InputError, match="model must be enhanced or simplified"):
        run_estimator(ds, {"name": "riss3d_tc_ekf", "label": None, "init": None,
                           "config": {"model": "full"}}, show_progress=False)


SEEDS = range(1, 11)


@pytest.fixture(scope="module")
def protocol(tmp_path_factory) -> dict:
    """The shortened protocol (one site) for ten seeds, three variants each."""
    directory = tmp_path_factory.mktemp("karamat")
    return {seed: run_protocol(directory, seed) for seed in SEEDS}


def _maxima(protocol: dict, label: str, count: int) -> np.ndarray:
    return np.array([protocol[s][label]["max"][count] for s in SEEDS])


def test_every_variant_is_a_working_filter(protocol):
    """All three variants stay bounded over the ten seeds (median window maxima measured: tight
    3.5 / 3.9 / 4.6 / 7.3 m, loose 9.8 / 6.8 / 8.6 / 8.9 m, simplified 4.8 / 8.7 / 7.1 / 8.0 m
    at 3 / 2 / 1 / 0 satellites)."""
    for label in ("tight", "loose", "simplified"):
        for count in (3, 2, 1, 0):
            assert np.median(_maxima(protocol, label, count)) < 20.0, (label, count)


def test_mean_window_maximum_under_12_m(protocol):
    """Karamat et al. section 4.3.1: 'on average, the maximum position error is always less
    than 12 m, irrespective of the number of visible satellites' (measured means: 3.0, 4.7,
    9.8, 8.5 m at 3, 2, 1, 0 satellites)."""
    for count in (3, 2, 1, 0):
        assert _maxima(protocol, "tight", count).mean() < 12.0


@pytest.mark.xfail(strict=True, reason="claim not reproduced: tight beats loose in 23 of the 30 "
                   "windows with 1-3 satellites, 77 % (docs/reproduction_karamat2015.md)")
def test_tight_beats_loose_with_one_to_three_satellites(protocol):
    """Issue 15: the tight filter beats ``coupling: loose`` (which has no GNSS below four
    satellites) in at least 80 % of the windows with 1-3 satellites, paired per seed (measured:
    8, 9 and 6 of 10 with 3, 2 and 1 satellites)."""
    wins = [(_maxima(protocol, "tight", c) < _maxima(protocol, "loose", c)) for c in (1, 2, 3)]
    assert np.concatenate(wins).mean() >= 0.8


def _gain(protocol: dict, counts: tuple[int, ...]) -> float:
    """1 - enhanced / simplified, on the means of the window maxima over the seeds (the earlier
    model here is an EKF with the earlier states, the paper's comparison an LKF)."""
    enhanced = np.mean([_maxima(protocol, "tight", c).mean() for c in counts])
    simplified = np.mean([_maxima(protocol, "simplified", c).mean() for c in counts])
    return 1.0 - enhanced / simplified


def test_enhanced_model_gains_16_percent_with_no_satellite(protocol):
    """Karamat et al. section 4.3.1: 16 % better than the earlier tightly coupled filter in the
    zero-satellite windows (measured: 20 %)."""
    assert _gain(protocol, (0,)) >= 0.16


@pytest.mark.xfail(strict=True, reason="claim not reproduced: the enhanced model gains 27 % over "
                   "all windows (docs/reproduction_karamat2015.md)")
def test_enhanced_model_gains_40_percent_overall(protocol):
    """Karamat et al. section 5: 40 % better than the earlier tightly coupled filter in overall
    maximum 2-D error (measured: 27 %; 40, 41, 20, 20 % at 3, 2, 1, 0 satellites)."""
    assert _gain(protocol, (3, 2, 1, 0)) >= 0.40


def test_gyro_bias_within_005_deg_s_by_300_s(protocol):
    """Karamat et al. section 4.3.3: the vertical-gyro bias converges in about 300 s (measured:
    the error at 300 s is at most 0.037 deg/s over the ten seeds)."""
    errors = np.array([protocol[s]["tight"]["bias_error_300s"] for s in SEEDS])
    assert np.all(np.abs(errors) < 0.05)


@pytest.mark.slow
def test_full_drive_all_sites(tmp_path):
    """The whole shipped scenario (nine sites, 36 windows, 1 h 53 min), seed 2015: every variant
    bounded and the gyro bias converged. Measured median window maxima at 3 / 2 / 1 / 0
    satellites: tight 3.7 / 5.0 / 22.1 / 12.0 m, loose 21.9 / 20.2 / 15.9 / 21.8 m, simplified
    5.1 / 9.2 / 24.9 / 13.8 m (sites 2-9 are harder to dead-reckon than site 1)."""
    data = short_scenario(2015, loops=13, site_s=None, end_s=1e9)
    result = run_protocol_dataset(generate(tmp_path / "full", data))
    for label in ("tight", "loose", "simplified"):
        for count in (3, 2, 1, 0):
            assert np.median(result[label]["max"][count]) < 40.0, (label, count)
    assert abs(result["tight"]["bias_error_300s"]) < 0.05
