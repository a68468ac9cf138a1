"""Motion-constraint Jacobians against finite differences taken with the error convention of
``estimators.toolbox.nav_error`` (estimate = truth perturbed by dx)."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.toolbox.constraints import NonholonomicNoise, body_velocity, height, nonholonomic
from estimators.toolbox.nav_error import correct, perturb
from simulator.earth import euler_to_quat, quat_to_euler

Q_TRUE = euler_to_quat(0.05, -0.08, 2.3)
V_TRUE = np.array([-7.0, 9.0, 0.4])
POS = np.array([np.radians(37.5), np.radians(127.0), 40.0])


def _numeric_jacobian(measure, eps=1e-6):
    base = measure(np.zeros(9))
    cols = []
    for i in range(9):
        dx = np.zeros(9)
        dx[i] = eps
        cols.append((measure(dx) - measure(-dx)) / (2 * eps))
    return base, np.array(cols).T


def test_nonholonomic_jacobian_matches_finite_differences():
    def measure(dx):
        q, v, _ = perturb(Q_TRUE, V_TRUE, POS, dx)
        return nonholonomic(q, v)[0]

    _, numeric = _numeric_jacobian(measure)
    _, h = nonholonomic(Q_TRUE, V_TRUE)
    np.testing.assert_allclose(h, numeric, atol=1e-7)
    assert h.shape == (2, 9)


def test_nonholonomic_is_zero_for_a_vehicle_moving_along_its_axis():
    q = euler_to_quat(0.02, 0.05, 1.0)
    v = 12.0 * np.array([np.cos(0.05) * np.cos(1.0), np.cos(0.05) * np.sin(1.0),
                         -np.sin(0.05)])
    dz, h = nonholonomic(q, v, n_states=15)
    np.testing.assert_allclose(dz, 0.0, atol=1e-12)
    assert h.shape == (2, 15) and not h[:, 9:].any()


def test_height_jacobian_matches_finite_differences():
    def measure(dx):
        _, _, pos = perturb(Q_TRUE, V_TRUE, POS, dx)
        return height(pos[2], 35.0)[0]

    base, numeric = _numeric_jacobian(measure)
    dz, h = height(POS[2], 35.0)
    np.testing.assert_allclose(dz, base)
    np.testing.assert_allclose(h, numeric, atol=1e-9)


def test_correct_undoes_perturb():
    dx = np.array([3.0, -4.0, 1.0, 0.1, -0.2, 0.05, 0.01, -0.02, 0.2])
    q, v, pos = correct(*perturb(Q_TRUE, V_TRUE, POS, dx), dx)
    np.testing.assert_allclose(v, V_TRUE, atol=1e-14)
    np.testing.assert_allclose(quat_to_euler(q), quat_to_euler(Q_TRUE), atol=1e-14)
    np.testing.assert_allclose(pos[:2], POS[:2], atol=1e-13)  # 1e-13 rad: under 1 mm
    assert pos[2] == pytest.approx(POS[2], abs=1e-9)


def test_attitude_error_is_a_rotation_of_the_nav_frame():
    """A pure heading error psi_d rotates the body axes about down: yaw grows by psi_d."""
    q, _, _ = perturb(Q_TRUE, V_TRUE, POS, np.r_[np.zeros(8), 0.1])
    roll, pitch, yaw = quat_to_euler(q)
    r0, p0, y0 = quat_to_euler(Q_TRUE)
    assert (roll, pitch) == pytest.approx((r0, p0), abs=1e-12)
    assert yaw == pytest.approx(y0 + 0.1, abs=1e-12)


RATE = np.array([0.03, -0.05, 0.4])  # compensated body rate, rad/s
REAR_AXLE = np.array([-1.74, 0.0, 0.1])  # the rear axle from the IMU, FRD, m


def test_body_velocity_at_a_lever_arm_jacobian_with_the_gyro_bias():
    """Finite differences over [dr, dv, psi] and over the gyro-bias error (a bias estimate too
    high by dbg makes the compensated rate w - dbg)."""
    bg = slice(12, 15)

    def measure(dx):
        q, v, _ = perturb(Q_TRUE, V_TRUE, POS, dx[:9])
        return body_velocity(q, v, 15, RATE - dx[bg], REAR_AXLE, bg)[0]

    eps = 1e-6
    numeric = np.array([(measure(e) - measure(-e)) / (2 * eps)
                        for e in np.eye(15) * eps]).T
    _, h = body_velocity(Q_TRUE, V_TRUE, 15, RATE, REAR_AXLE, bg)
    np.testing.assert_allclose(h, numeric, atol=1e-7)
    assert not h[:, 9:12].any()
    dz, h2 = nonholonomic(Q_TRUE, V_TRUE, 15, RATE, REAR_AXLE, bg)
    np.testing.assert_allclose(h2, h[1:3])
    assert dz.shape == (2,)


def test_the_rear_axle_of_a_kinematic_bicycle_has_no_lateral_velocity():
    """A car turning on a circle at low speed (no tyre slip): its rear axle moves along the
    body, the IMU 1.74 m ahead of it slips sideways at yaw rate x 1.74 m (Rajamani 2012, eq.
    2.29). The constraint at the rear axle is zero; at the IMU it reads the IMU's slip."""
    v, radius, ahead = 5.0, 12.0, 1.74
    yaw_rate = v / radius  # of the rear axle's circle
    yaw = 0.7
    slip = np.arctan2(ahead, radius)  # the IMU's velocity direction relative to the body x
    speed_imu = yaw_rate * np.hypot(radius, ahead)
    v_ned = speed_imu * np.array([np.cos(yaw + slip), np.sin(yaw + slip), 0.0])
    q = euler_to_quat(0.0, 0.0, yaw)
    rate = np.array([0.0, 0.0, yaw_rate])
    dz, _ = nonholonomic(q, v_ned, 15, rate, np.array([-ahead, 0.0, 0.0]))
    np.testing.assert_allclose(dz, 0.0, atol=1e-12)
    dz_imu, _ = nonholonomic(q, v_ned)
    assert dz_imu[0] == pytest.approx(yaw_rate * ahead, rel=1e-12)


