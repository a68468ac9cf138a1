"""Chan et al., "Robust Navigation System for a Land Vehicle" (seeds/001): tightly coupled
INS/GPS on pseudorange and pseudorange rate, as a total-state unscented Kalman filter
(``tc_ukf``) and as its error-state extended Kalman filter counterpart (``tc_ekf``), each with the
non-holonomic constraint (NHC) as a measurement.

State (paper, section "System Models"): latitude, longitude, height, NED velocity, attitude,
accelerometer biases, gyro biases (random constants), receiver clock bias cb (m) and drift d (m/s)
(random walk). The UKF carries the attitude as a quaternion; since a quaternion inside the
sigma-point covariance is rank deficient (four numbers, three degrees of freedom), the filter's
17-dimensional tangent space is

    [dr_n, dr_e, dr_d (m), dv_n, dv_e, dv_d (m/s), psi_n, psi_e, psi_d (rad),
     ba_x, ba_y, ba_z (m/s^2), bg_x, bg_y, bg_z (rad/s), cb (m), d (m/s)]

with position and attitude as small NED displacements and rotations around the mean
(``estimators.toolbox.nav_error`` convention: C_b^n(point) = exp([psi x]) C_b^n(mean)). The EKF's
error state is the same 17-vector (paper: the EKF state vector with phi_N, phi_E, phi_D).

Choices where the paper is silent, ambiguous or wrong (also in docs/reproduction_chan.md):

* UKF weights: W_i = 1 / (2 (n + lambda)) (the paper prints lambda / (2 (n + lambda)), which does
  not sum to one); P^xy has no R added (the paper adds R to P^xy, a misprint); the covariance
  update is P = P^xx - K P^yy K^T (the paper prints K P^xy K^T, dimensionally wrong);
  alpha = 0.99, beta = 2, kappa = 0 (paper).
* Propagation (paper: each sigma point integrated through the noise-free dynamics with 10 RK4
  steps per GPS interval): every sigma point is integrated with one RK4 step of eqs. 1-3 per IMU
  interval (``strapdown.rk4_step``; rates at the interval's ends and their mean at its middle),
  i.e. 100 steps per second at 100 Hz rather than 10, so that no IMU sample is skipped. The
  process noise is added to the propagated covariance (additive Q) and the points are drawn
  again from it before the measurement update.
* Eq. 7 lacks the receiver position and prints "+" for a product: the model is
  ``estimators.toolbox.gnss_model`` (range to r_ins + C_b^n l_b, with the Sagnac rotation).
* NHC: the rows are the body y and z velocities (the paper's text says "x and y" once), noise
  ``nhc_std`` (0.1 m/s, covering the road's bumps and a small mounting misalignment; the paper
  prints no value). It is stacked with the GPS measurements at each GPS epoch and applied alone at
  1 Hz when an expected GPS epoch has not come half an interval after its time (complete
  outages).
* Not printed: P0, Q, R. P0: ``initial_position_std`` per axis (10 m), 0.5 m/s, 1 deg roll and
  pitch, 3 deg yaw, the bias priors of an automotive MEMS IMU (10 mg, 0.2 deg/s), cb and d taken
  from the first GPS epoch's residuals with 30 m and 3 m/s. Q: white noise of the IMU (config
  ``accel_noise``, ``gyro_noise``, velocity and angle random walks of the automotive MEMS
  preset), small bias random walks, and the receiver-clock model of a TCXO
  (``gnss_model.clock_noise``). R: the receiver's reported pseudorange and pseudorange-rate
  1-sigma of each signal (``pseudorange_std``, ``pseudorange_rate_std``), floored at
  ``pseudorange_std`` 3 m and ``range_rate_std`` 0.1 m/s when the stream lacks them.
* The EKF (eqs. 4-6): position error rate dr' = dv as printed (eq. 4), velocity and attitude error
  equations in the psi convention of ``nav_error`` (eq. 5: -[f^n x] psi - C_b^n dba
  - (2 w_ie + w_en) x dv - (2 dw_ie + dw_en) x v; eq. 6: psi' = -w_in x psi - C_b^n dbg - dw_in,
  with dw_ie from the latitude error and dw_en from the velocity error; the paper's phi is -psi).
  The nominal state is propagated by the toolbox strapdown (``strapdown.propagate``), the
  covariance at 10 Hz with Phi = I + F dt + (F dt)^2 / 2; closed loop (errors fed back after each
  update). Measurements linearised at the nominal state (the "linearised model given in [2]").

Public names
------------
TcUkf, TcEkf.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from estimators.base import NAV_COLUMNS, STD_COLUMNS, Estimator
from estimators.toolbox import constraints, gnss_model, nav_error
from estimators.toolbox.kalman import ErrorState
from estimators.toolbox.sigma_points import symmetric_points
from estimators.toolbox.strapdown import propagate, rk4_step
from simulator.earth import (
    OMEGA_E_RAD_S,
    earth_rate_ned,
    geodetic_to_ecef,
    ned_to_ecef_matrix,
    quat_multiply,
    quat_to_dcm,
    quat_to_euler,
    radii_of_curvature,
    rotvec_to_quat,
    skew,
)
from simulator.units import DEG_S, DEG_S_RT_HZ, MILLI_G, MILLI_G_RT_HZ

N_STATES = 17  # [dr(3), dv(3), psi(3), ba(3), bg(3), cb, d]
SENSOR_COLUMNS = ("accel_bias_x", "accel_bias_y", "accel_bias_z", "gyro_bias_x", "gyro_bias_y",
                  "gyro_bias_z", "clock_bias", "clock_drift")
PAPER = ("Chan, Aung, Thar, Lee, Kaung, 'Robust Navigation System for a Land Vehicle' "
         "(tightly coupled INS/GPS, UKF vs EKF, NHC)")
COVARIANCE_RATE_HZ = 10.0  # EKF covariance propagation rate
CLOCK_INIT_STD = (30.0, 3.0)  # cb (m), d (m/s) after the first epoch's residuals


def _rad_deg(x: float) -> float:
    return float(np.radians(x))


DEFAULTS = {
    "nhc": True,
    "nhc_std": 0.1,  # m/s, body y and z velocity
    "nhc_rate": 1.0,  # Hz, NHC alone when GPS is missing
    "lever_arm": [0.0, 0.0, 0.0],  # IMU to GPS antenna, body FRD, m
    "initial_position_std": 10.0,  # m per axis
    "initial_velocity_std": 0.5,  # m/s
    "initial_attitude_std": [1.0, 1.0, 3.0],  # deg roll, pitch, yaw
    "accel_bias_std": 10 * MILLI_G,  # m/s^2, prior
    "gyro_bias_std": 0.2 * DEG_S,  # rad/s, prior
    "accel_noise": 0.1 * MILLI_G_RT_HZ * 3,  # m/s^2/sqrt(Hz), velocity random walk (3x datasheet:
    "gyro_noise": 0.005 * DEG_S_RT_HZ * 3,  # rad/s/sqrt(Hz) unmodelled scale factors, vibration)
    "accel_bias_walk": 1e-4,  # m/s^2/sqrt(s)
    "gyro_bias_walk": 1e-5,  # rad/s/sqrt(s)
    "pseudorange_std": 3.0,  # m, when the stream reports none
    "range_rate_std": 0.1,  # m/s, when the stream reports none
}


class _TightlyCoupled(Estimator):
    """What the two filters share: configuration, IMU handling, GPS epochs, clock start,
    NHC scheduling, output."""

    needs = ("imu", "gnss_raw")
    paper = PAPER
    output_columns = (*NAV_COLUMNS, *STD_COLUMNS, *SENSOR_COLUMNS)
    defaults = DEFAULTS

    def setup(self) -> None:
        cfg = self.config
        imu = self.columns["imu"]
        self._gyro_idx = [imu[c] for c in ("gyro_x", "gyro_y", "gyro_z")]
        self._accel_idx = [imu[c] for c in ("accel_x", "accel_y", "accel_z")]
        self._increments = self.units["imu"].get("gyro_x") == "rad"
        self._lever = np.asarray(cfg["lever_arm"], dtype=float)
        self._t_imu: float | None = None
        self._w_prev = np.zeros(3)
        self._f_prev = np.zeros(3)
        self._clock_started = False
        self._t_update = self.initial.t
        self._next_nhc = np.inf
        self._w_last = np.zeros(3)  # last body rate (bias-corrected), for the lever arm
        p0 = np.zeros(N_STATES)
        p0[0:3] = cfg["initial_position_std"]
        p0[3:6] = cfg["initial_velocity_std"]
        p0[6:9] = np.radians(cfg["initial_attitude_std"])
        p0[9:12] = cfg["accel_bias_std"]
        p0[12:15] = cfg["gyro_bias_std"]
        p0[15:17] = CLOCK_INIT_STD
        self._p0 = np.diag(p0**2)

    # -- inputs --------------------------------------------------------------------------------
    def _imu_sample(self, t: float, row: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        """Body rate and specific force over the interval ending at t, and its length."""
        dt = t - self._t_imu if self._t_imu is not None else 0.0
        w, f = row[self._gyro_idx], row[self._accel_idx]
        if self._increments and dt > 0:
            w, f = w / dt, f / dt
        return w, f, dt

    def process_noise(self, dt: float) -> np.ndarray:
        """Discrete Q over ``dt`` (s) on the tangent/error state (white accelerometer and gyro
        noise, bias random walks, the receiver clock)."""
        cfg = self.config
        q = np.zeros((N_STATES, N_STATES))
        q[3:6, 3:6] = np.eye(3) * cfg["accel_noise"] ** 2 * dt
        q[6:9, 6:9] = np.eye(3) * cfg["gyro_noise"] ** 2 * dt
        q[9:12, 9:12] = np.eye(3) * cfg["accel_bias_walk"] ** 2 * dt
        q[12:15, 12:15] = np.eye(3) * cfg["gyro_bias_walk"] ** 2 * dt
        q[15:17, 15:17] = gnss_model.clock_noise(dt)
        return q

    def _measurement_noise(self, ep: gnss_model.RawEpoch, with_nhc: bool) -> np.ndarray:
        cfg = self.config
        pr = np.where(np.isfinite(ep.pseudorange_std), ep.pseudorange_std, cfg["pseudorange_std"])
        rr = np.where(np.isfinite(ep.range_rate_std), ep.range_rate_std, cfg["range_rate_std"])
        nhc = [cfg["nhc_std"]] * 2 if with_nhc else []
        return np.diag(np.concatenate([pr, rr, nhc]) ** 2)

    def on_imu(self, t: float, row: np.ndarray) -> None:
        w, f, dt = self._imu_sample(t, row)
        if dt > 0:
            self.inertial_step(w, f, dt)
        self._w_prev, self._f_prev, self._t_imu = w, f, t
        if self.config["nhc"] and t >= self._next_nhc:
            self.update(t, None)
            self._next_nhc += 1.0 / self.config["nhc_rate"]

    def on_gnss_raw(self, t: float, block: np.ndarray) -> None:
        ep = gnss_model.raw_epoch(block, self.columns["gnss_raw"])
        if not self._clock_started:
            self.start_clock(t, ep)
            self._clock_started = True
        self.update(t, ep if len(block) else None)
        # NHC alone if the next epoch (expected 1 / nhc_rate later) has not come within half
        # an interval of its time
        self._next_nhc = t + 1.5 / self.config["nhc_rate"]

    def _clock_from_residuals(self, ep: gnss_model.RawEpoch, pos_ecef: np.ndarray,
                              vel_ecef: np.ndarray) -> tuple[float, float]:
        pr, rate, _ = gnss_model.predict(ep.sat_pos, ep.sat_vel, pos_ecef, vel_ecef)
        return (float(np.median(ep.pseudorange - pr)), float(np.median(ep.range_rate - rate)))

    def _output(self, pos: np.ndarray, v: np.ndarray, q: np.ndarray, biases: np.ndarray,
                clock: np.ndarray, p: np.ndarray) -> np.ndarray:
        roll, pitch, yaw = quat_to_euler(q)
        std = np.sqrt(np.maximum(np.diag(p)[:9], 0.0))
        return np.concatenate([[np.degrees(pos[0]), np.degrees(pos[1]), pos[2], *v, roll, pitch,
                                yaw], std, biases, clock])

    # -- filter-specific -----------------------------------------------------------------------
    def inertial_step(self, w: np.ndarray, f: np.ndarray, dt: float) -> None:
        raise NotImplementedError

    def start_clock(self, t: float, ep: gnss_model.RawEpoch) -> None:
        raise NotImplementedError

    def update(self, t: float, ep: gnss_model.RawEpoch | None) -> None:
        raise NotImplementedError


def _antenna_ecef(pos: np.ndarray, v: np.ndarray, c_bn: np.ndarray, lever: np.ndarray,
                  w_eb: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Antenna ECEF position and velocity of states (..., 3) and the NED-to-ECEF rotation."""
    lat, lon = pos[..., 0], pos[..., 1]
    off, voff = gnss_model.antenna_offset(c_bn, lever, w_eb)
    c_ne = ned_to_ecef_matrix(lat, lon)
    r = geodetic_to_ecef(lat, lon, pos[..., 2]) + np.einsum("...ij,...j->...i", c_ne, off)
    return r, np.einsum("...ij,...j->...i", c_ne, v + voff), c_ne


