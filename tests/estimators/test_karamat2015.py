"""riss3d_tc_ekf (Karamat et al. 2015): the error model against numerical differentiation, the RISS
mechanisation against the exact truth, and the paper's claims on its partial-outage protocol over
seeds 1-3 (ten with ``--runslow``), computed by ``simulator/reproduce/karamat2015.py`` (what
``landnav reproduce karamat2015`` judges; figures in docs/reproduction_karamat2015.md). The protocol
runs on the default automotive body (session 5: the filter mechanises the rear axle, where the
odometer's velocity is along the body; on a rigid body the tight filter beat the loose one in 24 of
30 windows). The mechanisation test compares with a rigid body's exact truth."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from estimators.builtin.karamat2015 import STATES, riss_rates, system_matrix
from simulator.dataset.generate import build_truth, generate_dataset
from simulator.dataset.io import open_dataset
from simulator.errors import InputError
from simulator.replay import run_estimator
from simulator.reproduce import karamat2015 as karamat
from simulator.reproduce.measures import horizontal_error
from simulator.reproduce.paper import scenario_path
from simulator.reproduce.runner import run_experiment
from simulator.scenario import load_scenario
from simulator.scoring.align import solution_errors
from tests.conftest import seed_sets

pytestmark = pytest.mark.usefixtures("shared_experiments")  # each (experiment, seed) once

RIGID = ["vehicle=rigid"]


def one_loop(directory, sensors: str | None = None):
    """The first loop of the shipped drive, without faults (and with ``sensors`` when given)."""
    overrides = ["trajectory.segments.0.repeat.times=1", "faults=[]", "estimators=[]", *RIGID]
    if sensors:
        overrides.append(f"sensors={sensors}")
    scenario = load_scenario(scenario_path(karamat.SCENARIO), overrides, seed=1)
    return open_dataset(generate_dataset(scenario, directory, show_progress=False))


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
    ds = one_loop(tmp_path / "ideal", "{imu: {preset: ideal, rate: 100, axes: riss3d, output: "
                  + output + "}, odometer: {preset: ideal, rate: 10}}")
    truth = ds.read("truth")
    solution, _ = run_estimator(ds, "riss3d_tc_ekf", show_progress=False)
    distance = truth["distance"].iloc[-1]
    assert distance > 5000.0
    assert horizontal_error(ds, solution)[1].max() < 5e-4 * distance  # 2.3 m measured
    yaw = np.interp(solution["t"], truth["t"], np.unwrap(truth["yaw"]))
    assert np.abs(np.angle(np.exp(1j * (solution["yaw"] - yaw)))).max() < math.radians(0.2)
    assert np.abs(solution["alt"] - np.interp(solution["t"], truth["t"], truth["alt"])).max() < 1.0
    assert solution["clock_bias"].isna().all()  # no GNSS: the clock is not estimated


def test_unknown_model_is_one_clear_error(tmp_path):
    ds = one_loop(tmp_path / "d")
    with pytest.raises(InputError, match="model must be enhanced or simplified"):
        run_estimator(ds, {"name": "riss3d_tc_ekf", "label": None, "init": None,
                           "config": {"model": "full"}}, show_progress=False)


def test_loop_duration_is_the_modules():
    """The protocol picks site 1's windows by the loop's duration: it must be the drive's."""
    scenario = load_scenario(scenario_path(karamat.SCENARIO),
                             ["trajectory.segments.0.repeat.times=1", "faults=[]"])
    assert build_truth(scenario.data).duration_s == pytest.approx(karamat.LOOP_S, abs=0.01)


SEEDS = range(1, 11)
THREE = replace(karamat.PROTOCOL, entries={k: karamat.PROTOCOL.entries[k]
                                           for k in ("tight", "loose", "simplified")})


@pytest.fixture(scope="module", params=seed_sets(SEEDS))
def protocol(request, tmp_path_factory):
    """The shortened protocol (site 1, loops 1-4), three variants each (the reproduction's
    ablation variants left out: ``THREE``), for seeds 1-3 (the ten seeds with --runslow)."""
    return run_experiment(THREE, request.param, tmp_path_factory.mktemp("karamat"), quick=True)


def _maxima(protocol, label: str, count: int) -> np.ndarray:
    return karamat.seed_maxima(protocol, label, count)


def test_every_variant_is_a_working_filter(protocol):
    """All three variants stay bounded over the ten seeds (median window maxima measured: tight
    2.7 / 4.5 / 11.4 / 9.9 m, loose 10.7 / 7.4 / 10.2 / 12.0 m, simplified 5.2 / 10.5 / 13.8 /
    12.7 m at 3 / 2 / 1 / 0 satellites)."""
    for label in ("tight", "loose", "simplified"):
        for count in (3, 2, 1, 0):
            assert np.median(_maxima(protocol, label, count)) < 20.0, (label, count)


ONE_SATELLITE_NOT_SHOWN = (
    "not shown at one satellite: mean window maximum 13.1 m over the ten seeds (per seed "
    "4.7-30.4 m, so the mean's sampling spread is about 2.6 m); 11.8 m before session 6's "
    "signal-in-space change, which also changed every later random draw: the claim sat "
    "within one sampling spread of its bound either way; docs/reproduction_karamat2015.md")


