"""Cho & Choi 2006 estimators: the transition matrices against finite differences and the
paper's eq. 17, the standstill gyro calibration against fixed biases, an error-free drive, and
the reproduction's own measures (the time to converge, the fix-noise condition); the paper's
claims are judged by ``landnav reproduce cho2006`` (``simulator.reproduce.cho2006``,
docs/reproduction_cho2006.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from estimators.builtin.cho2006 import (
    Drm2Ekf,
    drm1_jacobian,
    drm1_transition,
    drm2_jacobian,
    drm2_transition,
)
from estimators.builtin.cho2006_tuning import ROLL_GRADIENT, Tuning
from estimators.registry import get_estimator
from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import Dataset, open_dataset
from simulator.errors import InputError
from simulator.pipeline import estimate, generate, load_scenario
from simulator.reproduce import cho2006 as exp
from simulator.reproduce.measures import moving_off
from simulator.reproduce.paper import scenario_path
from simulator.scenario import Scenario, validate_data
from simulator.scoring.consistency import normalised_errors
from tests.synthetic import FLAT_LOOP

G = 9.8
U2 = np.array([0.7, 0.05, -0.2])  # f_x, w_y, w_z
U1 = np.array([0.7, 2.1, -0.2])  # f_x, f_y, w_z
U2_LATERAL = np.array([0.7, 0.05, -0.2, -0.35])  # and the IMU's lateral velocity (m/s)
X = np.array([3.0, -4.0, 12.0, 0.05, 2.5, 0.02, -0.03, 0.05])


def _dataset(name: str, seed: int, root, overrides: list[str] | None = None) -> Dataset:
    """scenarios/<name>.yaml generated with ``seed`` under ``root`` (reused if present)."""
    out = root / f"{name}-{seed}"
    if not out.exists():
        generate(load_scenario(scenario_path(f"{name}.yaml"), overrides, seed), out)
    return open_dataset(out)


def _run(ds: Dataset, name: str, config: dict | None = None):
    return estimate(ds, {"name": name, "label": None, "init": None, "config": config})[0]


def _numeric_jacobian(f, x: np.ndarray, step: float = 1e-6) -> np.ndarray:
    out = np.empty((x.size, x.size))
    for j in range(x.size):
        dx = np.zeros_like(x)
        dx[j] = step
        out[:, j] = (f(x + dx) - f(x - dx)) / (2 * step)
    return out


@pytest.mark.parametrize("transition, jacobian, u", [
    (drm2_transition, drm2_jacobian, U2), (drm2_transition, drm2_jacobian, U2_LATERAL),
    (drm1_transition, drm1_jacobian, U1)], ids=["DRM2", "DRM2-lateral", "DRM1"])
def test_transition_matrix_is_the_jacobian_of_the_propagation(transition, jacobian, u):
    def f(x):
        return transition(x[None, :], None, u, 0.1, G)[0]

    np.testing.assert_allclose(jacobian(X, u, 0.1, G), _numeric_jacobian(f, X), atol=1e-8)


def test_an_imu_ahead_of_the_rear_axle_keeps_its_speed_on_a_circle():
    """A car on a level circle at constant speed V: the rear axle moves along the path, an
    IMU a metres ahead of it has the same forward speed V and the lateral velocity a w; its
    forward accelerometer reads the centripetal share -a w^2 (f = dv/dt + w x v in the body
    frame). DRM2 with the lateral velocity as input keeps V; eq. 24c alone loses a w^2 t."""
    arm, w, v0, dt = 1.7, 0.8, 4.0, 0.1
    u = np.array([-arm * w * w, 0.0, w, arm * w])
    x = np.zeros((1, 9))
    x[0, 2] = v0
    for _ in range(100):  # 10 s
        x = drm2_transition(x, None, u, dt, G)
    assert abs(x[0, 2] - v0) < 1e-12
    x_rigid = np.zeros((1, 9))
    x_rigid[0, 2] = v0
    for _ in range(100):
        x_rigid = drm2_transition(x_rigid, None, u[:3], dt, G)
    assert x_rigid[0, 2] == pytest.approx(v0 - arm * w * w * 10.0)


def test_drm2_heading_rate_of_a_rolled_body_is_the_euler_rate():
    """A level turn at psi_dot = 0.55 rad/s and 12 m/s (``urban_canyon``'s junctions), the
    body rolled out of it by phi = -k V psi_dot: its gyros read w_y = psi_dot sin(phi), w_z =
    psi_dot cos(phi) (ZYX Euler rates, theta = 0). The heading rate DRM2 integrates is
    psi_dot to within the roll model's own second-order slip (it takes phi from w_z, not
    psi_dot), far inside the w_z phi^2 / 2 that w_z alone loses."""
    psi_dot, speed = 0.55, 12.0
    roll = -ROLL_GRADIENT * speed * psi_dot
    filt = Drm2Ekf.__new__(Drm2Ekf)
    filt._tuning = Tuning(np.eye(11), np.eye(11), roll_gradient=ROLL_GRADIENT,
                          rear_axle_m=1.7)
    filt._x = np.array([0.0, 0.0, speed, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    filt._p = np.eye(11)
    u = np.array([0.0, psi_dot * math.sin(roll), psi_dot * math.cos(roll)])
    lost = psi_dot - u[2]
    assert lost == pytest.approx(psi_dot * roll**2 / 2.0, rel=1e-3)
    out = filt._inputs(u)
    assert abs(out[2] - psi_dot) < 1e-3 * lost
    assert out[1] == pytest.approx(u[1] + ROLL_GRADIENT * speed * u[2] ** 2)  # pitch rate
    assert out[3] == pytest.approx(1.7 * u[2])  # the IMU's lateral velocity


def test_drm2_transition_matrix_has_the_terms_of_eq_17():
    dt = 0.1
    phi = drm2_jacobian(X, U2, dt, G)
    v, th, psi, d_ax = X[2], X[3], X[4], X[5]
    sf_ax = 1.0 - d_ax
    # A_1, A_2 exactly when speed and heading do not change over the step (trapezoidal rule)
    steady = np.array([G * math.sin(th) / sf_ax, U2[1], 0.0])
    still = drm2_jacobian(X, steady, dt, G)
    assert still[0, 2] == pytest.approx(math.cos(psi) * dt)  # A_1
    assert still[1, 2] == pytest.approx(math.sin(psi) * dt)
    assert still[0, 4] == pytest.approx(-v * math.sin(psi) * dt)  # A_2
    assert still[1, 4] == pytest.approx(v * math.cos(psi) * dt)
    assert phi[2, 3] == pytest.approx((G * math.sin(th) ** 2 - sf_ax * U2[0] * math.sin(th)
                                       - G * math.cos(th) ** 2) * dt)  # A_3
    assert phi[3, 6] == pytest.approx(-U2[1] * dt)  # A_4 (sign: true = (1 - d) measured)
    assert phi[4, 7] == pytest.approx(-U2[2] * dt)


def test_registered_with_the_spec_config_keys():
    for name in ("dr2d_drm1_ekf", "dr2d_drm2_ekf", "dr2d_drm2_spkf"):
        assert "standstill_calibration" in get_estimator(name).defaults
    assert {"alpha", "beta", "w0", "sigma_set"} <= set(get_estimator("dr2d_drm2_spkf").defaults)
    for name in ("dr2d_drm1_ekf", "dr2d_drm2_ekf", "dr2d_drm2_spkf"):
        assert get_estimator(name).defaults["tuning"] == "datasheet"


@pytest.fixture(scope="module")
def root(tmp_path_factory):
    return tmp_path_factory.mktemp("cho2006")


@pytest.mark.parametrize("name", ["dr2d_drm2_ekf", "dr2d_drm2_spkf", "dr2d_drm1_ekf"])
def test_standstill_calibration_finds_fixed_gyro_biases(root, name):
    """Gyro biases fixed at 0.01, 0.02, -0.03 rad/s, no other IMU error: the 10 s standstill
    returns them plus the Earth rate on the body axes (< 6e-5 rad/s at 36 deg N)."""
    bias = [0.01, 0.02, -0.03]
    ds = _dataset("cho2006_situation2", 1, root / "bias", [
        "sensors.imu.preset=ideal", f"sensors.imu.gyro.bias={{fixed: {bias}}}".replace(" ", ""),
    ])
    sol = _run(ds, name)
    assert sol["gyro_bias_z"].iloc[-1] == pytest.approx(bias[2], abs=6e-5)
    if "gyro_bias_y" in sol:
        assert sol["gyro_bias_y"].iloc[-1] == pytest.approx(bias[1], abs=6e-5)
    off = _run(ds, name, config={"standstill_calibration": False})
    assert np.all(off["gyro_bias_z"] == 0.0)


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_standstill_calibration_survives_the_papers_fix_noise(root, seed):
    """At the paper's fix level a stopped receiver reports speeds of 0.5 m/s per axis: a fix's
    speed above 0.5 m/s alone (61 % of them) must not end the initial standstill, whose 10 s
    average then finds fixed gyro biases as with ideal fixes (< 6e-5 rad/s: the Earth rate)."""
    bias = [0.01, 0.02, -0.03]
    ds = _dataset("cho2006_situation2", seed, root / "bias-paper-fixes", [
        "sensors.imu.preset=ideal", f"sensors.imu.gyro.bias={{fixed: {bias}}}".replace(" ", ""),
        *exp.PAPER_FIXES])
    sol = _run(ds, "dr2d_drm2_ekf", config={"tuning": "paper"})
    assert sol["gyro_bias_z"].iloc[-1] == pytest.approx(bias[2], abs=6e-5)


def test_error_free_sensors_track_the_drive(root):
    """Ideal IMU and receiver, no initial error. The EKF keeps only the 10 Hz integration and
    the flat-Earth position of eq. 18 (measured 0.12 m, 0.11 deg). The SPKF starts from the
    180 deg heading sigma of eq. 33 too, and its update is a statistical linearisation over
    points half a turn apart until that shrinks: measured 19 m and 12 deg while it settles,
    1.3 m and 0.6 deg from 60 s after moving off (docs/reproduction_cho2006.md)."""
    # a rigid body: the error-free case checks the filters' own integration (on the automotive
    # body, which rolls, pitches and slips where the planar model assumes a level body without
    # slip, the EKF's error is 2.2 m)
    ds = _dataset("cho2006_situation2", 1, root / "ideal",
                     ["sensors.imu.preset=ideal", "sensors.gnss.preset=ideal", "vehicle=rigid"])
    t, horizontal, d_yaw = exp.track_errors(ds, _run(ds, "dr2d_drm2_ekf"))
    assert horizontal.max() < 0.5
    assert np.abs(d_yaw).max() < 0.3
    assert t[-1] > 150.0
    t, horizontal, d_yaw = exp.track_errors(ds, _run(ds, "dr2d_drm2_spkf"))
    late = t >= moving_off(ds.read("truth")) + exp.SETTLE_S
    assert horizontal[late].max() < 2.0
    assert np.abs(d_yaw[late]).max() < 1.0


def test_drm1_follows_a_flat_drive_with_error_free_sensors(tmp_path):
    """DRM1 has no pitch, so on the level FLAT_LOOP with ideal sensors only the integration
    error is left (measured: 0.22 m, 0.23 deg)."""
    # a rigid body: level and without slip, as DRM1 assumes (the automotive body: 209 m)
    data = {"name": "flat", "seed": 1, "limits": {"roll_gradient": 0.0}, "vehicle": "rigid",
            "start": {"utc": "2024-05-01T03:00:00Z", "lat": 36.35, "lon": 127.38, "alt": 60.0,
                      "heading": 30.0},
            "trajectory": {"kind": "segments", "segments": FLAT_LOOP},
            "sensors": {"imu": {"preset": "ideal", "rate": 100},
                        "gnss": {"preset": "ideal", "rate": 1, "outputs": ["fix"]}}}
    scenario = Scenario(tmp_path / "flat.yaml", validate_data(data, "flat.yaml"), [])
    ds = open_dataset(generate_dataset(scenario, tmp_path / "flat", show_progress=False))
    t, horizontal, d_yaw = exp.track_errors(ds, _run(ds, "dr2d_drm1_ekf"))
    assert horizontal.max() < 0.5
    assert np.abs(d_yaw).max() < 0.5


def test_increment_output_gives_the_rate_output_solution(root):
    """The IMU samples are averaged over each 0.1 s step from rates or from increments alike."""
    # rigid, as the error-free case above (same dataset); on the automotive body the two
    # outputs differ by 0.09 m, the vibration's share of averaging rates against increments
    rates = _dataset("cho2006_situation2", 1, root / "ideal",
                        ["sensors.imu.preset=ideal", "sensors.gnss.preset=ideal",
                         "vehicle=rigid"])
    increments = _dataset("cho2006_situation2", 1, root / "increments",
                             ["sensors.imu.preset=ideal", "sensors.gnss.preset=ideal",
                              "sensors.imu.output=increment", "vehicle=rigid"])
    _, h_rate, yaw_rate = exp.track_errors(rates, _run(rates, "dr2d_drm2_ekf"))
    _, h_inc, yaw_inc = exp.track_errors(increments, _run(increments, "dr2d_drm2_ekf"))
    assert h_inc.max() < 0.5 and np.abs(yaw_inc).max() < 0.3
    assert abs(h_inc.max() - h_rate.max()) < 0.1


@pytest.mark.parametrize("config, key", [({"alpha": 0.0}, "alpha"), ({"alpha": 1.5}, "alpha"),
                                         ({"w0": 1.0}, "w0"), ({"beta": -1.0}, "beta"),
                                         ({"sigma_set": "cubature"}, "sigma_set")])
def test_spkf_refuses_parameters_outside_their_ranges(root, config, key):
    ds = _dataset("cho2006_situation2", 1, root)
    with pytest.raises(InputError, match=f"'{key}' of estimator dr2d_drm2_spkf"):
        _run(ds, "dr2d_drm2_spkf", config=config)


# -- the reproduction's figures (simulator.reproduce.cho2006) -----------------------------------

def test_converge_time_is_the_first_sample_after_the_last_bad_one():
    t = np.arange(6.0)
    assert exp.converge_time(t, np.array([1.0, 0.1, 0.9, 0.1, 0.1, 0.0]), 0.5, 99.0) == 3.0
    assert exp.converge_time(t, np.full(6, 0.1), 0.5, 99.0) == 0.0
    # never below at the end: censored at the drive's end (a pair that never converges ties)
    assert exp.converge_time(t, np.array([0.1] * 5 + [0.6]), 0.5, 99.0) == 99.0
    assert exp.converge_time(t, np.array([0.1] * 5 + [np.nan]), 0.5, 99.0) == 99.0


@pytest.mark.parametrize("overrides, low, high", [(exp.PAPER_FIXES, 10.0, 20.0),
                                                  (exp.LANDNAV_FIXES, 0.3, 3.0)])
def test_the_fix_noise_condition_is_what_it_is_called(root, overrides, low, high):
    """The situations' fix-noise condition, measured against the truth on seed 1: the paper's R
    level (eq. 35: 15 m per position axis) and landnav's carrier-smoothed receiver (about 1 m);
    bounds from the 180 fixes' own spread (a per-axis RMS of 360 values within about 10 %)."""
    ds = _dataset("cho2006_situation3", 1, root / f"fixes{len(overrides)}", list(overrides))
    assert low < exp.fix_rms(ds) < high