def _earth_rate_body(c_bn: np.ndarray, lat: np.ndarray) -> np.ndarray:
    """C_n^b w_ie^n of states (..., 3, 3), (...)."""
    w_ie = earth_rate_ned(lat).reshape(np.shape(lat) + (3,))
    return np.einsum("...ji,...j->...i", c_bn, w_ie)


# ----------------------------------------------------------------------------------------------
# tc_ukf
# ----------------------------------------------------------------------------------------------
@njit(cache=True)
def _propagate_points(pos: np.ndarray, v: np.ndarray, q: np.ndarray, ba: np.ndarray,
                      bg: np.ndarray, w: np.ndarray, f: np.ndarray, dt: np.ndarray) -> None:
    """Integrate every sigma point in place through the buffered IMU intervals: one RK4 step
    of Chan eqs. 1-3 per interval, bias-corrected rates at its start (row j), end (row j + 1)
    and their mean at its middle. pos, v, ba, bg: (k, 3); q: (k, 4); w, f: (m + 1, 3);
    dt: (m,)."""
    x = np.empty(10)
    work = np.empty((5, 10))
    rates = np.empty((6, 3))  # w0, w_mid, w1, f0, f_mid, f1
    for i in range(pos.shape[0]):
        x[0:3], x[3:6], x[6:10] = pos[i], v[i], q[i]
        for j in range(dt.shape[0]):
            for a in range(3):
                rates[0, a] = w[j, a] - bg[i, a]
                rates[2, a] = w[j + 1, a] - bg[i, a]
                rates[1, a] = 0.5 * (rates[0, a] + rates[2, a])
                rates[3, a] = f[j, a] - ba[i, a]
                rates[5, a] = f[j + 1, a] - ba[i, a]
                rates[4, a] = 0.5 * (rates[3, a] + rates[5, a])
            rk4_step(x, rates[0], rates[1], rates[2], rates[3], rates[4], rates[5], dt[j], work)
        pos[i], v[i], q[i] = x[0:3], x[3:6], x[6:10]


