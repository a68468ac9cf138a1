"""The navigation error-state convention shared by every error-state filter and measurement
model, and the corrections that go with it.

Errors are estimate minus truth, as in the NED-frame INS error states of Groves 2013
(chapter 14):

* dr : (3,) position error resolved in NED, m: north and east arc lengths and down;
* dv : (3,) NED velocity error, m/s;
* psi : (3,) attitude error, rad, a small rotation of the NED frame:
  C_b^n(estimate) = exp([psi x]) C_b^n(true) ~ (I + [psi x]) C_b^n(true), so
  q(estimate) = q(psi) * q(true).

The 9-vector dx = [dr, dv, psi] is the navigation block of an error state; ``correct`` removes
estimated errors from a solution (closed-loop feedback, or open-loop output) and ``perturb``
adds them (initial errors, tests). ``euler_covariance`` turns the covariance of psi into that of
the roll, pitch and yaw errors a solution reports (its ``std_roll ... std_yaw`` columns, which
the scores compare with Euler-angle errors).

Public names
------------
NAV_ERROR_STATES, perturb, correct, euler_error_jacobian, euler_covariance.
"""

from __future__ import annotations

import math

import numpy as np

from simulator.earth import euler_to_dcm, geodetic_rates, quat_multiply, rotvec_to_quat

NAV_ERROR_STATES = ("dr_n", "dr_e", "dr_d", "dv_n", "dv_e", "dv_d", "psi_n", "psi_e", "psi_d")


def _shift(pos: np.ndarray, d_ned: np.ndarray) -> np.ndarray:
    lat, lon, h = pos
    d_lat, d_lon, d_h = geodetic_rates(lat, h, d_ned)
    return np.array([lat + d_lat, lon + d_lon, h + d_h])


def perturb(q: np.ndarray, v: np.ndarray, pos: np.ndarray, dx: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A solution with errors ``dx`` added.

    Parameters
    ----------
    q : (4,) body-to-NED quaternion (scalar first); v : (3,) NED velocity, m/s;
    pos : (3,) latitude (rad), longitude (rad), height (m); dx : (9,) [dr, dv, psi].

    Returns
    -------
    q, v, pos of the erroneous solution.
    """
    dx = np.asarray(dx, dtype=float)
    q_new = quat_multiply(rotvec_to_quat(dx[6:9]), q)
    return q_new, np.asarray(v, float) + dx[3:6], _shift(np.asarray(pos, float), dx[0:3])


def correct(q: np.ndarray, v: np.ndarray, pos: np.ndarray, dx: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A solution with estimated errors ``dx`` removed (the inverse of ``perturb`` to first
    order in the position's curvature; exact for velocity and attitude)."""
    dx = np.asarray(dx, dtype=float)
    q_new = quat_multiply(rotvec_to_quat(-dx[6:9]), q)
    return q_new, np.asarray(v, float) - dx[3:6], _shift(np.asarray(pos, float), -dx[0:3])


def euler_error_jacobian(c_bn: np.ndarray) -> np.ndarray:
    """d(roll, pitch, yaw) / d psi, shape (3, 3), at the attitude of the body-to-NED DCM
    ``c_bn``, for the toolbox attitude error psi (C_b^n(estimate) = (I + [psi x]) C_b^n): the
    Euler-rate matrix M(roll, pitch) times C_n^b, since psi is the body-frame rotation
    C_n^b psi (Groves 2013, eq. 2.56 for M)."""
    roll = math.atan2(c_bn[2, 1], c_bn[2, 2])
    sr, cr = math.sin(roll), math.cos(roll)
    sp = -c_bn[2, 0]
    cp = math.sqrt(max(1.0 - sp * sp, 1e-12))
    m = np.array([[1.0, sr * sp / cp, cr * sp / cp], [0.0, cr, -sr], [0.0, sr / cp, cr / cp]])
    return m @ c_bn.T


def euler_covariance(roll: float, pitch: float, yaw: float, p_psi: np.ndarray) -> np.ndarray:
    """Covariance (3, 3) of the ZYX Euler-angle errors [d roll, d pitch, d yaw] (rad^2) of an
    attitude whose NED-frame error psi has covariance ``p_psi`` (3, 3): J P J^T with J
    ``euler_error_jacobian`` (the roll and pitch of a level car are psi_n and psi_e rotated by
    the yaw, not psi_n and psi_e themselves). Singular at pitch +-90 deg."""
    jac = euler_error_jacobian(euler_to_dcm(roll, pitch, yaw))
    return jac @ p_psi @ jac.T