@pytest.mark.parametrize("name", ["dr2d_drm2_ekf", "dr2d_drm1_ekf"])
def test_every_stop_recalibrates_a_drifting_gyro_bias(tmp_path, name):
    """A gyro whose bias ramps (2e-5 rad/s^2, drawn sign) and two stops, 110 s apart, seen by
    the odometer: the calibration held between them is the first stop's, and after the second
    it is that stop's bias (truth_sensors), the 2.2e-3 rad/s the bias moved in between
    removed. The Earth rate's vertical part (4.3e-5 rad/s at 36 deg N) is in both."""
    segments = [{"stop": {"duration": 10}}, {"accelerate": {"to_speed": 10.0, "accel": 1.0}},
                {"straight": {"length": 900}}, {"accelerate": {"to_speed": 0.0, "accel": 1.0}},
                {"stop": {"duration": 10}}, {"accelerate": {"to_speed": 10.0, "accel": 1.0}},
                {"straight": {"length": 200}}]
    data = {"name": "stops", "seed": 2, "vehicle": "rigid",
            "start": {"utc": "2024-05-01T03:00:00Z", "lat": 36.35, "lon": 127.38, "alt": 60.0,
                      "heading": 30.0},
            "trajectory": {"kind": "segments", "segments": segments},
            "sensors": {"imu": {"preset": "ideal", "rate": 100, "gyro": {"ramp": 2e-5}},
                        "odometer": {"preset": "ideal", "rate": 10},
                        "gnss": {"preset": "ideal", "rate": 1, "outputs": ["fix"]}}}
    scenario = Scenario(tmp_path / "stops.yaml", validate_data(data, "stops.yaml"), [])
    ds = open_dataset(generate_dataset(scenario, tmp_path / "stops", show_progress=False))
    truth = ds.read("truth_sensors")
    odo = ds.read("odometer")
    stopped = odo["t"][(odo["speed"].abs() < 1e-3) & (odo["t"] > 20.0)].to_numpy()
    first = truth.loc[truth["t"] < 10.0, "gyro_bias_z"].mean()
    second = truth.loc[(truth["t"] > stopped[0]) & (truth["t"] < stopped[-1]),
                       "gyro_bias_z"].mean()
    assert abs(second - first) > 2e-3  # the ramp moved the bias between the stops
    sol = _run(ds, name)
    t = sol["t"].to_numpy()
    between = sol["gyro_bias_z"].to_numpy()[(t > 20.0) & (t < stopped[0])]
    assert np.allclose(between, first, atol=6e-5)
    assert sol["gyro_bias_z"].iloc[-1] == pytest.approx(second, abs=6e-5)


