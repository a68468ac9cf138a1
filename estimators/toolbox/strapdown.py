"""Strapdown inertial mechanisation in the local NED frame with quaternion attitude.

The one home of INS propagation for every estimator. Inputs are IMU increments (delta-theta,
delta-v over each sample interval, FRD); rate samples are turned into increments by the caller.
The update per interval:

* attitude: q_b^n <- q(-w_in^n dt) * q_b^n * q(dtheta'), with the two-sample coning correction
  dtheta' = dtheta_k + (1/12) dtheta_{k-1} x dtheta_k (Savage 1998; Groves section 5.5.3;
  quaternion form of Chan et al. eqs. 1-3 and Park et al. 2019 eqs. 1-3);
* velocity: v <- v + C_b^n (I-frame rotation and sculling corrected dv) + (g - (w_en + 2 w_ie) x v)
  dt, with Earth and transport rate, normal gravity and Coriolis at the interval's midpoint
  (Groves eq. 5.54 integrated);
* position: latitude, longitude and height from the trapezoidal mean velocity (Groves eq. 5.56).

Public functions
----------------
propagate, run_strapdown, rates_to_increments, attitude_step, frame_rates, radii, nav_derivative,
rk4_step.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from simulator.earth import A_M, E2, GAMMA_E_M_S2, M_RATIO, OMEGA_E_RAD_S, SOMIGLIANA_K, F


@njit(cache=True)
def _normal_gravity(lat: float, h: float) -> float:
    # TR8350.2 eqs. 4-1 and 4-3 (same model as simulator.earth.normal_gravity)
    s2 = np.sin(lat) ** 2
    g0 = GAMMA_E_M_S2 * (1.0 + SOMIGLIANA_K * s2) / np.sqrt(1.0 - E2 * s2)
    return g0 * (1.0 - 2.0 / A_M * (1.0 + F + M_RATIO - 2.0 * F * s2) * h + 3.0 / A_M**2 * h * h)


@njit(cache=True)
def _radii(lat: float) -> tuple[float, float]:
    den = 1.0 - E2 * np.sin(lat) ** 2
    return A_M * (1.0 - E2) / den**1.5, A_M / np.sqrt(den)


@njit(cache=True)
def _quat_mul(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    return np.array([
        p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3],
        p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2],
        p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1],
        p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0],
    ])


@njit(cache=True)
def _rotvec_quat(v: np.ndarray) -> np.ndarray:
    angle = np.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
    k = 0.5 - angle**2 / 48.0 if angle < 1e-6 else np.sin(0.5 * angle) / angle
    return np.array([np.cos(0.5 * angle), v[0] * k, v[1] * k, v[2] * k])


@njit(cache=True)
def _quat_dcm(q: np.ndarray) -> np.ndarray:
    a, b, c, d = q[0], q[1], q[2], q[3]
    return np.array([
        [a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)],
        [2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)],
        [2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d],
    ])


@njit(cache=True)
def _nav_rates(lat: float, h: float, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    rn, re = _radii(lat)
    w_ie = np.array([OMEGA_E_RAD_S * np.cos(lat), 0.0, -OMEGA_E_RAD_S * np.sin(lat)])
    w_en = np.array([v[1] / (re + h), -v[0] / (rn + h), -v[1] * np.tan(lat) / (re + h)])
    return w_ie, w_en


@njit(cache=True)
def propagate(q: np.ndarray, v: np.ndarray, pos: np.ndarray, dtheta: np.ndarray,
              dv: np.ndarray, dtheta_prev: np.ndarray, dv_prev: np.ndarray,
              dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One strapdown step. q: body-to-NED quaternion (scalar first); v: NED velocity (m/s);
    pos: latitude (rad), longitude (rad), height (m); dtheta, dv: this interval's increments;
    *_prev: the previous interval's (zeros for the first step). Returns new (q, v, pos)."""
    lat, h = pos[0], pos[2]
    # coning and sculling corrections (two-sample, Savage)
    cone = np.cross(dtheta_prev, dtheta) / 12.0
    dth = dtheta + cone
    dv_b = dv + 0.5 * np.cross(dtheta, dv) + (np.cross(dtheta_prev, dv)
                                              + np.cross(dv_prev, dtheta)) / 12.0
    c_bn = _quat_dcm(q)
    # first pass: midpoint velocity for Coriolis and transport rate
    w_ie, w_en = _nav_rates(lat, h, v)
    g = np.array([0.0, 0.0, _normal_gravity(lat, h)])
    dv_n = c_bn @ dv_b
    v_mid = v + 0.5 * (dv_n + (g - np.cross(w_en + 2 * w_ie, v)) * dt)
    rn, re = _radii(lat)
    lat_mid = lat + 0.5 * dt * v_mid[0] / (rn + h)
    h_mid = h - 0.5 * dt * v_mid[2]
    w_ie, w_en = _nav_rates(lat_mid, h_mid, v_mid)
    w_in = w_ie + w_en
    g = np.array([0.0, 0.0, _normal_gravity(lat_mid, h_mid)])
    dv_n = c_bn @ dv_b - 0.5 * np.cross(w_in * dt, c_bn @ dv_b)
    v_new = v + dv_n + (g - np.cross(w_en + 2 * w_ie, v_mid)) * dt
    q_new = _quat_mul(_quat_mul(_rotvec_quat(-w_in * dt), q), _rotvec_quat(dth))
    q_new = q_new / np.sqrt(np.sum(q_new * q_new))
    h_new = h - 0.5 * dt * (v[2] + v_new[2])
    rn, re = _radii(lat_mid)
    lat_new = lat + 0.5 * dt * (v[0] + v_new[0]) / (rn + h_mid)
    lat_m2 = 0.5 * (lat + lat_new)
    rn, re = _radii(lat_m2)
    lon_new = pos[1] + 0.5 * dt * (v[1] + v_new[1]) / ((re + h_mid) * np.cos(lat_m2))
    return q_new, v_new, np.array([lat_new, lon_new, h_new])