@njit(cache=True)
def _tangent(pos: np.ndarray, v: np.ndarray, q: np.ndarray, ba: np.ndarray, bg: np.ndarray,
             clock: np.ndarray, ref: int, rm: float, rt: float) -> np.ndarray:
    """Tangent vectors (k, 17) of the points around point ``ref`` (the ``boxminus`` of
    ``TcUkf``): NED position displacement (m), velocity, the rotation vector of
    q_i * conj(q_ref) (NED-frame attitude error, ``nav_error`` convention), biases, clock."""
    k = pos.shape[0]
    out = np.empty((k, 17))
    lat0, lon0, h0 = pos[ref, 0], pos[ref, 1], pos[ref, 2]
    a2, b2, c2, d2 = q[ref, 0], -q[ref, 1], -q[ref, 2], -q[ref, 3]
    for i in range(k):
        out[i, 0] = (pos[i, 0] - lat0) * (rm + h0)
        out[i, 1] = (pos[i, 1] - lon0) * (rt + h0) * np.cos(lat0)
        out[i, 2] = h0 - pos[i, 2]
        a1, b1, c1, d1 = q[i, 0], q[i, 1], q[i, 2], q[i, 3]
        w = a1 * a2 - b1 * b2 - c1 * c2 - d1 * d2
        x = a1 * b2 + b1 * a2 + c1 * d2 - d1 * c2
        y = a1 * c2 - b1 * d2 + c1 * a2 + d1 * b2
        z = a1 * d2 + b1 * c2 - c1 * b2 + d1 * a2
        if w < 0:
            w, x, y, z = -w, -x, -y, -z
        s = np.sqrt(x * x + y * y + z * z)
        scale = 2.0 * np.arctan2(s, w) / s if s > 1e-12 else 2.0
        for j in range(3):
            out[i, 3 + j] = v[i, j] - v[ref, j]
            out[i, 9 + j] = ba[i, j] - ba[ref, j]
            out[i, 12 + j] = bg[i, j] - bg[ref, j]
        out[i, 6], out[i, 7], out[i, 8] = x * scale, y * scale, z * scale
        out[i, 15] = clock[i, 0] - clock[ref, 0]
        out[i, 16] = clock[i, 1] - clock[ref, 1]
    return out


