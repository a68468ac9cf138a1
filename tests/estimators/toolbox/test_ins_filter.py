"""The shared INS core against the simulator's exact kinematics: fed an ideal IMU (rates or
increments) and no aiding, the batched compiled strapdown follows the true trajectory of a drive
with turns, a slope and a helix; its covariance grows without aiding and an update shrinks it."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.base import InitialState
from estimators.toolbox import aiding
from estimators.toolbox.ins_filter import InsFilter, InsNoise
from estimators.toolbox.installation import Installation
from simulator.dataset.generate import generate_streams
from simulator.earth import radii_of_curvature, wrap_angle
from simulator.errors import InputError
from simulator.replay import initial_state
from tests.conftest import scenario_data

NOISE = InsNoise(1e-3, 1e-4, 1e-3, 1e-5, 300.0, 300.0)
P0 = np.r_[[1.0] * 3, [0.1] * 3, [0.01] * 3, [0.01] * 3, [1e-4] * 3]
SEGMENTS = [{"stop": {"duration": 5}}, {"accelerate": {"to_speed": 10.0, "accel": 1.5}},
            {"turn": {"angle": 90, "radius": 30}}, {"slope": {"grade": 0.06, "length": 150}},
            {"accelerate": {"to_speed": 4.0, "accel": 1.0}},
            {"helix": {"turns": 1, "radius": 11, "rise": -3.0}}]


def _streams(output: str):
    # a rigid body: the 1.5 cm bound of trapezoidal rate integration holds for its smooth
    # motion; the automotive body's vibration is what increments are for
    data = scenario_data(SEGMENTS, sensors={"imu": {"preset": "ideal", "rate": 100,
                                                    "output": output}}, vehicle="rigid")
    streams = generate_streams(data, show_progress=False).streams
    return streams["truth"], streams["imu"]


@pytest.mark.parametrize("output", ["rate", "increment"])
def test_free_inertial_follows_the_exact_trajectory(output):
    truth, imu = _streams(output)
    init = initial_state(truth, float(imu["t"].iloc[0]), None)
    cols = {c: i for i, c in enumerate(imu.columns)}
    ins = InsFilter(init, cols, output == "increment", P0, NOISE, buffer_size=64)
    rows = imu.to_numpy()
    for k, row in enumerate(rows):
        ins.add_imu(row[0], row)
        if k % 37 == 0:  # batches of uneven length, as measurements interleave
            ins.flush()
    ins.flush()
    end = truth.iloc[-1]
    assert ins.t == pytest.approx(end["t"])
    rn, re = radii_of_curvature(ins.pos[0])
    d_north = (ins.pos[0] - np.radians(end["lat"])) * rn
    d_east = (ins.pos[1] - np.radians(end["lon"])) * re * np.cos(ins.pos[0])
    duration = end["t"] - init.t
    # a free inertial solution over a minute of turns, a slope and a helix: under a millimetre
    # from the exact trajectory with increments (0.7 mm measured), 1.5 cm with trapezoidal
    # integration of rate samples
    limit = 0.005 if output == "increment" else 0.05
    assert duration > 60 and np.hypot(d_north, d_east) < limit
    assert abs(ins.pos[2] - end["alt"]) < limit
    np.testing.assert_allclose(ins.v, end[["vn", "ve", "vd"]].to_numpy(float), atol=limit / 10)
    _, _, _, biases = ins.corrected()
    assert not biases.any()
    q_yaw = np.arctan2(2 * (ins.q[0] * ins.q[3] + ins.q[1] * ins.q[2]),
                       1 - 2 * (ins.q[2] ** 2 + ins.q[3] ** 2))
    assert abs(wrap_angle(q_yaw - end["yaw"])) < 1e-3


def test_covariance_grows_unaided_and_an_update_shrinks_it():
    truth, imu = _streams("increment")
    init = initial_state(truth, float(imu["t"].iloc[0]), None)
    ins = InsFilter(init, {c: i for i, c in enumerate(imu.columns)}, True, P0, NOISE)
    for row in imu.to_numpy()[:3000]:
        ins.add_imu(row[0], row)
    ins.flush()
    grown = np.diag(ins.kf.p).copy()
    assert np.all(grown[:6] > P0[:6] ** 2)
    ins.update(*aiding.gnss_position(ins.q, ins.pos, ins.pos), np.eye(3))
    assert np.all(np.diag(ins.kf.p)[:3] < grown[:3])


def test_a_reduced_imu_is_refused_with_a_clear_message():
    truth, imu = _streams("increment")
    init = initial_state(truth, float(imu["t"].iloc[0]), None)
    cols = {c: i for i, c in enumerate(imu.columns) if c != "gyro_x"}
    with pytest.raises(InputError, match="lacks gyro_x"):
        InsFilter(init, cols, True, P0, NOISE)


def test_a_tilted_imu_mounting_is_rotated_out():
    """An IMU mounted rolled 2 deg, pitched -3 deg and yawed 10 deg in the car (the simulator
    rotates its outputs, x_s = C_v^s x_v): the filter given the datasheet's mounting rotates
    them back and navigates the car as if the unit were aligned (the bound of the aligned
    case above); without it the same drive is metres off."""
    mounting = [2.0, -3.0, 10.0]
    data = scenario_data(SEGMENTS, sensors={"imu": {"preset": "ideal", "rate": 100,
                                                    "output": "increment",
                                                    "mounting": mounting}}, vehicle="rigid")
    streams = generate_streams(data, show_progress=False).streams
    truth, imu = streams["truth"], streams["imu"]
    init = initial_state(truth, float(imu["t"].iloc[0]), None)
    cols = {c: i for i, c in enumerate(imu.columns)}
    site = Installation.from_datasheet({"imu": {"mounting": mounting}})
    end = truth.iloc[-1]
    misses = []
    for mount in (site.mounting, None):
        ins = InsFilter(init, cols, True, P0, NOISE, mounting=mount)
        for row in imu.to_numpy():
            ins.add_imu(row[0], row)
        ins.flush()
        rn, re = radii_of_curvature(ins.pos[0])
        misses.append(np.hypot((ins.pos[0] - np.radians(end["lat"])) * rn,
                               (ins.pos[1] - np.radians(end["lon"])) * re * np.cos(ins.pos[0])))
    assert misses[0] < 0.005 and misses[1] > 1.0


def test_extra_gauss_markov_states_follow_their_closed_form():
    """Three Gauss-Markov states (sigma 2 m, tau 100 s): after an update that sets their
    estimate, the estimate decays by exp(-T / tau) and the variance returns towards sigma^2 as
    sigma^2 - (sigma^2 - P) exp(-2 T / tau) (Brown & Hwang, section 2.9)."""
    truth, imu = _streams("increment")
    init = initial_state(truth, float(imu["t"].iloc[0]), None)
    ins = InsFilter(init, {c: i for i, c in enumerate(imu.columns)}, True, P0, NOISE,
                    extra_sigma=np.full(3, 2.0), extra_tau=100.0)
    assert ins.n_states == 18
    h = np.zeros((3, 18))
    h[:, 15:] = np.eye(3)
    ins.update(np.array([-1.0, 0.5, 2.0]), h, np.eye(3))  # the states read 1, -0.5, -2 less
    x0, p0 = ins.extra.copy(), ins.kf.p[15, 15]
    np.testing.assert_allclose(x0, -4.0 / 5.0 * np.array([-1.0, 0.5, 2.0]))  # K = 4 / (4 + 1)
    rows = imu.to_numpy()
    t0 = ins.t
    for row in rows[rows[:, 0] > t0][:2000]:
        ins.add_imu(row[0], row)
    ins.flush()
    span = ins.t - t0
    np.testing.assert_allclose(ins.extra, x0 * np.exp(-span / 100.0), rtol=1e-9)
    expected = 4.0 - (4.0 - p0) * np.exp(-2 * span / 100.0)
    assert ins.kf.p[15, 15] == pytest.approx(expected, rel=1e-3)


def _turntable(scale_z: float, rate: float, seconds: float, hz: float = 100.0):
    """A level IMU on a turntable at 45 deg N spinning about its z axis at ``rate`` (rad/s),
    its z gyro reading (1 + scale_z) times the table's rate: the time, the samples (gyro with
    the Earth rate, accelerometer against normal gravity) and the true yaw."""
    from simulator.earth import OMEGA_E_RAD_S, normal_gravity
    lat = np.radians(45.0)
    t = np.arange(0.0, seconds + 0.5 / hz, 1.0 / hz)
    yaw = rate * t
    w_ie = OMEGA_E_RAD_S * np.array([np.cos(lat), 0.0, -np.sin(lat)])
    gyro = np.column_stack([np.cos(yaw) * w_ie[0], -np.sin(yaw) * w_ie[0],
                            np.full_like(t, w_ie[2] + (1.0 + scale_z) * rate)])
    accel = np.column_stack([np.zeros_like(t), np.zeros_like(t),
                             np.full_like(t, -float(normal_gravity(lat, 0.0)))])
    init = InitialState(0.0, np.array([lat, 0.0, 0.0]), np.zeros(3), np.zeros(3))
    return t, np.column_stack([t, gyro, accel]), yaw, init


TURNTABLE_COLUMNS = {c: i + 1 for i, c in enumerate(
    ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"))}
QUIET = InsNoise(1e-9, 1e-12, 1e-9, 1e-12, 300.0, 300.0)
QUIET_P0 = np.r_[[0.1] * 3, [0.01] * 3, [1e-4] * 3, [1e-6] * 3, [1e-9] * 3]


def test_yaw_response_states_grow_the_yaw_variance_as_the_scale_factor_does():
    """Unaided, a z-gyro scale-factor uncertainty sigma_s on a table turning at w gives a yaw
    error of sigma_s w T after T seconds: the yaw variance is (sigma_s w T)^2 plus its start
    (the closed form of a random constant times a known rate; the noise model without the
    states spread it over the flushes as independent increments and lost it)."""
    sigma_s, rate, seconds = 0.005, 0.5, 20.0
    _, rows, _, init = _turntable(0.0, rate, seconds)
    ins = InsFilter(init, TURNTABLE_COLUMNS, False, QUIET_P0, QUIET,
                    yaw_response_sigma=np.array([1e-3, 1e-3, sigma_s]))
    assert ins.n_states == 18 and ins.extra_start == 18
    for k, row in enumerate(rows):
        ins.add_imu(row[0], row)
        if k % 10 == 0:
            ins.flush()
    ins.flush()
    expected = QUIET_P0[8] ** 2 + (sigma_s * rate * seconds) ** 2
    assert ins.kf.p[8, 8] == pytest.approx(expected, rel=0.01)


def test_yaw_response_states_learn_a_scale_factor_from_headings():
    """With the true heading measured every 0.1 s (1 mrad), a z gyro reading 0.4 % fast on a
    table at 0.5 rad/s: the z yaw-response state converges to 0.004 within three of its own
    sigma, and the yaw follows the table."""
    scale, rate = 0.004, 0.5
    t, rows, yaw, init = _turntable(scale, rate, 30.0)
    ins = InsFilter(init, TURNTABLE_COLUMNS, False, QUIET_P0, QUIET,
                    yaw_response_sigma=np.array([1e-3, 1e-3, 0.005]))
    for k, row in enumerate(rows):
        ins.add_imu(row[0], row)
        if k % 10 == 0 and k:
            ins.flush()
            ins.update(*aiding.heading(ins.q, float(wrap_angle(yaw[k])), ins.n_states),
                       np.array([[1e-6]]))
    sigma = np.sqrt(ins.kf.p[17, 17])
    assert sigma < 2e-4 and abs(ins.yaw_response[2] - scale) < 3 * sigma
    assert abs(ins.bg[2]) < 1e-4  # the scale factor is not taken as a bias


def _accel_z_bias_growth(window: float, amplitude: float, step: float) -> float:
    """The growth of the z accelerometer bias variance over 10 s of a level IMU at rest whose
    z reading vibrates at 5 Hz with ``amplitude`` (m/s^2) and steps by ``step`` at 3 s, with a
    0.3 % scale-factor uncertainty, flushed every 0.05 s (the drift of the bias itself made
    negligible)."""
    noise = InsNoise(1e-9, 1e-12, 1e-9, 1e-12, 1e9, 1e9, accel_scale_sigma=0.003)
    t, rows, _, init = _turntable(0.0, 0.0, 10.0)
    rows[:, 6] += amplitude * np.sin(2 * np.pi * 5.0 * t) + step * (t >= 3.0)
    ins = InsFilter(init, TURNTABLE_COLUMNS, False, QUIET_P0, noise, scale_noise_window=window)
    for k, row in enumerate(rows):
        ins.add_imu(row[0], row)
        if k % 5 == 0:
            ins.flush()
    ins.flush()
    return ins.kf.p[11, 11] - QUIET_P0[11] ** 2


def test_scale_noise_on_windows_counts_a_step_and_not_a_vibration():
    """The scale-factor noise (s dx)^2 from the change dx of the mean reading: on 1 s windows a
    step of 1 m/s^2 adds s^2 once (0.99 s^2: the trapezoid puts half a sample of it in the
    window before), where a 5 Hz vibration of 0.3 m/s^2, whole periods in each window, adds
    nothing; flush by flush (window 0) the vibration adds s^2 times the sum of squares of the
    changes between the 0.05 s means of its trapezoid increments, computed here from the
    readings (14.2 (m/s^2)^2 over the 10 s, 0.27 m/s^2 rms)."""
    s2 = 0.003**2
    assert _accel_z_bias_growth(1.0, 0.0, 1.0) == pytest.approx(0.99 * s2, rel=0.01)
    assert _accel_z_bias_growth(1.0, 0.3, 0.0) < 1e-6 * s2
    t = np.arange(0.0, 10.005, 0.01)
    vibration = 0.3 * np.sin(2 * np.pi * 5.0 * t)
    means = (0.5 * (vibration[1:] + vibration[:-1])).reshape(-1, 5).mean(axis=1)
    expected = s2 * np.sum(np.diff(means) ** 2)
    assert _accel_z_bias_growth(0.0, 0.3, 0.0) == pytest.approx(expected, rel=1e-6)