@njit(cache=True)
def _run(q0: np.ndarray, v0: np.ndarray, pos0: np.ndarray, dtheta: np.ndarray,
         dv: np.ndarray, dt: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    n = dtheta.shape[0]
    qs = np.empty((n + 1, 4))
    vs = np.empty((n + 1, 3))
    ps = np.empty((n + 1, 3))
    qs[0], vs[0], ps[0] = q0, v0, pos0
    prev_th = np.zeros(3)
    prev_dv = np.zeros(3)
    for k in range(n):
        qs[k + 1], vs[k + 1], ps[k + 1] = propagate(qs[k], vs[k], ps[k], dtheta[k], dv[k],
                                                    prev_th, prev_dv, dt[k])
        prev_th = dtheta[k]
        prev_dv = dv[k]
    return qs, vs, ps


def run_strapdown(q0: np.ndarray, v0_ned: np.ndarray, pos0: np.ndarray, dtheta: np.ndarray,
                  dv: np.ndarray, dt: np.ndarray | float) -> tuple[np.ndarray, ...]:
    """Integrate a whole increment sequence (free inertial, no aiding).

    Parameters
    ----------
    q0 : array, shape (4,)
        Initial body-to-NED quaternion (scalar first).
    v0_ned : array, shape (3,)
        Initial NED velocity, m/s.
    pos0 : array, shape (3,)
        Initial latitude (rad), longitude (rad), height (m).
    dtheta, dv : arrays, shape (n, 3)
        Angle (rad) and velocity (m/s) increments, FRD.
    dt : float or array, shape (n,)
        Interval lengths, s.

    Returns
    -------
    q : (n + 1, 4), v : (n + 1, 3), pos : (n + 1, 3) including the initial state.
    """
    dtheta = np.ascontiguousarray(dtheta, dtype=float)
    dt_arr = np.broadcast_to(np.asarray(dt, dtype=float), (len(dtheta),)).copy()
    return _run(np.asarray(q0, float), np.asarray(v0_ned, float), np.asarray(pos0, float),
                dtheta, np.ascontiguousarray(dv, dtype=float), dt_arr)


def rates_to_increments(t: np.ndarray, rates: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Trapezoidal increments over [t_{k-1}, t_k] from rate samples; returns (increments, dt)."""
    dt = np.diff(t)
    return 0.5 * (rates[1:] + rates[:-1]) * dt[:, None], dt


@njit(cache=True)
def attitude_step(q: np.ndarray, rot_nav: np.ndarray, rot_body: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Rotate a body-to-NED quaternion by a navigation-frame rotation ``rot_nav`` (rad; the
    frame's own rotation w_in dt, or an estimated attitude error psi) and a body-frame rotation
    ``rot_body`` (rad; the gyro increment): q <- q(-rot_nav) * q * q(rot_body), normalised
    (the attitude line of ``propagate``). Returns the quaternion and its body-to-NED DCM."""
    q_new = _quat_mul(_quat_mul(_rotvec_quat(-rot_nav), q), _rotvec_quat(rot_body))
    q_new = q_new / np.sqrt(np.sum(q_new * q_new))
    return q_new, _quat_dcm(q_new)


@njit(cache=True)
def frame_rates(lat: float, h: float, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Earth rate and transport rate resolved in NED (rad/s) at latitude ``lat`` (rad), height
    ``h`` (m) and NED velocity ``v`` (m/s) (Groves eqs. 5.41, 5.44; compiled, for filters'
    inner loops; ``simulator.earth.earth_rate_ned`` and ``transport_rate_ned`` vectorised)."""
    return _nav_rates(lat, h, v)


@njit(cache=True)
def radii(lat: float) -> tuple[float, float]:
    """Meridian and transverse radii of curvature (m) at latitude ``lat`` (rad) (compiled;
    ``simulator.earth.radii_of_curvature`` vectorised)."""
    return _radii(lat)

@njit(cache=True)
def nav_derivative(x: np.ndarray, w_ib: np.ndarray, f_b: np.ndarray, out: np.ndarray) -> None:
    """Time derivative of the total navigation state in the NED frame, written into ``out``
    without allocating (Chan et al. eqs. 1-3; Titterton & Weston 2004, section 3.5.3):

    L' = v_N / (R_m + h), l' = v_E / ((R_t + h) cos L), h' = -v_D (eq. 1);
    v' = C_b^n f^b - (2 w_ie + w_en) x v + g^n (eq. 2, g the normal gravity);
    q' = 1/2 q * (0, w_nb^b), w_nb^b = w_ib^b - C_n^b (w_ie + w_en) (eq. 3, whose Omega matrix
    is this product).

    x, out : (10,) latitude, longitude (rad), height (m), NED velocity (m/s), body-to-NED
    quaternion (scalar first); w_ib, f_b : (3,) body angular rate (rad/s) and specific force
    (m/s^2), FRD."""
    lat, h, vn, ve, vd = x[0], x[2], x[3], x[4], x[5]
    a, b, c, d = x[6], x[7], x[8], x[9]
    sl, cl = np.sin(lat), np.cos(lat)
    rm, rt = _radii(lat)
    out[0] = vn / (rm + h)
    out[1] = ve / ((rt + h) * cl)
    out[2] = -vd
    ie_n, ie_d = OMEGA_E_RAD_S * cl, -OMEGA_E_RAD_S * sl
    en_n, en_e, en_d = ve / (rt + h), -vn / (rm + h), -ve * sl / cl / (rt + h)
    c00, c01, c02 = a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)
    c10, c11, c12 = 2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)
    c20, c21, c22 = 2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d
    fx, fy, fz = f_b[0], f_b[1], f_b[2]
    an, ae, ad = 2.0 * ie_n + en_n, en_e, 2.0 * ie_d + en_d  # 2 w_ie + w_en
    out[3] = c00 * fx + c01 * fy + c02 * fz - (ae * vd - ad * ve)
    out[4] = c10 * fx + c11 * fy + c12 * fz - (ad * vn - an * vd)
    out[5] = c20 * fx + c21 * fy + c22 * fz - (an * ve - ae * vn) + _normal_gravity(lat, h)
    wn, we, wd = ie_n + en_n, en_e, ie_d + en_d  # w_in
    p = w_ib[0] - (c00 * wn + c10 * we + c20 * wd)
    q = w_ib[1] - (c01 * wn + c11 * we + c21 * wd)
    r = w_ib[2] - (c02 * wn + c12 * we + c22 * wd)
    out[6] = 0.5 * (-b * p - c * q - d * r)
    out[7] = 0.5 * (a * p + c * r - d * q)
    out[8] = 0.5 * (a * q - b * r + d * p)
    out[9] = 0.5 * (a * r + b * q - c * p)


@njit(cache=True)
def rk4_step(x: np.ndarray, w0: np.ndarray, w_mid: np.ndarray, w1: np.ndarray, f0: np.ndarray,
             f_mid: np.ndarray, f1: np.ndarray, dt: float, work: np.ndarray) -> None:
    """One classical fourth-order Runge-Kutta step of ``nav_derivative`` over ``dt``, in place
    on x (10,), with the body rates and specific forces at the step's start, middle and end;
    the quaternion is normalised after the step. ``work`` is a (5, 10) scratch array."""
    k1, k2, k3, k4, xt = work[0], work[1], work[2], work[3], work[4]
    nav_derivative(x, w0, f0, k1)
    for i in range(10):
        xt[i] = x[i] + 0.5 * dt * k1[i]
    nav_derivative(xt, w_mid, f_mid, k2)
    for i in range(10):
        xt[i] = x[i] + 0.5 * dt * k2[i]
    nav_derivative(xt, w_mid, f_mid, k3)
    for i in range(10):
        xt[i] = x[i] + dt * k3[i]
    nav_derivative(xt, w1, f1, k4)
    for i in range(10):
        x[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    norm = np.sqrt(x[6] ** 2 + x[7] ** 2 + x[8] ** 2 + x[9] ** 2)
    for i in range(6, 10):
        x[i] /= norm