# -- consistency of the default (datasheet) tuning -----------------------------------------

CONSISTENCY_SEEDS = (1, 2, 3)


def _nse(ds: Dataset, solution) -> dict[str, float]:
    """Per axis, the mean of (error / sigma)^2 from 60 s after the first row (SPEC section 8),
    the axes the solution has a sigma for."""
    nse = normalised_errors(ds.read("truth"), solution)
    return {axis: value for axis, value in nse.items() if np.isfinite(value)}


@pytest.fixture(scope="module")
def consistency(root):
    """nse per filter, seed and axis on situation II's road (Crossbow unit, 165 s), no
    initial error, default tuning; and under ``"fix"`` the receiver's own fixes' (their
    reported 1-sigma against their error from the truth)."""
    out = {}
    for seed in CONSISTENCY_SEEDS:
        ds = _dataset("cho2006_situation2", seed, root / "consistency", ["estimators=[]"])
        for name in ("dr2d_drm1_ekf", "dr2d_drm2_ekf", "dr2d_drm2_spkf"):
            out[name, seed] = _nse(ds, _run(ds, name))
        fixes = ds.read("gnss_fix")
        fixes = fixes[fixes["fix"] > 0].assign(roll=np.nan, pitch=np.nan, yaw=np.nan)
        out["fix", seed] = _nse(ds, fixes)
    return out


