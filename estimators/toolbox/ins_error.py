"""The 15-state NED INS error model: system matrix F, noise input G Q G^T and their discrete form.

State (errors are estimate minus truth, the convention of ``estimators.toolbox.nav_error``)::

    dx = [dr_n, dr_e, dr_d, dv_n, dv_e, dv_d, psi_n, psi_e, psi_d,
          dba_x, dba_y, dba_z, dbg_x, dbg_y, dbg_z]

* dr: position error resolved in NED (north and east arc lengths, down), m;
* dv: NED velocity error, m/s;
* psi: attitude error, C_b^n(estimate) = (I + [psi x]) C_b^n(true), rad;
* dba, dbg: errors of the accelerometer and gyro bias estimates (estimate minus true bias, body
  FRD axes, m/s^2 and rad/s). The compensated outputs are f - ba_hat = f_true - dba and
  w - bg_hat = w_true - dbg, so a positive dba makes the compensated specific force too small.

Continuous error dynamics (the NED-frame model of Groves 2013, section 14.2.4,
rewritten for this sign convention; the model Park et al. 2019 cite for eq. 5, F_0, and the one a
linearised INS filter such as Tan et al. 2008's eqs. 1-4 needs)::

    d(psi)/dt = -[w_in x] psi - dw_in(dr, dv) - C_b^n dbg
    d(dv)/dt  = -[(C_b^n f) x] psi - C_b^n dba - [(2 w_ie + w_en) x] dv
                + [v x] (2 dw_ie(dr) + dw_en(dr, dv)) + dg(dr)
    d(dr)/dt  = dv + (terms of order v / R in dr: the curvilinear position rates, eq. 1 of
                Park et al. 2019, differentiated)
    d(db)/dt  = -db / tau + w_b    (first-order Gauss-Markov; tau = inf gives a random walk)

where dw_ie and dw_en are the changes of the Earth and transport rates (Groves eqs. 5.41, 5.44)
with the position and velocity errors, and dg_d = 2 g dr_d / (sqrt(R_N R_E) + h) is the change of
normal gravity with height (a down error grows gravity: the unstable vertical channel).

Noise: accelerometer white noise (velocity random walk, PSD S_a in (m/s^2)^2/Hz) drives dv
through C_b^n, gyro white noise (angle random walk, S_g in (rad/s)^2/Hz) drives psi, and the bias
driving noises have PSD 2 sigma^2 / tau (Gauss-Markov) or the random-walk PSD.

Discretisation over a step dt (Groves section 3.2.3): Phi = I + F dt + (F dt)^2 / 2 and the
trapezoidal Q_d = (Phi G Q G^T Phi^T + G Q G^T) dt / 2 (Tan et al. 2008's eqs. 3-4 are the
first-order forms of the same).

Public names
------------
N_STATES, BA, BG, system_matrix, noise_psd, discretise.
"""

from __future__ import annotations

import numpy as np

from simulator.earth import OMEGA_E_RAD_S, normal_gravity, radii_of_curvature, skew

N_STATES = 15
BA = slice(9, 12)  # accelerometer-bias error block
BG = slice(12, 15)  # gyro-bias error block
_BIAS_DIAG = np.arange(9, 15)