def test_nonholonomic_noise_follows_the_bicycle_model():
    """The lateral sigma is the rear slip of the linear bicycle model, D_r v a_y with the
    cornering compliance of tyres with Gillespie's 0.15 per degree: 1 / (0.15 x 57.3 x 9.81)
    rad per m/s^2 = 6.67 deg/g; straight and steady, only the floor and the road remain."""
    noise = NonholonomicNoise(wheelbase=2.7)
    assert np.degrees(noise.cornering_compliance) * 9.80665 == pytest.approx(1 / 0.15,
                                                                                rel=1e-9)
    v, a_y = 10.0, 3.0
    lateral, _ = noise.sigma(v, a_y / v, 0.0)
    assert lateral == pytest.approx(np.hypot(0.1, noise.cornering_compliance * v * a_y))
    # pitch on the springs: h / (w^2 (L/2)^2) = 0.55 / ((2 pi)^2 1.35^2) rad per m/s^2
    assert noise.pitch_compliance == pytest.approx(0.55 / ((2 * np.pi) ** 2 * 1.35**2))
    assert noise.sigma(0.0, 0.0, 0.0) == pytest.approx((0.1, 0.1))
    # class B road at 10 m/s through 10 Hz: 4 pi^2 64e-6 0.01 10 10 = 2.53e-3 (m/s)^2
    _, vertical = noise.sigma(10.0, 0.0, 0.0)
    assert vertical**2 == pytest.approx(0.01 + 4 * np.pi**2 * 64e-6 * 0.01 * 100, rel=1e-9)


def test_nonholonomic_noise_of_a_state_reads_speed_yaw_rate_and_forward_acceleration():
    """Pitched up 0.1 rad at rest on a slope: the accelerometer reads g sin(0.1) forward and
    the forward acceleration is zero; moving at 10 m/s along the body with a 0.3 rad/s yaw
    rate it is the ``sigma`` of those."""
    noise = NonholonomicNoise(wheelbase=2.7)
    q = euler_to_quat(0.0, 0.1, 0.4)
    v = 10.0 * np.array([np.cos(0.1) * np.cos(0.4), np.cos(0.1) * np.sin(0.4), -np.sin(0.1)])
    force = np.array([9.80665 * np.sin(0.1), 0.0, -9.80665 * np.cos(0.1)])
    rate = np.array([0.0, 0.0, 0.3])
    assert noise.sigma_of_state(q, v, rate, force) == pytest.approx(noise.sigma(10.0, 0.3, 0.0))
