"""Each aiding measurement's Jacobian against central finite differences of its own h(x),
taken with the error convention of ``nav_error`` (estimate = truth perturbed by dx), and the
magnetometer calibration against a synthetic field with hard iron."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.toolbox import aiding
from estimators.toolbox.ins_error import BG
from estimators.toolbox.nav_error import perturb
from simulator.earth import OMEGA_E_RAD_S, euler_to_dcm, euler_to_quat, quat_to_dcm

Q_TRUE = euler_to_quat(0.06, -0.09, 2.4)
V_TRUE = np.array([-6.0, 8.5, 0.3])
POS = np.array([np.radians(21.0), np.radians(105.8), 12.0])
EPS = np.r_[[1e-3] * 3, [1e-5] * 3, [1e-7] * 3]


def _jacobian(measure) -> np.ndarray:
    cols = [(measure(e) - measure(-e)) / (2 * e[i]) for i, e in enumerate(np.diag(EPS))]
    return np.array(cols).T


def _check(measure, h_analytic):
    numeric = _jacobian(measure)
    np.testing.assert_allclose(h_analytic[:, :9], numeric, rtol=1e-5, atol=1e-8)


def test_gnss_position_with_lever_arm():
    arm = np.array([1.2, -0.4, -1.5])
    truth = aiding.gnss_position(Q_TRUE, POS, POS, arm)[0]  # antenna offset from the IMU, NED
    pos_gnss = POS  # measured at the IMU position: dz of the truth is the lever arm itself
    np.testing.assert_allclose(truth, quat_to_dcm(Q_TRUE) @ arm, atol=1e-9)

    def measure(dx):
        q, _, pos = perturb(Q_TRUE, V_TRUE, POS, dx)
        return aiding.gnss_position(q, pos, pos_gnss, arm)[0]

    _check(measure, aiding.gnss_position(Q_TRUE, POS, pos_gnss, arm)[1])


@pytest.mark.parametrize("name", ["velocity", "speed", "course", "odometer", "odometer_x",
                                  "heading", "zupt"])
def test_velocity_and_attitude_jacobians(name):
    fns = {
        "velocity": lambda q, v: aiding.gnss_velocity(v, V_TRUE),
        "speed": lambda q, v: aiding.ground_speed(v, 10.0),
        "course": lambda q, v: aiding.course(v, 2.0),
        "odometer": lambda q, v: aiding.odometer(q, v, 10.0),
        "odometer_x": lambda q, v: aiding.odometer(q, v, 10.0, nhc=False),
        "heading": lambda q, v: aiding.heading(q, 2.3),
        "zupt": lambda q, v: aiding.zero_velocity(v),
    }
    fn = fns[name]

    def measure(dx):
        q, v, _ = perturb(Q_TRUE, V_TRUE, POS, dx)
        return fn(q, v)[0]

    _check(measure, fn(Q_TRUE, V_TRUE)[1])


def test_values_at_the_truth():
    c_nb = quat_to_dcm(Q_TRUE).T
    dz, _ = aiding.odometer(Q_TRUE, V_TRUE, 0.0)
    np.testing.assert_allclose(dz, c_nb @ V_TRUE, atol=1e-12)
    assert aiding.heading(Q_TRUE, 2.4)[0][0] == pytest.approx(0.0, abs=1e-12)
    # atan2 gives -pi + 1e-3 here: the residual against pi wraps to +1e-3, not -2 pi + 1e-3
    assert aiding.course(np.array([-1.0, -1e-3, 0]), np.pi)[0][0] == pytest.approx(
        1e-3, rel=1e-3)
    assert aiding.ground_speed(np.array([3.0, 4.0, 9.0]), 5.0)[0][0] == pytest.approx(0.0)


def test_zero_rate_sees_the_earth_rate_and_the_gyro_bias_error():
    c_nb = quat_to_dcm(Q_TRUE).T
    w_ie_b = c_nb @ (OMEGA_E_RAD_S * np.array([np.cos(POS[0]), 0, -np.sin(POS[0])]))
    dbg = np.array([1e-3, -2e-3, 5e-4])  # bias estimate too high: output reads too low
    dz, h = aiding.zero_rate(Q_TRUE, POS[0], w_ie_b - dbg)
    x = np.zeros(15)
    x[BG] = dbg
    np.testing.assert_allclose(dz, h @ x, atol=1e-15)


def test_barometric_height_removes_the_offset():
    dz, h = aiding.barometric_height(50.0, 62.0, 10.0)
    assert dz[0] == pytest.approx(-2.0) and h[0, 2] == -1.0


def test_magnetic_heading_calibration_recovers_heading_with_hard_iron_and_declination():
    rng = np.random.default_rng(3)
    # Hanoi-like field (T): 8 deg declination west, 30 deg inclination
    b_ned = 40e-6 * np.array([np.cos(0.52) * np.cos(-0.14), np.cos(0.52) * np.sin(-0.14),
                              np.sin(0.52)])
    hard_iron = np.array([4e-6, -3e-6, 2e-6])
    cal = aiding.MagneticHeading()
    assert cal.heading(np.ones(3), Q_TRUE) is None
    for yaw in np.linspace(-3.0, 3.0, 40):  # a drive with turns while GNSS is good
        roll, pitch = rng.normal(0, 0.03, 2)
        c_bn = euler_to_dcm(roll, pitch, yaw)
        m = c_bn.T @ b_ned + hard_iron + rng.normal(0, 0.1e-6, 3)
        cal.learn(m, euler_to_quat(roll, pitch, yaw))
    assert cal.solve()
    np.testing.assert_allclose(cal.hard_iron, hard_iron, atol=0.1e-6)
    for yaw in (-2.5, 0.3, 1.9):
        q = euler_to_quat(0.05, -0.04, yaw)
        m = quat_to_dcm(q).T @ b_ned + hard_iron
        assert cal.heading(m, q) == pytest.approx(yaw, abs=np.radians(0.5))


def test_gnss_velocity_and_odometer_with_lever_arms_against_finite_differences():
    """The antenna's velocity v + C_b^n (w x l) and the odometer at the rear axle, over the
    navigation errors and the gyro-bias error (compensated rate w - dbg)."""
    rate = np.array([0.02, -0.04, 0.3])
    arm = np.array([0.5, -0.2, -1.4])
    rear = np.array([-1.7, 0.0, 0.1])
    fns = {
        "velocity": lambda q, v, w: aiding.gnss_velocity(v, V_TRUE, 15, q, w, arm),
        "odometer": lambda q, v, w: aiding.odometer(q, v, 10.0, True, 15, w, rear),
        "path_speed": lambda q, v, w: aiding.path_speed(q, v, 10.0, 15, w, rear),
    }
    for fn in fns.values():
        def measure(dx, fn=fn):
            q, v, _ = perturb(Q_TRUE, V_TRUE, POS, dx[:9])
            return fn(q, v, rate - dx[BG])[0]

        eps = np.r_[EPS, [1e-7] * 6]
        numeric = np.array([(measure(e) - measure(-e)) / (2 * e[i])
                            for i, e in enumerate(np.diag(eps))]).T
        np.testing.assert_allclose(fn(Q_TRUE, V_TRUE, rate)[1], numeric, rtol=1e-5, atol=1e-8)
    c_bn = quat_to_dcm(Q_TRUE)
    dz, _ = aiding.gnss_velocity(V_TRUE, V_TRUE, 15, Q_TRUE, rate, arm)
    np.testing.assert_allclose(dz, c_bn @ np.cross(rate, arm), atol=1e-12)


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_path_speed_is_the_speed_on_the_circle_a_point_turns_on(direction):
    """A car turning steadily about a centre R = 11 m beside its rear axle (which rolls without
    sliding), the IMU on the rear axle: its centre of gravity, l_r = 1.35 m ahead, runs on a
    circle of radius sqrt(R^2 + l_r^2) at w sqrt(R^2 + l_r^2), forward or reversing, while
    its body-x velocity is only w R (the factor cos(beta), beta = atan(l_r / R))."""
    radius, l_r, speed = 11.0, 1.35, 4.0 * direction
    yaw = 0.7
    q = euler_to_quat(0.0, 0.0, yaw)
    v_ned = speed * np.array([np.cos(yaw), np.sin(yaw), 0.0])  # the rear axle's, along x
    rate = np.array([0.0, 0.0, speed / radius])
    cog = np.array([l_r, 0.0, 0.0])
    along_path = speed / radius * np.hypot(radius, l_r)
    dz, _ = aiding.path_speed(q, v_ned, along_path, 15, rate, cog)
    assert dz[0] == pytest.approx(0.0, abs=1e-12)
    dz_x, _ = aiding.odometer(q, v_ned, along_path, False, 15, rate, cog)
    assert dz_x[0] == pytest.approx(speed - along_path, rel=1e-12)
    assert abs(dz_x[0]) == pytest.approx(abs(speed) * (np.hypot(1.0, l_r / radius) - 1.0))