def _plus_one(state: dict, dx: np.ndarray) -> dict:
    """One state moved by a tangent vector (``TcUkf.boxplus`` of a single point, through the
    ``nav_error`` convention)."""
    q, v, pos = nav_error.perturb(state["q"], state["v"], state["pos"], dx[:9])
    return {"pos": pos, "v": v, "q": q, "ba": state["ba"] + dx[9:12],
            "bg": state["bg"] + dx[12:15], "clock": state["clock"] + dx[15:17]}


class TcUkf(_TightlyCoupled):
    """Tightly coupled total-state UKF (Chan et al.; see the module docstring).

    Config: ``nhc`` (bool), ``alpha``, ``beta`` (sigma-point spread and prior, 0.99 and 2),
    and the noise and prior keys of ``DEFAULTS``.
    """

    name = "tc_ukf"
    defaults = {**DEFAULTS, "alpha": 0.99, "beta": 2.0}

    def setup(self) -> None:
        super().setup()
        init = self.initial
        self._mean = {"pos": np.array(init.position, dtype=float),
                      "v": np.array(init.velocity, dtype=float), "q": init.quaternion,
                      "ba": np.zeros(3), "bg": np.zeros(3), "clock": np.zeros(2)}
        self._p = self._p0.copy()
        self._draw()
        self._buf_w: list[np.ndarray] = []
        self._buf_f: list[np.ndarray] = []
        self._buf_dt: list[float] = []
        self._fresh = True  # the points still are the drawn set (mean known)

    # manifold hooks: x (+) dx and x1 (-) x0 on the 17-dim tangent space --------------------
    @staticmethod
    def boxplus(mean: dict, dx: np.ndarray) -> dict:
        """States ``mean`` moved by tangent vectors dx (k, 17); returns arrays over k."""
        pos = mean["pos"]
        rm, rt = radii_of_curvature(pos[0])
        k = len(dx)
        new_pos = np.empty((k, 3))
        new_pos[:, 0] = pos[0] + dx[:, 0] / (rm + pos[2])
        new_pos[:, 1] = pos[1] + dx[:, 1] / ((rt + pos[2]) * np.cos(pos[0]))
        new_pos[:, 2] = pos[2] - dx[:, 2]
        q = quat_multiply(rotvec_to_quat(dx[:, 6:9]), mean["q"][None, :])
        return {"pos": new_pos, "v": mean["v"] + dx[:, 3:6], "q": q,
                "ba": mean["ba"] + dx[:, 9:12], "bg": mean["bg"] + dx[:, 12:15],
                "clock": mean["clock"] + dx[:, 15:17]}

    @staticmethod
    def boxminus(pts: dict, ref: int = 0) -> np.ndarray:
        """Tangent vectors (k, 17) of the points ``pts`` around their point ``ref``."""
        rm, rt = radii_of_curvature(pts["pos"][ref, 0])
        return _tangent(pts["pos"], pts["v"], pts["q"], pts["ba"], pts["bg"], pts["clock"], ref,
                        float(rm), float(rt))

    def _draw(self) -> None:
        """Sigma points of N(mean, P) on the tangent space (paper step 1), as states."""
        try:
            dx, self._wm, self._wc = symmetric_points(np.zeros(N_STATES), self._p,
                                                      self.config["alpha"], self.config["beta"])
        except np.linalg.LinAlgError:  # lost positive definiteness: clip the eigenvalues
            val, vec = np.linalg.eigh(self._p)
            self._p = (vec * np.maximum(val, 1e-12)) @ vec.T
            dx, self._wm, self._wc = symmetric_points(np.zeros(N_STATES), self._p,
                                                      self.config["alpha"], self.config["beta"])
        self._pts = self.boxplus(self._mean, dx)
        self._pts_dx = dx

    def _mean_cov(self) -> tuple[dict, np.ndarray, np.ndarray]:
        """Weighted mean and covariance of the propagated points (paper step 3), and the
        points' tangent deviations from the mean."""
        center = {k: v[0] for k, v in self._pts.items()}
        d = self.boxminus(self._pts)
        mean_dx = self._wm @ d
        mean = _plus_one(center, mean_dx)
        dev = d - mean_dx
        return mean, (self._wc[:, None] * dev).T @ dev, dev

    # -- propagation ---------------------------------------------------------------------------
    def inertial_step(self, w: np.ndarray, f: np.ndarray, dt: float) -> None:
        if not self._buf_dt:  # the interval's start
            self._buf_w, self._buf_f = [self._w_prev], [self._f_prev]
        self._buf_w.append(w)
        self._buf_f.append(f)
        self._buf_dt.append(dt)

    def _flush(self) -> None:
        if not self._buf_dt:
            return
        p = self._pts
        _propagate_points(p["pos"], p["v"], p["q"], p["ba"], p["bg"], np.array(self._buf_w),
                          np.array(self._buf_f), np.array(self._buf_dt))
        p["clock"][:, 0] += p["clock"][:, 1] * sum(self._buf_dt)  # cb' = d
        self._buf_dt = []
        self._fresh = False

    def _predict(self, t: float) -> None:
        """Propagate to t: mean and covariance of the points plus Q (paper step 3)."""
        self._flush()
        if not self._fresh:
            self._mean, p_xx, _ = self._mean_cov()
            self._p = p_xx + self.process_noise(t - self._t_update)
            self._t_update = t

    # -- measurements --------------------------------------------------------------------------
    def start_clock(self, t: float, ep: gnss_model.RawEpoch) -> None:
        if len(ep.sv) == 0:
            return
        self._predict(t)
        m = self._mean
        c_bn = quat_to_dcm(m["q"])
        r, v, _ = _antenna_ecef(m["pos"], m["v"], c_bn, self._lever, np.zeros(3))
        m["clock"] = np.array(self._clock_from_residuals(ep, r, v))
        self._p[15:17, :] = 0.0
        self._p[:, 15:17] = 0.0
        self._p[15:17, 15:17] = np.diag(np.square(CLOCK_INIT_STD))
        self._draw()
        self._fresh = True

    def _observe(self, pts: dict, ep: gnss_model.RawEpoch | None, nhc: bool) -> np.ndarray:
        """Predicted measurements of every point (paper step 4): pseudoranges, range rates
        (eqs. 7-8) and the NHC body y, z velocities; shape (k, m)."""
        c_bn = quat_to_dcm(pts["q"])
        parts = []
        if ep is not None:
            w_ib = self._w_prev[None, :] - pts["bg"]
            w_eb = w_ib - _earth_rate_body(c_bn, pts["pos"][:, 0])
            r, v, _ = _antenna_ecef(pts["pos"], pts["v"], c_bn, self._lever, w_eb)
            pr, rate, _ = gnss_model.predict(ep.sat_pos, ep.sat_vel, r, v, pts["clock"][:, 0],
                                             pts["clock"][:, 1])
            parts += [pr, rate]
        if nhc:
            parts.append(np.einsum("kji,kj->ki", c_bn, pts["v"])[:, 1:3])
        return np.concatenate(parts, axis=1)

    def update(self, t: float, ep: gnss_model.RawEpoch | None) -> None:
        nhc = bool(self.config["nhc"])
        self._predict(t)
        self._draw()  # the points of N(x_bar, P^xx + Q)
        y = self._observe(self._pts, ep, nhc)
        y_mean = self._wm @ y
        dy = y - y_mean
        dx = self._pts_dx - self._wm @ self._pts_dx
        p_yy = (self._wc[:, None] * dy).T @ dy
        r = (self._measurement_noise(ep, nhc) if ep is not None
             else np.eye(2) * self.config["nhc_std"] ** 2)
        p_yy = p_yy + r
        p_xy = (self._wc[:, None] * dx).T @ dy  # no R here (the paper's misprint)
        z_parts = [ep.pseudorange, ep.range_rate] if ep is not None else []
        z = np.concatenate(z_parts + ([np.zeros(2)] if nhc else []))
        gain = np.linalg.solve(p_yy, p_xy.T).T
        correction = gain @ (z - y_mean)
        self._mean = _plus_one(self._mean, correction)
        p = self._p - gain @ p_yy @ gain.T
        self._p = 0.5 * (p + p.T)
        self._draw()
        self._fresh = True

    def solution(self, t: float) -> np.ndarray:
        self._flush()
        mean, p, _ = self._mean_cov() if not self._fresh else (self._mean, self._p, None)
        return self._output(mean["pos"], mean["v"], mean["q"],
                            np.concatenate([mean["ba"], mean["bg"]]), mean["clock"], p)


