"""Motion-constraint Jacobians against finite differences taken with the error convention of
``estimators.toolbox.nav_error`` (estimate = truth perturbed by dx)."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.toolbox.constraints import height, nonholonomic
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
