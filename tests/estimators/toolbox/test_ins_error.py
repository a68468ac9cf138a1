"""The 15-state INS error model against the strapdown mechanisation it linearises: the
transition matrix of ``ins_error`` must match a numerical Jacobian of one
``strapdown.propagate`` step, taken with the error convention of ``nav_error``."""

from __future__ import annotations

import numpy as np

from estimators.toolbox.ins_error import BA, BG, discretise, noise_psd, system_matrix
from estimators.toolbox.nav_error import perturb
from estimators.toolbox.strapdown import propagate
from simulator.earth import (
    euler_to_quat,
    quat_multiply,
    quat_to_dcm,
    radii_of_curvature,
)

Q0 = euler_to_quat(0.04, -0.07, 2.1)
V0 = np.array([-9.0, 14.0, 0.6])
POS0 = np.array([np.radians(52.0), np.radians(13.0), 120.0])
F_BODY = np.array([1.2, -0.9, -9.6])  # m/s^2
W_BODY = np.array([0.03, -0.02, 0.25])  # rad/s
DT = 0.01


def _error(q, v, pos, q_ref, v_ref, pos_ref) -> np.ndarray:
    """[dr, dv, psi] of (q, v, pos) against the reference (inverse of ``nav_error.perturb``)."""
    rn, re = radii_of_curvature(pos_ref[0])
    dr = np.array([(pos[0] - pos_ref[0]) * (rn + pos_ref[2]),
                   (pos[1] - pos_ref[1]) * (re + pos_ref[2]) * np.cos(pos_ref[0]),
                   pos_ref[2] - pos[2]])
    conj = q_ref * np.array([1.0, -1.0, -1.0, -1.0])
    dq = quat_multiply(q, conj)
    psi = 2.0 * np.sign(dq[0]) * dq[1:]
    return np.r_[dr, v - v_ref, psi]


def _step(dx: np.ndarray) -> np.ndarray:
    """Error after one strapdown step from the truth perturbed by ``dx`` (15 states)."""
    q, v, pos = perturb(Q0, V0, POS0, dx[:9])
    dth = (W_BODY - dx[BG]) * DT  # compensated with a bias estimate off by dbg
    dvel = (F_BODY - dx[BA]) * DT
    q1, v1, p1 = propagate(q, v, pos, dth, dvel, dth, dvel, DT)
    qt, vt, pt = propagate(Q0, V0, POS0, W_BODY * DT, F_BODY * DT, W_BODY * DT, F_BODY * DT, DT)
    return np.r_[_error(q1, v1, p1, qt, vt, pt), dx[9:]]


def test_transition_matrix_matches_a_numerical_jacobian_of_the_strapdown():
    eps = np.r_[[1.0] * 3, [0.01] * 3, [1e-4] * 3, [1e-3] * 3, [1e-5] * 3]
    numeric = np.array([(_step(e) - _step(-e)) / 2.0 for e in np.diag(eps)]).T / eps
    numeric[9:, 9:] = np.eye(6)  # the strapdown has no bias dynamics (random-walk biases)
    c_bn = quat_to_dcm(Q0)
    f = system_matrix(POS0[0], POS0[2], V0, c_bn, F_BODY)
    phi, _ = discretise(f, np.zeros((15, 15)), DT)
    # every element to 2 % of its column's scale: the navigation terms of order g dt, dt and the
    # small curvature, Earth-rate and transport-rate terms of order v dt / R alike
    scale = np.abs(phi - np.eye(15)).max(axis=0)
    np.testing.assert_allclose(phi - np.eye(15), numeric - np.eye(15), rtol=0,
                               atol=1e-12 + 0.02 * scale.max())
    # the small terms themselves (relative to their own size)
    for (i, j) in [(0, 2), (1, 0), (1, 2), (5, 2), (6, 0), (8, 0), (6, 4), (7, 3), (3, 4)]:
        assert abs(phi[i, j] - numeric[i, j]) <= 0.05 * abs(numeric[i, j]), (i, j)


def test_gravity_term_makes_the_vertical_channel_unstable():
    f = system_matrix(POS0[0], 0.0, np.zeros(3), np.eye(3), np.array([0, 0, -9.8]))
    # Groves eq. 14.69: 2 g / r, about 3.1e-6 1/s^2
    assert 3.0e-6 < f[5, 2] < 3.2e-6


def test_noise_psd_is_rotation_invariant_for_equal_axes_and_drives_the_right_blocks():
    c_bn = quat_to_dcm(Q0)
    gqg = noise_psd(c_bn, 4e-6, 1e-8, 1e-10, 1e-12)
    np.testing.assert_allclose(gqg[3:6, 3:6], 4e-6 * np.eye(3), rtol=0, atol=1e-18)
    np.testing.assert_allclose(gqg[6:9, 6:9], 1e-8 * np.eye(3), rtol=0, atol=1e-20)
    assert not gqg[0:3].any()
    # Gauss-Markov biases: the discrete variance of a bias step is 2 sigma^2 dt / tau
    f = system_matrix(POS0[0], 0.0, V0, c_bn, F_BODY, tau_accel=100.0, tau_gyro=300.0)
    phi, q_d = discretise(f, gqg, 1.0)
    np.testing.assert_allclose(np.diag(phi)[BA], 1 - 1 / 100 + 0.5e-4, rtol=1e-9)
    np.testing.assert_allclose(np.diag(q_d)[BG], 1e-12 * (1 + (1 - 1 / 300 + 0.5 / 300**2)**2) / 2,
                               rtol=1e-9)