@pytest.mark.parametrize("name", ["dr2d_drm1_ekf", "dr2d_drm2_ekf", "dr2d_drm2_spkf"])
def test_datasheet_tuning_is_never_overconfident_tenfold(consistency, name):
    """No axis of any seed has a mean squared normalised error above 10 (measured at most
    1.9, the SPKF's east velocity on seed 3); 2-D filters write NaN height and roll (SPEC
    section 7)."""
    for seed in CONSISTENCY_SEEDS:
        nse = consistency[name, seed]
        assert set(nse) >= {"n", "e", "vn", "ve", "yaw"}
        assert not {"d", "vd", "roll"} & set(nse)  # NaN: not estimated
        assert all(value < 10.0 for value in nse.values()), (seed, nse)


def _mean(consistency, name: str, axis: str) -> float:
    return float(np.mean([consistency[name, seed][axis] for seed in CONSISTENCY_SEEDS]))


@pytest.mark.parametrize("name", ["dr2d_drm1_ekf", "dr2d_drm2_ekf", "dr2d_drm2_spkf"])
def test_datasheet_position_knows_the_fix_error(consistency, name):
    """The position's error is the fix's drive-long error, carried as two states sized by the
    fix's own report (``FixErrorModel.reported_drive_long_sigma``): on a 165 s drive each
    seed's horizontal (error / sigma)^2 is one draw of that error, so it follows the
    receiver's own fixes' (their reported 1-sigma against their error, an independent figure:
    the receiver's least squares): mean over the seeds within a factor 2 of theirs (measured:
    fixes north 0.61, east 0.21; DRM1 0.62 / 0.20, DRM2 EKF 0.82 / 0.29, SPKF 0.44 / 0.21)."""
    for axis in ("n", "e"):
        own, fix = _mean(consistency, name, axis), _mean(consistency, "fix", axis)
        assert 0.5 * fix < own < 2.0 * fix, (axis, own, fix)