@pytest.mark.parametrize("count", [3, 2, 1, 0])
def test_mean_window_maximum_under_12_m(protocol, count, request):
    """Karamat et al. section 4.3.1: 'on average, the maximum position error is always less
    than 12 m, irrespective of the number of visible satellites' (measured means on the
    automotive body: 3.1, 5.9, 13.1, 10.2 m at 3, 2, 1, 0 satellites; session 5: 3.2, 5.6,
    11.8, 9.8 m). At one satellite an expected failure over the ten seeds; seeds 1-3 draw a
    mean under 12 m."""
    if count == 1 and len(protocol) == len(SEEDS):
        request.applymarker(pytest.mark.xfail(strict=True, reason=ONE_SATELLITE_NOT_SHOWN))
    mean = _maxima(protocol, "tight", count).mean()
    print(f"tight mean window maximum, {count} satellites, {len(protocol)} seeds: {mean:.1f} m")
    assert mean < 12.0


@pytest.mark.xfail(strict=True, reason="claim not reproduced: tight beats loose in 20 of the 30 "
                   "windows with 1-3 satellites on the automotive body, 67 % (24 of 30 on a "
                   "rigid body); docs/reproduction_karamat2015.md")
def test_tight_beats_loose_with_one_to_three_satellites(protocol):
    """Issue 15: the tight filter beats ``coupling: loose`` (which has no GNSS below four
    satellites) in at least 80 % of the windows with 1-3 satellites, paired per seed."""
    wins, windows = karamat.window_wins(protocol, "tight", "loose", (1, 2, 3))
    assert windows == 3 * len(protocol)
    assert wins >= 0.8 * windows


def test_enhanced_model_gains_16_percent_with_no_satellite(protocol):
    """Karamat et al. section 4.3.1: 16 % better than the earlier tightly coupled filter in the
    zero-satellite windows (measured: 20 % on the automotive body, 17 % rigid)."""
    assert karamat.gain(protocol, (0,)) >= 0.16


def test_enhanced_model_gains_40_percent_overall(protocol):
    """Karamat et al. section 5: 40 % better than the earlier tightly coupled filter in overall
    maximum 2-D error (26 % over ten seeds, an expected failure, while v_u was an independent
    state whose corrections eq. 6 threw away; at least 40 % on seeds 1-3 since; the ten seeds
    of ``--runslow`` not re-measured)."""
    assert karamat.gain(protocol, (3, 2, 1, 0)) >= 0.40


def test_gyro_bias_within_005_deg_s_by_300_s(protocol):
    """Karamat et al. section 4.3.3: the vertical-gyro bias converges in about 300 s (measured:
    the error at 300 s is at most 0.032 deg/s over the ten seeds)."""
    errors = protocol["tight.gyro_bias_error_300s_deg_s"].to_numpy()
    assert len(errors) == len(protocol)
    assert np.all(np.abs(errors) < 0.05)


@pytest.fixture(scope="module")
def full_drive(tmp_path_factory):
    """The whole shipped scenario (ten sites, 40 windows, 2 h 20 min), seed 2015."""
    return run_experiment(THREE, [2015], tmp_path_factory.mktemp("karamat_full"))


@pytest.mark.slow
def test_full_drive_all_sites(full_drive):
    """Every variant bounded over the whole drive. Measured median window maxima at 3 / 2 / 1 /
    0 satellites: tight 3.7 / 7.6 / 23.0 / 20.1 m, loose 22.0 / 23.2 / 22.8 / 21.4 m,
    simplified 5.3 / 9.5 / 24.7 / 21.1 m (sites 2-10 are harder to dead-reckon than site 1)."""
    for label in ("tight", "loose", "simplified"):
        for count in (3, 2, 1, 0):
            maxima = karamat.window_maxima(full_drive, label, count)
            assert len(maxima) == 10
            assert np.median(maxima) < 40.0, (label, count)


@pytest.mark.slow
# not strict: the figure is 0.00003 deg/s above the bound, within what any change to the
# random draws moves it
@pytest.mark.xfail(strict=False, reason="claim not reproduced: 0.05003 deg/s at 300 s on seed 2015 "
                   "of the ten-site drive (0.033 on the nine-site drive, whose "
                   "shorter duration drew the sensors' processes differently; "
                   "docs/reproduction_karamat2015.md)")
def test_full_drive_gyro_bias_converged(full_drive):
    """Section 4.3.3 on the whole drive's seed: the bias error at 300 s below 0.05 deg/s."""
    assert abs(full_drive["tight.gyro_bias_error_300s_deg_s"].iloc[0]) < 0.05