# ----------------------------------------------------------------------------------------------
# tc_ekf
# ----------------------------------------------------------------------------------------------
def error_dynamics(pos: np.ndarray, v: np.ndarray, c_bn: np.ndarray, f_b: np.ndarray
                   ) -> np.ndarray:
    """System matrix F (17 x 17) of the error state (Chan et al. eqs. 4-6 in the psi
    convention of ``nav_error``; see the module docstring)."""
    lat, h = pos[0], pos[2]
    rm, rt = radii_of_curvature(lat)
    sl, cl, tl = np.sin(lat), np.cos(lat), np.tan(lat)
    w_ie = OMEGA_E_RAD_S * np.array([cl, 0.0, -sl])
    w_en = np.array([v[1] / (rt + h), -v[0] / (rm + h), -v[1] * tl / (rt + h)])
    # d w_ie / d dr_n and d w_en / d dv (latitude and velocity errors)
    dwie_dr = np.zeros((3, 3))
    dwie_dr[:, 0] = OMEGA_E_RAD_S * np.array([-sl, 0.0, -cl]) / (rm + h)
    dwen_dv = np.array([[0.0, 1.0 / (rt + h), 0.0], [-1.0 / (rm + h), 0.0, 0.0],
                        [0.0, -tl / (rt + h), 0.0]])
    f = np.zeros((N_STATES, N_STATES))
    f[0:3, 3:6] = np.eye(3)  # eq. 4
    f_n = c_bn @ f_b
    f[3:6, 6:9] = -skew(f_n)  # eq. 5
    f[3:6, 9:12] = -c_bn
    f[3:6, 3:6] = -skew(2.0 * w_ie + w_en) + skew(v) @ dwen_dv
    f[3:6, 0:3] = skew(v) @ (2.0 * dwie_dr)
    f[6:9, 6:9] = -skew(w_ie + w_en)  # eq. 6
    f[6:9, 12:15] = -c_bn
    f[6:9, 0:3] = -dwie_dr
    f[6:9, 3:6] = -dwen_dv
    f[15, 16] = 1.0  # clock: cb' = d
    return f


