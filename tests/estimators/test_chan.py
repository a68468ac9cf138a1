"""tc_ekf and tc_ukf (Chan et al.): the EKF's error model against the nonlinear mechanisation,
both filters against the truth on a noise-free drive (position, attitude, and the receiver clock
the simulator drew), and the configuration contract."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.builtin.chan import N_STATES, error_dynamics
from estimators.registry import get_estimator
from estimators.toolbox import nav_error
from estimators.toolbox.strapdown import rk4_step
from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import open_dataset
from simulator.earth import euler_to_quat, quat_multiply, quat_to_dcm, radii_of_curvature
from simulator.errors import InputError
from simulator.reproduce.chan import run_filter
from simulator.scenario import load_scenario
from tests.conftest import REPO


def _tangent_error(x_est: np.ndarray, x_true: np.ndarray) -> np.ndarray:
    """[dr, dv, psi] of an estimated against a true total state (lat, lon, h, v, q)."""
    rn, re = radii_of_curvature(x_true[0])
    dr = [(x_est[0] - x_true[0]) * (rn + x_true[2]),
          (x_est[1] - x_true[1]) * (re + x_true[2]) * np.cos(x_true[0]), x_true[2] - x_est[2]]
    dq = quat_multiply(x_est[6:10], x_true[6:10] * np.array([1, -1, -1, -1]))
    return np.concatenate([dr, x_est[3:6] - x_true[3:6], 2.0 * dq[1:4] * np.sign(dq[0])])


def test_error_model_predicts_the_growth_of_small_errors():
    """F of eqs. 4-6 (psi convention) against the nonlinear equations 1-3: two states a small
    error apart, with a biased IMU in the estimate, integrated over 10 ms with RK4; the change
    of their difference is F dx dt to within the second-order terms the model drops."""
    lat, v = np.radians(40.0), np.array([15.0, -8.0, 0.3])
    q = euler_to_quat(0.05, -0.03, 2.0)
    x_true = np.concatenate([[lat, 2.0, 200.0], v, q])
    w = np.array([0.01, -0.02, 0.3])
    f = np.array([1.5, 3.0, -9.7])
    dx = np.zeros(N_STATES)
    dx[0:9] = [3.0, -2.0, 1.0, 0.05, -0.04, 0.02, 2e-3, -1e-3, 3e-3]
    dx[9:12] = [0.02, -0.03, 0.01]  # accelerometer bias estimate minus truth
    dx[12:15] = [1e-3, -2e-3, 1.5e-3]  # gyro bias estimate minus truth
    q_e, v_e, pos_e = nav_error.perturb(q, v, x_true[0:3], dx[0:9])
    x_est = np.concatenate([pos_e, v_e, q_e])
    dt = 0.01
    work = np.empty((5, 10))
    e0 = _tangent_error(x_est, x_true)
    a, b = x_true.copy(), x_est.copy()
    rk4_step(a, w, w, w, f, f, f, dt, work)
    rk4_step(b, w - dx[12:15], w - dx[12:15], w - dx[12:15], f - dx[9:12], f - dx[9:12],
             f - dx[9:12], dt, work)
    rate = (_tangent_error(b, a) - e0) / dt
    predicted = error_dynamics(x_true[0:3], v, quat_to_dcm(q), f) @ dx
    np.testing.assert_allclose(rate[3:6], predicted[3:6], atol=2e-3)  # m/s^2
    # rad/s; second order: |psi| |dbg| = 6e-6
    np.testing.assert_allclose(rate[6:9], predicted[6:9], atol=1e-5)
    np.testing.assert_allclose(rate[0:3], predicted[0:3], atol=2e-3)  # m/s


@pytest.fixture(scope="module")
def noise_free(tmp_path_factory):
    """The initial-error drive with an ideal IMU and error-free ranges, but a real TCXO
    receiver clock (bias and drift to estimate), on a rigid body (the constraint the filters
    apply holds exactly there; the automotive body's side slip would break it)."""
    sc = load_scenario(REPO / "scenarios" / "chan_initial_error.yaml",
                       ["sensors.imu.preset=ideal", "sensors.gnss.preset=ideal",
                        "sensors.gnss.clock=tcxo", "vehicle=rigid"], seed=5)
    return open_dataset(generate_dataset(sc, tmp_path_factory.mktemp("chan") / "d",
                                         show_progress=False))


@pytest.mark.parametrize("name", ["tc_ekf", "tc_ukf"])
def test_noise_free_drive_gives_the_truth_and_the_receiver_clock(noise_free, name):
    solution, error = run_filter(noise_free, name)
    assert error.max() < 0.3
    truth = noise_free.read("truth")
    yaw = np.interp(solution["t"], truth["t"], np.unwrap(truth["yaw"]))
    assert np.abs(np.angle(np.exp(1j * (solution["yaw"] - yaw)))).max() < np.radians(0.1)
    clock = noise_free.read("truth_gnss").groupby("t")[["receiver_clock",
                                                         "receiver_clock_drift"]].first()
    at = solution[["t", "clock_bias", "clock_drift"]].merge(clock.reset_index(), on="t")
    assert len(at) > 100  # one row at each GNSS epoch
    assert np.abs(at["receiver_clock"]).max() > 100.0  # a clock worth estimating
    np.testing.assert_allclose(at["clock_bias"], at["receiver_clock"], atol=0.5)
    np.testing.assert_allclose(at["clock_drift"], at["receiver_clock_drift"], atol=0.05)
    # what is not estimated is absent from the solution, not made up; the NIS is written at
    # the GNSS epochs only (NaN between them, SPEC section 8)
    assert not solution.drop(columns=["nis_gnss", "nis_gnss_dof"]).isna().any().any()
    nis = solution.dropna(subset=["nis_gnss"])
    assert len(nis) > 100 and (nis["nis_gnss_dof"] >= 8).all()
    assert "odometer_scale_factor" not in solution


def test_registered_with_the_spec_config_keys():
    for name in ("tc_ukf", "tc_ekf"):
        cls = get_estimator(name)
        assert cls.defaults["nhc"] is True
        assert {"gnss_raw", "imu"} <= set(cls.needs)
    assert get_estimator("tc_ukf").defaults["alpha"] == 0.99
    assert get_estimator("tc_ukf").defaults["beta"] == 2.0
    with pytest.raises(InputError, match="unknown config key"):
        get_estimator("tc_ekf")(config={"gamma": 1}, initial=None, columns={}, units={})


def test_z_accelerometer_misalignment_states_grow_the_vertical_velocity_variance():
    """A car standing rolled by 30 deg (the specific force f_y = g sin 30 deg on its y axis),
    no GNSS: the two states of the z accelerometer's misalignment towards x and y (prior
    sigma_m) add (C_b^n[2, 2] sigma_m |f_xy| T)^2 to the vertical velocity's variance after T
    seconds, the closed form of a random constant times a known force (the filter otherwise
    identical, its states' prior set to 0). tc_ekf: the UKF forms its covariance only at an
    update, and its points take the same states in ``_propagate_points``."""
    from estimators.base import InitialState
    from simulator.earth import OMEGA_E_RAD_S, euler_to_dcm, normal_gravity

    lat, roll, seconds, sigma_m = np.radians(45.0), np.radians(30.0), 20.0, 1e-3
    c_bn = euler_to_dcm(roll, 0.0, 0.0)
    g = float(normal_gravity(lat, 0.0))
    f_body = c_bn.T @ np.array([0.0, 0.0, -g])
    w_body = c_bn.T @ (OMEGA_E_RAD_S * np.array([np.cos(lat), 0.0, -np.sin(lat)]))
    columns = {"imu": {c: i + 1 for i, c in enumerate(
        ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"))}}
    quiet = {"nhc": False, "accel_noise": 1e-9, "gyro_noise": 1e-12, "accel_bias_walk": 0.0,
             "gyro_bias_walk": 0.0, "accel_bias_std": 1e-6, "gyro_bias_std": 1e-9,
             "initial_attitude_std": [1e-6] * 3, "initial_velocity_std": 1e-3,
             "accel_scale_factor": 0.0, "gyro_scale_factor": 0.0}

    def vd_variance(m_std: float) -> float:
        initial = InitialState(0.0, np.array([lat, 0.0, 0.0]), np.zeros(3),
                               np.array([roll, 0.0, 0.0]))
        est = get_estimator("tc_ekf")({**quiet, "accel_z_misalignment_std": m_std}, initial,
                                  columns, {}, imu_output="rate")
        for t in np.arange(0.0, seconds + 1e-9, 0.01):
            est.on_imu(float(t), np.r_[t, w_body, f_body])
        return float(est.solution(seconds)[14]) ** 2  # std_vd

    expected = (c_bn[2, 2] * sigma_m * np.hypot(*f_body[:2]) * seconds) ** 2
    assert vd_variance(sigma_m) - vd_variance(0.0) == pytest.approx(expected, rel=0.02)