def test_frozen_states_are_never_corrected(tmp_path):
    """``frozen_states`` (the ablation of the enhanced model's states): with the accelerometer
    biases frozen their estimates stay exactly zero through a loop with GNSS, while the full
    model moves them; with all of its additions frozen and the accelerometer update off the
    enhanced model is the earlier one; an unknown state name is refused."""
    ds = one_loop(tmp_path / "d")
    frozen, _ = run_estimator(ds, {"name": "riss3d_tc_ekf", "config": {
        "tuning": "paper", "frozen_states": ["bx", "by"]}}, show_progress=False)
    full, _ = run_estimator(ds, {"name": "riss3d_tc_ekf", "config": {"tuning": "paper"}},
                            show_progress=False)
    assert (frozen[["accel_bias_x", "accel_bias_y"]].to_numpy() == 0.0).all()
    assert np.abs(full["accel_bias_x"].to_numpy()).max() > 1e-4
    # every addition of the enhanced model frozen and its accelerometer update off: the earlier
    # model's solution (a leak through eq. 32's dv_o' = da_od moved the frozen speed error)
    inert, _ = run_estimator(ds, {"name": "riss3d_tc_ekf", "config": {
        "tuning": "paper", "frozen_states": ["r", "p", "bx", "by", "vo"],
        "accel_update_interval": 1e9}}, show_progress=False)
    earlier, _ = run_estimator(ds, {"name": "riss3d_tc_ekf", "config": {
        "tuning": "paper", "model": "simplified"}}, show_progress=False)
    columns = ["lat", "lon", "alt", "vn", "ve", "vd", "yaw", "std_n", "gyro_bias_z", "clock_bias"]
    np.testing.assert_allclose(inert[columns].to_numpy(), earlier[columns].to_numpy(),
                               rtol=1e-12, atol=1e-9)
    with pytest.raises(InputError, match="frozen_states must be among r, p, bx, by, vo"):
        run_estimator(ds, {"name": "riss3d_tc_ekf", "label": None, "init": None,
                           "config": {"frozen_states": ["bz"]}}, show_progress=False)


def test_gate_takes_the_ranges_back_from_a_filter_off_by_a_known_error(tmp_path):
    """The datasheet tuning's chi-square gate after a lock-out: the filter starts 50 m off while
    its covariance says 3 m (as after an outage its process noise under-describes), so every
    pseudorange fails the gate at first. After ``REACQUIRE_EPOCHS`` such epochs the position and
    clock covariance is matched to the innovations: from 30 s on every range is accepted and
    the horizontal error is inside three of the filter's own sigmas (without the rule: 45 m at
    30 s, three or four of the seven ranges accepted)."""
    drive = ("[{accelerate: {to_speed: 12.0, accel: 1.2}}, {straight: {length: 600}}, "
             "{turn: {angle: 90, radius: 40}}, {straight: {length: 600}}]")
    scenario = load_scenario(scenario_path(karamat.SCENARIO), [
        f"trajectory.segments={drive}", "faults=[]", "estimators=[]"], seed=1)
    ds = open_dataset(generate_dataset(scenario, tmp_path / "d", show_progress=False))
    solution, _ = run_estimator(ds, {"name": "riss3d_tc_ekf", "label": "ds", "config": {},
                                     "init": {"position_error": [40.0, -30.0, 0.0]}},
                                show_progress=False)
    t, err = horizontal_error(ds, solution)
    assert err[0] > 40.0
    late = solution["t"].to_numpy() >= 30.0
    sigma = np.hypot(solution["std_n"], solution["std_e"]).to_numpy()[late]
    assert np.all(np.interp(solution["t"].to_numpy()[late], t, err) < 3.0 * sigma)
    satellites = ds.read("gnss_raw").groupby("t").size().to_numpy()
    accepted = solution.loc[late, "nis_gnss_dof"].dropna().to_numpy()
    assert np.all(accepted == 2 * satellites.max())  # every range and every rate


@pytest.mark.parametrize("seed", [1, 2])
def test_height_holds_through_a_climb_with_three_satellites(tmp_path, seed):
    """A 90 deg turn into a 4.5 % climb inside a 60 s window of the three highest satellites
    (the turn-and-slope windows of docs/reproduction_karamat2015.md, shortened): the height
    error stays inside two of the filter's own sigmas (measured 0.58 and 0.37 sigma, 1.8 and
    1.1 m on seeds 1 and 2). While v_u was an independent error state, eq. 6 threw each
    Doppler correction of it away and the covariance kept it: 2.3 sigma (7.4 m) on seed 1,
    210 m in the fifth window of the long drive."""
    drive = ("[{accelerate: {to_speed: 12.0, accel: 1.2}}, {straight: {length: 700}}, "
             "{turn: {angle: 90, radius: 30}}, {slope: {grade: 0.045, length: 280}}, "
             "{straight: {length: 300}}]")
    scenario = load_scenario(scenario_path(karamat.SCENARIO), [
        f"trajectory.segments={drive}", "estimators=[]",
        "faults=[{kind: gnss_satellite_limit, start: 63.0, duration: 60, count: 3}]"], seed=seed)
    ds = open_dataset(generate_dataset(scenario, tmp_path / "d", show_progress=False))
    solution, _ = run_estimator(ds, "riss3d_tc_ekf", show_progress=False)
    e = solution_errors(ds.read("truth"), solution).errors
    window = e[(e["t"] >= 63.0) & (e["t"] <= 123.0)]
    assert len(window) > 500
    assert (window["err_d"].abs() / window["std_d"]).max() < 2.0