class TcEkf(_TightlyCoupled):
    """Tightly coupled error-state EKF (Chan et al. eqs. 4-6; see the module docstring).

    Config: ``nhc`` (bool) and the noise and prior keys of ``DEFAULTS``.
    """

    name = "tc_ekf"

    def setup(self) -> None:
        super().setup()
        init = self.initial
        self._q = init.quaternion
        self._v = np.array(init.velocity, dtype=float)
        self._pos = np.array(init.position, dtype=float)
        self._ba = np.zeros(3)
        self._bg = np.zeros(3)
        self._clock = np.zeros(2)
        self._err = ErrorState(self._p0)
        self._dth_prev = np.zeros(3)
        self._dv_prev = np.zeros(3)
        self._acc_f = np.zeros(3)
        self._acc_dt = 0.0

    def inertial_step(self, w: np.ndarray, f: np.ndarray, dt: float) -> None:
        if self._increments:  # the interval's mean rates
            w_c, f_c = w - self._bg, f - self._ba
        else:  # trapezoid over the interval
            w_c = 0.5 * (w + self._w_prev) - self._bg
            f_c = 0.5 * (f + self._f_prev) - self._ba
        dth, dv = w_c * dt, f_c * dt
        self._q, self._v, self._pos = propagate(self._q, self._v, self._pos, dth, dv,
                                                self._dth_prev, self._dv_prev, dt)
        self._dth_prev, self._dv_prev = dth, dv
        self._clock[0] += self._clock[1] * dt
        self._acc_f += f_c * dt
        self._acc_dt += dt
        if self._acc_dt >= 1.0 / COVARIANCE_RATE_HZ - 1e-9:
            self._propagate_covariance()

    def _propagate_covariance(self) -> None:
        dt = self._acc_dt
        if dt <= 0:
            return
        fm = error_dynamics(self._pos, self._v, quat_to_dcm(self._q), self._acc_f / dt) * dt
        phi = np.eye(N_STATES) + fm + 0.5 * fm @ fm
        self._err.predict(phi, self.process_noise(dt))
        self._acc_f = np.zeros(3)
        self._acc_dt = 0.0

    def start_clock(self, t: float, ep: gnss_model.RawEpoch) -> None:
        if len(ep.sv) == 0:
            return
        r, v, _ = _antenna_ecef(self._pos, self._v, quat_to_dcm(self._q), self._lever,
                                np.zeros(3))
        self._clock = np.array(self._clock_from_residuals(ep, r, v))

    def update(self, t: float, ep: gnss_model.RawEpoch | None) -> None:
        self._propagate_covariance()
        nhc = bool(self.config["nhc"])
        dz, rows, noise = [], [], []
        c_bn = quat_to_dcm(self._q)
        if ep is not None:
            w_eb = self._w_prev - self._bg - _earth_rate_body(c_bn, self._pos[0])
            r, v, c_ne = _antenna_ecef(self._pos, self._v, c_bn, self._lever, w_eb)
            pr, rate, los = gnss_model.predict(ep.sat_pos, ep.sat_vel, r, v, self._clock[0],
                                               self._clock[1])
            u = los @ c_ne  # lines of sight in NED, (m, 3)
            m = len(pr)
            h_pr = np.zeros((m, N_STATES))
            h_pr[:, 0:3] = -u
            h_pr[:, 6:9] = u @ skew(c_bn @ self._lever)
            h_pr[:, 15] = 1.0
            h_rr = np.zeros((m, N_STATES))
            h_rr[:, 3:6] = -u
            h_rr[:, 16] = 1.0
            dz += [pr - ep.pseudorange, rate - ep.range_rate]
            rows += [h_pr, h_rr]
            noise.append(self._measurement_noise(ep, False))
        if nhc:
            z_nhc, h_nhc = constraints.nonholonomic(self._q, self._v, N_STATES)
            dz.append(z_nhc)
            rows.append(h_nhc)
            noise.append(np.eye(2) * self.config["nhc_std"] ** 2)
        if not dz:
            return
        r_all = np.zeros((sum(len(x) for x in dz),) * 2)
        i = 0
        for block in noise:
            r_all[i:i + len(block), i:i + len(block)] = block
            i += len(block)
        self._err.update(np.concatenate(dz), np.vstack(rows), r_all)
        dx = self._err.feedback()
        self._q, self._v, self._pos = nav_error.correct(self._q, self._v, self._pos, dx[0:9])
        self._ba = self._ba - dx[9:12]
        self._bg = self._bg - dx[12:15]
        self._clock = self._clock - dx[15:17]

    def solution(self, t: float) -> np.ndarray:
        return self._output(self._pos, self._v, self._q, np.concatenate([self._ba, self._bg]),
                            self._clock, self._err.p)