def _rate_jacobians(lat: float, h: float, v: np.ndarray, rn: float, re: float
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """d w_ie / d dr, d w_en / d dr and d w_en / d dv (each 3 x 3)."""
    tan_l, cos_l, sin_l = np.tan(lat), np.cos(lat), np.sin(lat)
    rn_h, re_h = rn + h, re + h
    j_ie_r = np.zeros((3, 3))
    j_ie_r[0, 0] = -OMEGA_E_RAD_S * sin_l / rn_h  # d/dL of Omega (cos L, 0, -sin L) / (R_N + h)
    j_ie_r[2, 0] = -OMEGA_E_RAD_S * cos_l / rn_h
    j_en_r = np.zeros((3, 3))
    j_en_r[2, 0] = -v[1] / (re_h * cos_l**2) / rn_h
    # dh = -dr_d: d w_en / d dr_d = -d w_en / dh
    j_en_r[0, 2] = v[1] / re_h**2
    j_en_r[1, 2] = -v[0] / rn_h**2
    j_en_r[2, 2] = -v[1] * tan_l / re_h**2
    j_en_v = np.array([[0.0, 1.0 / re_h, 0.0],
                       [-1.0 / rn_h, 0.0, 0.0],
                       [0.0, -tan_l / re_h, 0.0]])
    return j_ie_r, j_en_r, j_en_v


def system_matrix(lat: float, h: float, v_ned: np.ndarray, c_bn: np.ndarray,
                  f_body: np.ndarray, tau_accel: np.ndarray | float = np.inf,
                  tau_gyro: np.ndarray | float = np.inf) -> np.ndarray:
    """The continuous system matrix F of the 15-state error model (module docstring).

    Parameters
    ----------
    lat : float
        Latitude, rad. h : float, ellipsoidal height, m.
    v_ned : (3,) NED velocity, m/s.
    c_bn : (3, 3) body-to-NED direction cosine matrix.
    f_body : (3,) compensated specific force, body FRD, m/s^2.
    tau_accel, tau_gyro : float or (3,)
        Bias correlation times, s (inf: random-walk biases).

    Returns
    -------
    f : (15, 15).
    """
    v = np.asarray(v_ned, dtype=float)
    rn, re = (float(x) for x in radii_of_curvature(lat))
    rn_h, re_h = rn + h, re + h
    tan_l = np.tan(lat)
    w_ie = OMEGA_E_RAD_S * np.array([np.cos(lat), 0.0, -np.sin(lat)])
    w_en = np.array([v[1] / re_h, -v[0] / rn_h, -v[1] * tan_l / re_h])
    j_ie_r, j_en_r, j_en_v = _rate_jacobians(lat, h, v, rn, re)
    f = np.zeros((N_STATES, N_STATES))
    # position: d/dt of [(R_N + h) dL, (R_E + h) cos L dlon, -dh]
    f[0, 0] = -v[2] / rn_h
    f[0, 2] = v[0] / rn_h
    f[1, 0] = v[1] * tan_l / rn_h
    f[1, 1] = -(v[2] + v[0] * tan_l * re_h / rn_h) / re_h
    f[1, 2] = v[1] / re_h
    f[0:3, 3:6] = np.eye(3)
    # velocity
    v_x = skew(v)
    f[3:6, 0:3] = v_x @ (2.0 * j_ie_r + j_en_r)
    f[5, 2] += 2.0 * float(normal_gravity(lat, h)) / (np.sqrt(rn * re) + h)
    f[3:6, 3:6] = v_x @ j_en_v - skew(2.0 * w_ie + w_en)
    f[3:6, 6:9] = -skew(c_bn @ np.asarray(f_body, dtype=float))
    f[3:6, BA] = -c_bn
    # attitude
    f[6:9, 0:3] = -(j_ie_r + j_en_r)
    f[6:9, 3:6] = -j_en_v
    f[6:9, 6:9] = -skew(w_ie + w_en)
    f[6:9, BG] = -c_bn
    # biases
    f[_BIAS_DIAG, _BIAS_DIAG] = -1.0 / np.concatenate([np.broadcast_to(tau_accel, 3),
                                                       np.broadcast_to(tau_gyro, 3)])
    return f


def noise_psd(c_bn: np.ndarray, accel_psd: np.ndarray | float, gyro_psd: np.ndarray | float,
              accel_bias_psd: np.ndarray | float, gyro_bias_psd: np.ndarray | float
              ) -> np.ndarray:
    """G Q G^T of the 15-state model, (15, 15).

    Parameters
    ----------
    c_bn : (3, 3) body-to-NED DCM (maps the body-axis white noises into NED).
    accel_psd : accelerometer white-noise PSD per axis, (m/s^2)^2/Hz (noise density squared).
    gyro_psd : gyro white-noise PSD per axis, (rad/s)^2/Hz.
    accel_bias_psd, gyro_bias_psd : PSD of the bias driving noises, (m/s^2)^2/s and
        (rad/s)^2/s (2 sigma^2 / tau for a Gauss-Markov bias).
    """
    gqg = np.zeros((N_STATES, N_STATES))
    gqg[3:6, 3:6] = (c_bn * np.broadcast_to(accel_psd, 3)) @ c_bn.T
    gqg[6:9, 6:9] = (c_bn * np.broadcast_to(gyro_psd, 3)) @ c_bn.T
    gqg[_BIAS_DIAG, _BIAS_DIAG] = np.concatenate([np.broadcast_to(accel_bias_psd, 3),
                                                  np.broadcast_to(gyro_bias_psd, 3)])
    return gqg


def discretise(f: np.ndarray, gqg: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Transition matrix and process-noise covariance over ``dt`` (s): Phi = I + F dt +
    (F dt)^2 / 2, Q_d = (Phi G Q G^T Phi^T + G Q G^T) dt / 2 (Groves section 3.2.3)."""
    fdt = f * dt
    phi = np.eye(f.shape[0]) + fdt + 0.5 * (fdt @ fdt)
    q_d = 0.5 * dt * (phi @ gqg @ phi.T + gqg)
    return phi, 0.5 * (q_d + q_d.T)
