"""The loosely coupled INS error-state Kalman filter core shared by the INS estimators: a nominal
strapdown solution with bias compensation, the 15-state error model of ``ins_error``, and closed-
or open-loop correction (``kalman.ErrorState``), switchable mid-run.

Lean by design. ``add_imu`` only copies the sample into a preallocated buffer; ``flush`` (called
before every measurement and every solution, so always causally) integrates the buffered samples
in one compiled loop (``strapdown.propagate`` per sample, with the bias estimates removed and
rate samples turned into trapezoidal increments) and then propagates the covariance once over
the flushed interval with the mean specific force of the interval (the usual practice of running
the covariance propagation slower than the mechanisation, Groves 2013, chapter 14). With a
10 Hz solution rate the covariance is propagated at 10 Hz or faster.

Optional extra states after the 15: first-order Gauss-Markov errors of an aid (``extra_sigma``,
``extra_tau``; a GNSS receiver's correlated fix error, for example), x' = -x / tau + w with
steady-state sigma (Brown & Hwang, 4th ed., section 2.9), appended to F and G Q G^T. Their
current estimate ``extra`` is kept beside the nominal solution: fed back like the biases in
closed loop, and decayed by exp(-dt / tau) between updates (the process's expected value).

Optional yaw-response states (``yaw_response_sigma``), placed between the 15 and the extra states
(``extra_start`` is the first extra state's index): the third column k of the gyro triad's
scale-factor and misalignment error matrix S + M, what the three gyros read per rad/s of the
body's z rate beyond it (the x and y gyros' misalignment towards z, the z gyro's scale factor).
They are random constants (P0 from the datasheet) coupled to the attitude: the compensated rate
is w - b_hat - k_hat w_z, so its error is -dbg - dk w_z and d(psi)/dt gains -C_b^n dk w_z
(Groves 2013, eq. 14.63's scale-factor and misalignment terms, the column of the one large rate
of a land vehicle kept). Without them a scale-factor error s enters only as bias process noise,
(s dw)^2 for each flush's change dw of the reading (``InsNoise``): increments taken as
independent although s is one constant, so a yaw rate that ramps up over N flushes adds 1/N of
the variance (s w)^2 its bias really gains. With the states that noise keeps the x and y rates
only. (The lever-arm terms of the aids take the rate error as -dbg alone: dk w_z times a lever
arm of a metre is under a millimetre per second.)

Public names
------------
InsNoise, InsFilter.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numba import njit

from estimators.base import InitialState
from estimators.toolbox import nav_error
from estimators.toolbox.gating import innovation_covariance, passes_gate
from estimators.toolbox.ins_error import BA, BG, N_STATES, discretise, noise_psd, system_matrix
from estimators.toolbox.kalman import ErrorState
from estimators.toolbox.strapdown import propagate
from simulator.earth import quat_to_dcm, quat_to_euler
from simulator.errors import InputError

IMU_AXES = ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")


@dataclass(frozen=True)
class InsNoise:
    """Continuous noise model of the IMU, per axis (equal on the three axes).

    Attributes
    ----------
    accel_noise : accelerometer white noise density, m/s^2/sqrt(Hz).
    gyro_noise : gyro white noise density, rad/s/sqrt(Hz).
    accel_bias_sigma, gyro_bias_sigma : steady-state 1-sigma of the Gauss-Markov in-run biases,
        m/s^2 and rad/s.
    accel_bias_tau, gyro_bias_tau : their correlation times, s.
    accel_scale_sigma, gyro_scale_sigma : 1-sigma scale-factor errors (dimensionless), not
        states: as a reading x changes by dx over a flush, its bias (which absorbs s x) moves
        by s dx, so (s dx)^2 joins the bias's process noise (``toolbox.datasheet``).
    gyro_g_sensitivity : gyro g-sensitivity, rad/s per m/s^2, likewise with the change of the
        specific force.
    """

    accel_noise: float
    gyro_noise: float
    accel_bias_sigma: float
    gyro_bias_sigma: float
    accel_bias_tau: float
    gyro_bias_tau: float
    accel_scale_sigma: float = 0.0
    gyro_scale_sigma: float = 0.0
    gyro_g_sensitivity: float = 0.0


@njit(cache=True)
def _integrate(t: np.ndarray, raw: np.ndarray, n: int, increments: bool, t0: float,
               q: np.ndarray, v: np.ndarray, pos: np.ndarray, ba: np.ndarray, bg: np.ndarray,
               prev: np.ndarray, sums: np.ndarray) -> float:
    """Strapdown over buffered samples ``raw[:n]`` (gyro xyz, accel xyz; rates or increments)
    taken at ``t[:n]``, from the state at ``t0``; q, v, pos, ``prev`` (previous increments and
    raw sample, 12) are updated in place, ``sums`` (7) accumulates the NED velocity increment
    without gravity, the compensated angle increment and the time. Returns the last time."""
    t_last = t0
    for k in range(n):
        dt = t[k] - t_last
        if dt <= 0.0:  # the sample at the start time: its interval predates the state
            prev[6:12] = raw[k]
            continue
        if increments:
            dth = raw[k, 0:3] - bg * dt
            dvb = raw[k, 3:6] - ba * dt
        else:
            dth = 0.5 * (prev[6:9] + raw[k, 0:3]) * dt - bg * dt
            dvb = 0.5 * (prev[9:12] + raw[k, 3:6]) * dt - ba * dt
        q_new, v_new, pos_new = propagate(q, v, pos, dth, dvb, prev[0:3], prev[3:6], dt)
        a, b, c, d = q[0], q[1], q[2], q[3]  # body-to-NED DCM rows times dvb, at the start
        sums[0] += ((a * a + b * b - c * c - d * d) * dvb[0] + 2 * (b * c - a * d) * dvb[1]
                    + 2 * (b * d + a * c) * dvb[2])
        sums[1] += (2 * (b * c + a * d) * dvb[0] + (a * a - b * b + c * c - d * d) * dvb[1]
                    + 2 * (c * d - a * b) * dvb[2])
        sums[2] += (2 * (b * d - a * c) * dvb[0] + 2 * (c * d + a * b) * dvb[1]
                    + (a * a - b * b - c * c + d * d) * dvb[2])
        sums[3:6] += dth
        sums[6] += dt
        q[:] = q_new
        v[:] = v_new
        pos[:] = pos_new
        prev[0:3] = dth
        prev[3:6] = dvb
        prev[6:12] = raw[k]
        t_last = t[k]
    return t_last


class InsFilter:
    """Nominal INS solution and its error-state Kalman filter.

    Parameters
    ----------
    initial : InitialState
        Start time and state (truth perturbed by the scenario's ``init`` errors).
    imu_columns : mapping
        Column positions of the IMU stream (``gyro_x`` ... ``accel_z``).
    increments : bool
        True when the IMU gives angle and velocity increments, False for rates.
    p0_sigma : (15,) initial 1-sigma of the error state.
    noise : InsNoise
    closed_loop : bool
        Start in closed loop (True) or open loop.
    initial_biases : (6,), optional
        Initial accelerometer and gyro bias estimates.
    extra_sigma, extra_tau : (k,), optional
        Steady-state 1-sigma and correlation times (s) of k Gauss-Markov states after the 15
        (module docstring); they start at zero with their steady-state covariance.
    mounting : (3, 3), optional
        C_s^v, the IMU's sensor frame to the vehicle frame (``installation.Installation``): the
        samples are rotated into the vehicle frame before the strapdown, so that the filter
        navigates the vehicle (the frame of the constraints and lever arms).
    yaw_response_sigma : (3,), optional
        1-sigma of the yaw-response states (module docstring; x, y gyro misalignment towards
        z, z gyro scale factor, dimensionless); None: no such states.
    scale_noise_window : float
        s; 0: the scale-factor and g-sensitivity noise (``InsNoise``) counts the change of the
        mean reading from one flush to the next. Above 0: from one window of this length to
        the next, added at the flush that completes a window, so that a vibration that
        averages out within the window (a car body's, 1-20 Hz) is not taken for a change of
        the bias while a manoeuvre still is.
    """

    def __init__(self, initial: InitialState, imu_columns: Mapping[str, int], increments: bool,
                 p0_sigma: np.ndarray, noise: InsNoise, closed_loop: bool = True,
                 initial_biases: np.ndarray | None = None, buffer_size: int = 512,
                 mounting: np.ndarray | None = None, extra_sigma: np.ndarray | None = None,
                 extra_tau: np.ndarray | None = None,
                 yaw_response_sigma: np.ndarray | None = None, sparse: bool = False,
                 scale_noise_window: float = 0.0):
        self.t = float(initial.t)
        self.q = np.array(initial.quaternion, dtype=float)
        self.v = np.array(initial.velocity, dtype=float)
        self.pos = np.array(initial.position, dtype=float)
        biases = np.zeros(6) if initial_biases is None else np.asarray(initial_biases, float)
        self.ba, self.bg = biases[:3].copy(), biases[3:].copy()
        extra_sigma = np.zeros(0) if extra_sigma is None else np.asarray(extra_sigma, float)
        self._extra_tau = np.broadcast_to(np.asarray(np.inf if extra_tau is None else extra_tau,
                                                     dtype=float), extra_sigma.shape).copy()
        self.extra = np.zeros(len(extra_sigma))  # estimate of the extra states
        yaw_sigma = (np.zeros(0) if yaw_response_sigma is None
                     else np.asarray(yaw_response_sigma, float))
        self.yaw_response = np.zeros(len(yaw_sigma))  # estimate of k (module docstring)
        self.extra_start = N_STATES + len(yaw_sigma)  # index of the first extra state
        self.n_states = self.extra_start + len(extra_sigma)
        self.kf = ErrorState(np.diag(np.r_[np.asarray(p0_sigma, float), yaw_sigma,
                                           extra_sigma] ** 2), closed_loop, sparse)
        self.noise = noise
        missing = [c for c in IMU_AXES if c not in imu_columns]
        if missing:
            raise InputError(f"imu: an INS filter needs all six axes; the dataset's IMU lacks "
                             f"{', '.join(missing)} (sensors.imu.axes)")
        self._idx = np.array([imu_columns[c] for c in IMU_AXES])
        self._increments = increments
        self._buf_t = np.empty(buffer_size)
        self._buf = np.empty((buffer_size, 6))
        self._n = 0
        self._prev = np.zeros(12)
        self._sums = np.zeros(7)
        self._rejected: dict[str, int] = {}  # per kind: rejected in a row by ``gated_update``
        self.mean_rate = np.zeros(3)  # compensated body angular rate over the last flush, rad/s
        self.mean_rate_dt = 0.0  # the length of that flush, s
        self.mean_force = np.zeros(3)  # compensated specific force over it, body, m/s^2
        self._mount = None if mounting is None else np.asarray(mounting, dtype=float)
        self._scale_window = float(scale_noise_window)
        self._window = np.zeros(7)  # rate and force times dt, and dt, of the window filling
        self._window_means: np.ndarray | None = None  # rate and force of the last full one
        # equal noise on the three axes: C Q C^T = Q, so G Q G^T does not depend on attitude
        self._gqg = np.zeros((self.n_states, self.n_states))
        self._gqg[:N_STATES, :N_STATES] = noise_psd(
            np.eye(3), noise.accel_noise**2, noise.gyro_noise**2,
            2 * noise.accel_bias_sigma**2 / noise.accel_bias_tau,
            2 * noise.gyro_bias_sigma**2 / noise.gyro_bias_tau)
        extra = np.arange(self.extra_start, self.n_states)
        self._gqg[extra, extra] = 2 * extra_sigma**2 / self._extra_tau

    def set_extra_sigma(self, index: int, sigma: float) -> None:
        """Reset the steady-state 1-sigma of extra state ``index`` (0 = the first after the
        15): its variance, its cross-covariances zeroed, and its driving noise (a state whose
        size is learnt at the first measurement, such as a fix error scaled by the DOP)."""
        k = self.extra_start + index
        self.kf.p[k, :] = 0.0
        self.kf.p[:, k] = 0.0
        self.kf.p[k, k] = sigma * sigma
        self._gqg[k, k] = 2 * sigma * sigma / self._extra_tau[index]

    def add_imu(self, t: float, row: np.ndarray) -> None:
        """Buffer one IMU sample (integrated at the next ``flush``)."""
        if self._n == len(self._buf_t):
            self.flush()
        self._buf_t[self._n] = t
        np.take(row, self._idx, out=self._buf[self._n])
        self._n += 1

    def flush(self) -> None:
        """Integrate the buffered samples and propagate the covariance over them."""
        if self._n == 0:
            return
        self._sums[:] = 0.0
        if self._mount is not None:
            raw = self._buf[:self._n]
            raw[:, 0:3] = raw[:, 0:3] @ self._mount.T
            raw[:, 3:6] = raw[:, 3:6] @ self._mount.T
        if len(self.yaw_response):  # the yaw rate's share of every gyro, k_hat w_z
            raw = self._buf[:self._n]
            raw[:, 0:3] -= np.outer(raw[:, 2], self.yaw_response)
        self.t = _integrate(self._buf_t, self._buf, self._n, self._increments, self.t, self.q,
                            self.v, self.pos, self.ba, self.bg, self._prev, self._sums)
        self._n = 0
        dt = self._sums[6]
        if dt <= 0.0:
            return
        rate = self._sums[3:6] / dt
        c_bn = quat_to_dcm(self.q)
        f_body = c_bn.T @ (self._sums[0:3] / dt)
        n = self.noise
        f_nav = system_matrix(self.pos[0], self.pos[2], self.v, c_bn, f_body,
                              n.accel_bias_tau, n.gyro_bias_tau)
        a = self.extra_start  # the coupled block: the 15 and the yaw-response states
        if a > N_STATES:
            f_nav = np.pad(f_nav, (0, a - N_STATES))
            f_nav[6:9, N_STATES:a] = -c_bn * rate[2]
        # the extra states are uncoupled scalars: the transition is block diagonal
        phi, q_d = discretise(f_nav, self._gqg[:a, :a], dt)
        changes = self._reading_changes(rate, f_body, dt) if self._scale_window > 0 else (
            (rate - self.mean_rate, f_body - self.mean_force) if self.mean_rate_dt > 0
            else None)
        if changes is not None and (n.accel_scale_sigma or n.gyro_scale_sigma
                                    or n.gyro_g_sensitivity):
            d_rate, d_force = changes
            if a > N_STATES:  # the z rate's scale factor is a state
                d_rate[2] = 0.0
            ia, ig = np.arange(N_STATES)[BA], np.arange(N_STATES)[BG]
            q_d[ia, ia] += (n.accel_scale_sigma * d_force) ** 2
            q_d[ig, ig] += ((n.gyro_scale_sigma * d_rate) ** 2
                            + (n.gyro_g_sensitivity * d_force) ** 2)
        self.mean_rate = rate
        self.mean_rate_dt = dt
        self.mean_force = f_body
        if len(self.extra):
            f_extra = -dt / self._extra_tau
            phi_extra = 1.0 + f_extra + 0.5 * f_extra * f_extra
            g_extra = np.diag(self._gqg)[a:]
            q_extra = 0.5 * dt * (phi_extra * phi_extra * g_extra + g_extra)
            self.kf.predict_blocks(phi, q_d, phi_extra, q_extra)
        else:
            self.kf.predict(phi, q_d)
        if len(self.extra):
            self.extra *= np.exp(-dt / self._extra_tau)

    def _reading_changes(self, rate: np.ndarray, f_body: np.ndarray, dt: float
                         ) -> tuple[np.ndarray, np.ndarray] | None:
        """With ``scale_noise_window``: the change of the mean rate and specific force from
        the last full window to the one this flush completes, or None while a window fills."""
        acc = self._window
        acc[0:3] += rate * dt
        acc[3:6] += f_body * dt
        acc[6] += dt
        if acc[6] < self._scale_window - 1e-9:
            return None
        means = acc[0:6] / acc[6]
        acc[:] = 0.0
        previous, self._window_means = self._window_means, means
        if previous is None:
            return None
        return means[0:3] - previous[0:3], means[3:6] - previous[3:6]

    def update(self, dz: np.ndarray, h: np.ndarray, r: np.ndarray) -> np.ndarray:
        """Measurement update with dz = h(nominal) - z; in closed loop the errors are fed back.
        Returns the innovation covariance H P H^T + R."""
        s = self.kf.update(dz, h, r)
        if self.kf.closed_loop:
            self._remove(self.kf.feedback())
        return s

    def passes(self, dz: np.ndarray, h: np.ndarray, r: np.ndarray, probability: float = 0.999,
               max_rejected: int = 5, kind: str = "") -> bool:
        """``gated_update``'s decision without the update, its count of rejections in a row
        kept: whether the measurement passes (so that rows of several gates can be taken in
        one update)."""
        nu = dz - h @ self.kf.x
        rejected = self._rejected.get(kind, 0)
        if (rejected < max_rejected
                and not passes_gate(nu, innovation_covariance(self.kf.p, h, r), probability)):
            self._rejected[kind] = rejected + 1
            return False
        self._rejected[kind] = 0
        return True

    def gated_update(self, dz: np.ndarray, h: np.ndarray, r: np.ndarray,
                     probability: float = 0.999, max_rejected: int = 5,
                     kind: str = "") -> bool:
        """``update`` only when the innovation passes the chi-square gate at ``probability``
        (``gating.passes_gate``); whether it did. After ``max_rejected`` measurements of one
        ``kind`` rejected in a row the next one is taken whatever its innovation: a filter
        whose own error has grown past its covariance (after an outage) would otherwise reject
        every fix for ever. The count is kept per ``kind``, so that an aid accepted at 10 Hz
        does not reset that of the fixes."""
        if not self.passes(dz, h, r, probability, max_rejected, kind):
            return False
        self.update(dz, h, r)
        return True

    def set_closed_loop(self, closed: bool) -> None:
        """Switch loops; closing it removes the open-loop estimate from the nominal solution."""
        self._remove(self.kf.set_closed_loop(closed))

    def _remove(self, dx: np.ndarray) -> None:
        self.q, self.v, self.pos = nav_error.correct(self.q, self.v, self.pos, dx[:9])
        self.ba -= dx[BA]
        self.bg -= dx[BG]
        self.yaw_response -= dx[N_STATES:self.extra_start]
        self.extra -= dx[self.extra_start:]

    def corrected(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The best estimate (nominal minus the open-loop error estimate): q, v, pos and the
        six bias estimates (accelerometer m/s^2, gyro rad/s)."""
        x = self.kf.estimate
        if self.kf.closed_loop or not x.any():
            return self.q, self.v, self.pos, np.concatenate([self.ba, self.bg])
        q, v, pos = nav_error.correct(self.q, self.v, self.pos, x[:9])
        return q, v, pos, np.concatenate([self.ba - x[BA], self.bg - x[BG]])

    def solution_row(self) -> list[float]:
        """lat, lon (deg), alt, vn, ve, vd, roll, pitch, yaw, std_n ... std_vd, std_roll,
        std_pitch, std_yaw and the bias estimates (``SOLUTION_COLUMNS``). The Euler angles'
        1-sigma are those of psi mapped by ``nav_error.euler_error_jacobian``."""
        q, v, pos, biases = self.corrected()
        roll, pitch, yaw = quat_to_euler(q)
        p = self.kf.p
        std = np.sqrt(np.diag(p)[:6])
        jac = nav_error.euler_error_jacobian(quat_to_dcm(q))
        std_att = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", jac, p[6:9, 6:9], jac), 0.0))
        return [np.degrees(pos[0]), np.degrees(pos[1]), pos[2], *v, float(roll), float(pitch),
                float(yaw), *std, *std_att, *biases]


SOLUTION_COLUMNS = ("lat", "lon", "alt", "vn", "ve", "vd", "roll", "pitch", "yaw",
                    "std_n", "std_e", "std_d", "std_vn", "std_ve", "std_vd", "std_roll",
                    "std_pitch", "std_yaw",
                    "accel_bias_x", "accel_bias_y", "accel_bias_z",
                    "gyro_bias_x", "gyro_bias_y", "gyro_bias_z")