@pytest.mark.parametrize("name", ["dr2d_drm2_ekf", "dr2d_drm2_spkf"])
def test_drm2_datasheet_tuning_is_consistent(consistency, name):
    """Mean over the seeds within 0.3-3 on velocity and yaw (measured EKF: velocity 0.97 and
    0.93, yaw 1.07; SPKF 1.25, 1.31, 1.21), the position below 3 (it is the fix's: above).
    Pitch is left out of the mean: it carries the forward accelerometer's bias (the two are
    one unobservable combination, eq. 11), so each seed's pitch error is one draw of that
    bias over g and three seeds do not pin its mean (measured 0.0-0.4 per seed against a
    sigma of 1.7 deg from the 30 mg datasheet bias)."""
    for axis in ("vn", "ve", "yaw"):
        assert 0.3 < _mean(consistency, name, axis) < 3.0, axis
    for axis in ("n", "e"):
        assert _mean(consistency, name, axis) < 3.0, axis


def test_drm1_datasheet_tuning_is_cautious_but_not_tenfold(consistency):
    """DRM1 sits at the band's lower edge: mean over the seeds measured 0.84 and 0.78
    (velocity), 0.30 (yaw). Its accelerometer-bias states take the road's grade and bank as
    a random walk (its level frame senses g sin(grade), eq. 2), which the 5 % slopes here
    need and the level stretches do not. Asserted: velocity and yaw between 0.15 and 3,
    position below 3 (it is the fix's: above)."""
    for axis in ("n", "e", "vn", "ve", "yaw"):
        mean = _mean(consistency, "dr2d_drm1_ekf", axis)
        assert (0.0 if axis in ("n", "e") else 0.15) < mean < 3.0, (axis, mean)
