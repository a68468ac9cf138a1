"""Cho & Choi 2006, "Performance Enhancement of Low-Cost Land Navigation System for
Location-Based Service" (ETRI J. 28(2)): two-dimensional dead reckoning (DR) on reduced inertial
units, loosely coupled with GPS.

Estimators
----------
* ``dr2d_drm1_ekf``: DRM1 (eqs. 2-3: two accelerometers and a yaw gyro) with an EKF.
* ``dr2d_drm2_ekf``: DRM2 (eqs. 4-7: forward accelerometer, pitch and yaw gyros), state eq. 8
  with the sensor-error model 2 (eq. 14b), EKF (eqs. 15-17).
* ``dr2d_drm2_spkf``: the same model with the scaled simplex sigma-point filter (eqs. 19-32),
  through ``estimators.toolbox.ukf``.

All three propagate at 10 Hz (the IMU samples of each 0.1 s are averaged; the paper's DR runs
at 10 Hz) and update with each 1 Hz GPS fix: north and east position and horizontal speed
(eq. 18).

Tuning (``config: {tuning: datasheet | paper}``, ``estimators.builtin.cho2006_tuning``):
``paper`` is P0, Q and R of eqs. 33-35 and the paper's eight states; the reproduction names it.
``datasheet`` (the default) takes the noise and the sensor-error priors from the dataset's
datasheet, R from each fix's HDOP and its own reported accuracy, and adds what a consistent
filter on a real car needs: accelerometer-bias states (DRM2's pitch and forward bias are one
unobservable combination, eq. 11, so without the bias state its pitch claims the bias's
accuracy), DRM2's pitch rate corrected for the body's roll in turns, the IMU's lateral velocity
about the rear axle (in the position and, as w_z times it, in the speed's dynamics:
``drm2_transition``), the fix's velocity and correlated error (below), fixes weighted down
beyond a 99.9 % chi-square gate, and, with an odometer, a zero-velocity update at each stop
(the DR running on until the stop is confirmed, since a wheel below its cut-off may still
roll). The SPKF's ``sigma_set: auto | simplex | symmetric`` picks the point set; ``auto`` (the
default) is the paper's simplex set with the paper's tuning and the symmetric set with the
datasheet's: the simplex set's non-zero third moments move unobservable states under eq. 33's
180 deg heading prior (docs/reproduction_cho2006.md), and with the datasheet's R it lost the
heading at the start on 3 of 10 seeds of two drives (urban canyon, garage), where the symmetric
set converged on every seed.

Choices where the paper is silent, ambiguous or wrong (also in docs/reproduction_cho2006.md)
----------------------------------------------------------------------------------------
* Scale-factor states. Eqs. 12-13 define the measured value as (1 + delta) times the true one,
  but the propagation (eqs. 24c-e) compensates by multiplying with (1 - delta). We follow the
  propagation: the state ``d`` is the compensation error, true = (1 - d) measured, which stays
  regular when a sigma point has d near -1 (P0 gives the scale factors a 1-sigma of 1). The
  solution's ``*_scale_factor_*`` columns convert it to SPEC section 7's convention, measured =
  (1 + s) true: s = d / (1 - d).
* Eq. 24c multiplies g sin(theta) by the accelerometer scale factor as well; eqs. 6, 11 and the
  appendix scale only the measured specific force. We use ((1 - d_ax) f_x - g sin theta)
  cos theta, whose derivative in theta is eq. 17c.
* Eq. 24 moves the position with the previous step's speed and heading, eq. 5 with the new
  ones; DRM2 uses their mean (the trapezoidal rule: in a 15 deg/s turn either one alone lags or
  leads the heading by 0.75 deg, which the filter mistakes for a scale-factor error). The EKF's
  transition matrix is the Jacobian of the same function (eqs. 16-17).
* Q (eq. 34) is read as the variance growth per second: the EKF adds Q dt per 0.1 s step; the
  SPKF augments the non-zero terms of Q over one second (eqs. 19-20 with the singular zero rows
  left out) and each 10 Hz step adds its sigma point's noise times dt / 1 s; the points are
  drawn at every GPS epoch and after each second of propagation without one, and the
  covariance (eq. 26) is formed from them before each draw.
* Standstill gyro calibration (the paper: "the bias of a gyro can be calibrated during the
  standing phase"): at every standstill, the filter holds its state and averages the gyros; the
  averages are removed from every later sample and written as ``gyro_bias_*``. The run starts at
  rest; with an odometer stream (used when the dataset has one) every later stop counts too: a
  standstill begins when the odometer reads zero (below 1 mm/s: a stopped wheel; a wheel-speed
  sensor's reading below its cut-off speed, 2 km/h for CAN, counts as stopped, and the state held
  over such a crawl moves the position by under 0.55 m/s times its length) and ends when it reads
  a speed, or the forward specific force moves more than 0.2 m/s^2 from its mean at rest, or a GPS
  fix reports a speed that the fixes' scatter at rest does not explain: more than 0.5 m/s and more
  than 5 times the RMS per axis of the velocities the fixes reported during this stop, tested from
  the third fix at rest on (a stopped receiver's velocity noise alone, 0.5 m/s per axis at the
  paper's fix level, exceeds 0.5 m/s on 61 % of fixes, which ended the calibration within the
  first fixes on 7 of 10 seeds of situation II). A stop's average replaces the calibration when it
  lasted at least 2 s (the bias drifts in-run, so the latest stop is the best estimate; shorter
  stops, whose 2 s average of the white noise would be no better than the calibration held, are
  ignored). Without an odometer only the initial standstill is used (a stop cannot be told from
  driving at a constant speed by the IMU alone). ``standstill_calibration: false`` skips it.
* DRM1's filter state is not printed: [P_N, P_E, V_N, V_E, psi, d_ax, d_ay, d_gz], the level-
  frame velocity of eq. 2 without its "+ g^n" (a typo: the horizontal components of g^n are
  zero) and the scale-factor model 2 of both accelerometers and the yaw gyro. P0 and Q follow
  eqs. 33-34 term by term (5 m/s and 0.1 m/s^2 on each velocity axis). Its specific force is
  resolved at the step's mid heading and its position moves with the mean of the old and new
  velocity (``drm1_transition``). Its speed measurement is linearised (and left out below
  0.5 m/s, where the speed's direction is undefined).
* The fix with the datasheet tuning (``_ChoDr._velocity_update``), when it reports its
  velocity's 1-sigma: its north and east velocity replace eq. 18's speed. DRM1's two
  velocity states are measured directly: the speed left the cross-track velocity to the
  position alone, which the body's roll and the road's bank push and a street canyon's
  reflected fixes barely hold (sumo_city_canyon seed 1 north (error / sigma)^2 7.8 -> 1.3,
  parking_garage seed 3 yaw 7.2 -> 0.74). DRM2's velocity is V along the heading and the
  IMU's lateral velocity across it (eq. 5), so the cross-track row measures the heading
  (V times its error), which the speed along the heading (eq. 18) left to the position's
  slow turn: with it DRM2's yaw claimed 3-4 times its error (SUMO city (error / sigma)^2
  0.04-0.13, seeds 1-3); it waits until the heading is found (before, the speed row of
  ``_Drm2._fix_speed``). The position is the truth plus the fix's correlated north and
  east error, two unit-variance states times each fix's own drive-long 1-sigma
  (``toolbox.datasheet.FixErrorModel.reported_drive_long_sigma``: the reported 1-sigma less
  the smoothed part, at most the receiver budget's correlated part), plus the
  budget's white part and the reported excess (reflections) as white noise. With the
  velocity known to the fix's Doppler a white R, even inflated over ``FIX_CORRELATION_S``,
  averaged the drive-long error away (DRM2 on the SUMO city: a fix 3.1 m north of the truth
  for the whole drive against a north sigma of 1.0 m, seed 3 (error / sigma)^2 9.1; DRM1
  before its states 8.4 over three seeds, worst 22); the budget's 1.7 m per axis against a
  report of 1.0-1.5 m on open sky made it cautious (DRM1 open-road north 0.06).
* Eq. 18 converts GPS latitude and longitude to metres with one Earth radius R_e; we use the
  WGS-84 meridian and transverse radii at the start (``simulator.earth``).
* No Earth rate (the paper ignores it); the standstill calibration removes its vertical part.
* The paper gives no alpha or w0 for the simplex set. w0 = 0 (Julier 2003: the simplex set
  without a central weight), beta = 2 (Gaussian prior, eq. 21), and alpha = 0.3, from the
  heading's initial 1-sigma of 180 deg (eq. 33): with L = 11 (8 states and the 3 non-zero
  noise terms) the farthest simplex point lies 3.16 sigma from the mean on the heading axis,
  so alpha = 1 puts heading points 569 deg away, where the 2 pi-periodic model aliases them
  onto arbitrary headings and their wrapped spread no longer matches P; alpha <= 1 / 3.16
  keeps every initial heading point within +-180 deg, and 0.3 is the round value below that.
  Much smaller alphas shrink the points towards a linearisation, the EKF's weakness. All three
  are ``config`` keys (docs/reproduction_cho2006.md gives the figures for alpha = 1 and 0.1).

Outputs: latitude, longitude, horizontal velocity, yaw (and DRM2's pitch) with their 1-sigma
(``std_vn``, ``std_ve`` from the speed's and heading's covariance for DRM2); height, vertical
velocity and roll (and DRM1's pitch) are NaN, as they are not estimated, and so are the
accelerometer-bias columns under the paper's tuning.

Public classes
--------------
Drm1Ekf, Drm2Ekf, Drm2Spkf.
"""

from __future__ import annotations

import math

import numpy as np

from estimators.base import NAV_COLUMNS, Estimator
from estimators.builtin.cho2006_tuning import (
    LATERAL_HOLD_S,
    MIN_SPEED_SIGMA_M_S,
    PAPER_R,
    ROLL_GRADIENT_SPREAD,
    TUNINGS,
    TURN_HOLD_S,
    Tuning,
    datasheet_tuning,
    paper_tuning,
    stopped_speed_sigma,
)
from estimators.toolbox.datasheet import FixAccuracy, fix_error_model, ground_track_sigma
from estimators.toolbox.gating import (
    FixNoiseMatching,
    chi2_threshold,
    normalised_innovation_squared,
)
from estimators.toolbox.kalman import predict as kf_predict
from estimators.toolbox.kalman import update as kf_update
from estimators.toolbox.ukf import SigmaPointFilter, angle_hooks, psd_sqrt
from simulator.earth import normal_gravity, radii_of_curvature, wrap_angle
from simulator.errors import InputError, Problem

PAPER = "Cho & Choi 2006, ETRI J. 28(2) (seeds/000)"
DR_STEP_S = 0.1  # the DR propagation interval (10 Hz, section III)
DRAW_INTERVAL_S = 1.0  # longest SPKF propagation between sigma-point draws (the GPS period)
MOVE_ACCEL_M_S2 = 0.2  # forward specific-force change that ends the initial standstill
MOVE_SPEED_M_S = 0.5  # GPS speed that ends a standstill (at least; see MOVING_SIGMAS)
MOVING_SIGMAS = 5.0  # a GPS speed this many times the stopped fixes' own speed scatter is motion
MIN_STILL_FIXES = 3  # fixes at rest needed before the GPS speed test applies
MIN_STOP_S = 2.0  # shortest stop whose gyro average replaces the calibration
STOPPED_M_S = 1e-3  # odometer speed read as a stopped wheel (below any encoder's resolution)
STOPPED_SIGMA_M_S = 0.01  # speed 1-sigma of a car whose wheel has read zero for MIN_STOP_S
MIN_SPEED_UPDATE_M_S = 0.5  # DRM1: below this the speed measurement is left out
GATE_PROBABILITY = 0.999  # a fix beyond this chi-square quantile is weighted down to it
ALIGNED_HEADING_VAR = (30.0 * math.pi / 180.0) ** 2  # rad^2: heading found (zero-speed update)
DEG = math.pi / 180.0
SIGMA_SETS = ("simplex", "symmetric")  # the SPKF's point sets (estimators.toolbox.sigma_points)

def drm2_transition(x: np.ndarray, w: np.ndarray | None, u: np.ndarray, dt: float,
                    g: float) -> np.ndarray:
    """DRM2 propagation of states ``x`` (k, 8) over ``dt`` (Cho & Choi eqs. 24a-h, 4-7).

    ``u`` = [f_x (m/s^2), w_y, w_z (rad/s)], bias-compensated means over the step; ``w``
    (k, 8) is the noise of each point over one second, added in proportion dt / 1 s. The
    position moves with the mean of the step's old (eq. 24a-b) and new (eq. 5) velocity
    vectors (the trapezoidal rule). An IMU with the lateral velocity ``lat`` (u[3]) in a turn
    senses f_x = dV/dt - w_z lat along its x axis (the body-frame acceleration dv/dt + w x v),
    so its speed gains (1 - d_gz) w_z lat per second (at 60 deg/s with the IMU 1.7 m ahead
    of the rear axle, 2 m/s^2 that eq. 24c, written for a point without side slip, leaves out).
    """
    pn, pe, v, th, psi, d_ax, d_gy, d_gz = x.T[:8]
    f_x, w_y, w_z = u[:3]
    lat = u[3] if len(u) > 3 else 0.0  # lateral velocity of the IMU (m/s), 0 in the paper
    out = np.empty_like(x)
    f_h = (1.0 - d_ax) * f_x - (x[:, 8] if x.shape[1] > 8 else 0.0)  # eq. 14b (+ bias, eq. 9)
    v_new = v + (f_h - g * np.sin(th)) * np.cos(th) * dt  # eqs. 24c, 6
    if lat:
        v_new = v_new + (1.0 - d_gz) * w_z * lat * dt
    psi_new = psi + (1.0 - d_gz) * w_z * dt  # eq. 24e
    c0, s0, c1, s1 = np.cos(psi), np.sin(psi), np.cos(psi_new), np.sin(psi_new)
    out[:, 0] = pn + 0.5 * (v * c0 - lat * s0 + v_new * c1 - lat * s1) * dt  # eqs. 24a, 5
    out[:, 1] = pe + 0.5 * (v * s0 + lat * c0 + v_new * s1 + lat * c1) * dt  # eqs. 24b, 5
    out[:, 2] = v_new
    out[:, 3] = th + (1.0 - d_gy) * w_y * dt  # eq. 24d
    out[:, 4] = wrap_angle(psi_new)
    out[:, 5:] = x[:, 5:]  # eqs. 24f-h
    if w is not None:
        out += w * (dt / DRAW_INTERVAL_S)
        out[:, 4] = wrap_angle(out[:, 4])
    return out


def drm2_jacobian(x: np.ndarray, u: np.ndarray, dt: float, g: float) -> np.ndarray:
    """Transition matrix of ``drm2_transition`` at ``x`` (8,) (Cho & Choi eqs. 16-17, with the
    trapezoidal position step)."""
    _, _, v, th, psi, d_ax, d_gy, d_gz = x[:8]
    f_x, w_y, w_z = u[:3]
    lat = u[3] if len(u) > 3 else 0.0
    st, ct = math.sin(th), math.cos(th)
    f_h = (1.0 - d_ax) * f_x - (x[8] if x.size > 8 else 0.0)
    v_new = v + (f_h - g * st) * ct * dt
    if lat:
        v_new += (1.0 - d_gz) * w_z * lat * dt
    psi_new = psi + (1.0 - d_gz) * w_z * dt
    phi = np.eye(x.size)
    if lat:
        phi[2, 7] = -w_z * lat * dt  # the IMU's lateral velocity in the turn (drm2_transition)
    # A_3 (eq. 17c) with SF_ax = 1 - d_ax (and the bias), and the scale-factor column
    phi[2, 3] = (g * st * st - f_h * st - g * ct * ct) * dt
    phi[2, 5] = -f_x * ct * dt
    if x.size > 8:
        phi[2, 8] = -ct * dt
    phi[3, 6] = -w_y * dt  # A_4 (eq. 17d)
    phi[4, 7] = -w_z * dt
    # position rows: A_1 and A_2 (eq. 17a-b) at the old and at the new velocity vector
    c0, s0, c1, s1 = math.cos(psi), math.sin(psi), math.cos(psi_new), math.sin(psi_new)
    half = 0.5 * dt
    phi[0, 2] += half * c0
    phi[0, 4] -= half * (v * s0 + lat * c0)
    phi[1, 2] += half * s0
    phi[1, 4] += half * (v * c0 - lat * s0)
    phi[0] += half * (c1 * phi[2] - (v_new * s1 + lat * c1) * phi[4])
    phi[1] += half * (s1 * phi[2] + (v_new * c1 - lat * s1) * phi[4])
    return phi


def drm1_transition(x: np.ndarray, w: np.ndarray | None, u: np.ndarray, dt: float,
                    g: float) -> np.ndarray:
    """DRM1 propagation of states ``x`` (k, 8) (Cho & Choi eqs. 2-3, level frame, no g^n).

    ``u`` = [f_x, f_y (m/s^2), w_z (rad/s)]; the specific force is resolved at the step's
    mid heading (eq. 2 names the new one, C_b^n at k; in a turn either end alone turns the
    velocity by half a step too far or too little), the velocity is updated first and the
    position moves with the mean of the old and the new velocity (eq. 3 names the new one,
    which puts the position a dt / 2 ahead while accelerating).
    """
    pn, pe, vn, ve, psi, d_ax, d_ay, d_gz = x.T[:8]
    f_x, f_y, w_z = u
    fxc, fyc = (1.0 - d_ax) * f_x, (1.0 - d_ay) * f_y
    if x.shape[1] > 8:  # accelerometer biases (the datasheet tuning's states)
        fxc, fyc = fxc - x[:, 8], fyc - x[:, 9]
    turn = (1.0 - d_gz) * w_z * dt
    c, s = np.cos(psi + 0.5 * turn), np.sin(psi + 0.5 * turn)
    out = np.empty_like(x)
    out[:, 2] = vn + (c * fxc - s * fyc) * dt  # eq. 2, C_b^n f^b
    out[:, 3] = ve + (s * fxc + c * fyc) * dt
    out[:, 0] = pn + 0.5 * (vn + out[:, 2]) * dt  # eq. 3, trapezoidal as DRM2's
    out[:, 1] = pe + 0.5 * (ve + out[:, 3]) * dt
    out[:, 4] = wrap_angle(psi + turn)
    out[:, 5:] = x[:, 5:]
    if w is not None:
        out += w * (dt / DRAW_INTERVAL_S)
        out[:, 4] = wrap_angle(out[:, 4])
    return out


def drm1_jacobian(x: np.ndarray, u: np.ndarray, dt: float, g: float) -> np.ndarray:
    """Transition matrix of ``drm1_transition`` at ``x`` (8,)."""
    psi, d_ax, d_ay, d_gz = x[4], x[5], x[6], x[7]
    f_x, f_y, w_z = u
    mid = psi + 0.5 * (1.0 - d_gz) * w_z * dt
    c, s = math.cos(mid), math.sin(mid)
    fxc, fyc = (1.0 - d_ax) * f_x, (1.0 - d_ay) * f_y
    if x.size > 8:
        fxc, fyc = fxc - x[8], fyc - x[9]
    phi = np.eye(x.size)
    # velocity rows: d/d psi, d/d d_ax, d/d d_ay, d/d d_gz (through the mid heading)
    dvn_dpsi, dve_dpsi = (-s * fxc - c * fyc) * dt, (c * fxc - s * fyc) * dt
    phi[2, 4], phi[2, 5], phi[2, 6] = dvn_dpsi, -c * f_x * dt, s * f_y * dt
    phi[3, 4], phi[3, 5], phi[3, 6] = dve_dpsi, -s * f_x * dt, -c * f_y * dt
    phi[2, 7], phi[3, 7] = -0.5 * w_z * dt * dvn_dpsi, -0.5 * w_z * dt * dve_dpsi
    if x.size > 8:  # d/d b_ax, d/d b_ay
        phi[2, 8], phi[2, 9], phi[3, 8], phi[3, 9] = -c * dt, s * dt, -s * dt, -c * dt
    phi[0] += 0.5 * dt * phi[2]  # the position moves with the old and new velocity (eq. 3)
    phi[1] += 0.5 * dt * phi[3]
    phi[0, 2] += 0.5 * dt
    phi[1, 3] += 0.5 * dt
    phi[4, 7] = -w_z * dt
    return phi


class _ChoDr(Estimator):
    """Shared part: IMU averaging to 10 Hz, standstill gyro calibration, GPS measurement
    (eq. 18), local north/east metres, the solution row."""

    needs = ("imu", "gnss_fix")
    uses = ("odometer",)
    paper = PAPER
    output_rate_hz = 10.0
    defaults = {"standstill_calibration": True, "tuning": "datasheet"}
    config_help = {"standstill_calibration": ("", "calibrate the sensor biases at each "
                                                  "standstill (the initial one without odometer)"),
                   "tuning": ("", "datasheet: noise and states from the manifest's datasheet "
                                  "(default); paper: eqs. 33-35 with the paper's eight states")}
    # set by the model
    _model = ""  # "drm1" or "drm2" (cho2006_tuning)
    _velocity_states: tuple[int, ...] = ()  # the states of the velocity (zero at a stop)
    _imu_columns: tuple[str, str, str] = ("", "", "")
    _gyro_channels: tuple[int, ...] = ()  # which of the three inputs are gyros

    def setup(self) -> None:
        if self.config["tuning"] not in TUNINGS:
            raise InputError([Problem("config", None, "", (
                f"config key 'tuning' of estimator {self.name} must be one of "
                f"{', '.join(TUNINGS)}, got {self.config['tuning']!r}"))])
        init = self.initial
        self._lat0, self._lon0, self._h0 = (float(v) for v in init.position)
        rn, re = radii_of_curvature(self._lat0)
        self._rn, self._re = float(rn) + self._h0, float(re) + self._h0
        self._g = float(normal_gravity(self._lat0, self._h0))
        imu = self.columns["imu"]
        self._cols = [imu[c] for c in self._imu_columns]
        self._increment = self.imu_output == "increment"
        fix = self.columns["gnss_fix"]
        self._fix_cols = (fix["fix"], fix["lat"], fix["lon"], fix["vn"], fix["ve"], fix["hdop"])
        self._accuracy = FixAccuracy(fix)  # the receiver's own 1-sigma, NaN without it
        self._fix_model = fix_error_model(self.datasheet)  # its budget (``excess_sigma``)
        self._s0 = self._s1 = self._s2 = 0.0  # the three inputs integrated over the DR step
        self._acc_t = 0.0  # time accumulated in the current DR step
        self._t_imu = init.t
        self._bias = np.zeros(3)  # calibrated gyro biases (zero for accelerometer inputs)
        speed = float(np.hypot(init.velocity[0], init.velocity[1]))
        self._still = bool(self.config["standstill_calibration"]) and speed < MOVE_SPEED_M_S
        self._still_sum = np.zeros(3)
        self._still_t = 0.0
        self._still_fixes = 0  # fixes received during the current standstill
        self._still_speed2 = 0.0  # their summed squared speeds, (m/s)^2
        self._first_stop = self._still  # the initial standstill: calibrated however short
        self._odo_speed = self.columns.get("odometer", {}).get("speed")
        self._tuning = self._make_tuning(0.0)
        self._lateral = 0.0  # the IMU's lateral velocity in the last step (DRM2 on a car)
        self._lateral_var = 0.0  # its error variance, (m/s)^2
        self._datasheet = self.config["tuning"] == "datasheet"
        self._matching = FixNoiseMatching()
        self._stop_sigma = stopped_speed_sigma(self.datasheet)
        self._odo_stop = False  # a stop seen by the odometer, not yet confirmed still
        self._fix_gain = np.ones(2)  # the fix-error states' gain at the last fix, m
        x0 = self._initial_state()
        self._start_filter(np.concatenate([x0, np.zeros(len(self._tuning.p0) - len(x0))]),
                           self._tuning.p0.copy())

    def _make_tuning(self, still_s: float) -> Tuning:
        """The configured tuning (``cho2006_tuning``) after ``still_s`` s of calibration."""
        if self.config["tuning"] == "paper":
            return paper_tuning(self._model)
        return datasheet_tuning(self._model, self.datasheet, still_s)

    def _inputs(self, u: np.ndarray) -> np.ndarray:
        """The model's inputs from the step's mean bias-compensated IMU inputs ``u``."""
        return u

    def _q_step(self, u: np.ndarray) -> np.ndarray:
        """Q (variance growth per second) over a step with inputs ``u``."""
        return self._tuning.q

    _fix_states = 2  # the fix's correlated north and east error, the last states (datasheet)
    _velocity_needs_heading = False  # velocity rows only once the heading is found (DRM2)

    @property
    def _bias_states(self) -> int:
        """Accelerometer-bias states appended to the paper's eight (datasheet tuning)."""
        return len(self._tuning.p0) - 8 - (self._fix_states if self._datasheet else 0)

    # -- to be provided by the model and filter -------------------------------------------
    def _initial_state(self) -> np.ndarray:
        raise NotImplementedError

    def _start_filter(self, x0: np.ndarray, p0: np.ndarray) -> None:
        raise NotImplementedError

    def _propagate(self, u: np.ndarray, dt: float) -> None:
        raise NotImplementedError

    def _update(self, z: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Update with the fix ``z`` [north, east, speed] and its noise ``r``; returns the
        innovation and its covariance (position rows first)."""
        raise NotImplementedError

    def _linear_update(self, index: list[int], z: np.ndarray, r: np.ndarray) -> None:
        """Update with a direct measurement ``z`` of the states ``index`` with noise ``r``."""
        raise NotImplementedError

    def _zero_velocity(self, sigma: float) -> None:
        """The velocity states measured as zero with 1-sigma ``sigma`` (m/s), once the heading
        is found (before, the SPKF's points span half a turn, and the covariance formed from
        them for an update loses its definiteness)."""
        if self._estimate()[1][4, 4] < ALIGNED_HEADING_VAR:
            index = list(self._velocity_states)
            self._linear_update(index, np.zeros(len(index)), np.eye(len(index)) * sigma**2)

    def _estimate(self) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    def _predicted(self) -> tuple[np.ndarray, np.ndarray]:
        """The state and covariance predicted to now (before an update)."""
        return self._estimate()

    # -- messages --------------------------------------------------------------------------
    def on_imu(self, t: float, row: np.ndarray) -> None:
        dt = t - self._t_imu
        if dt <= 0.0:
            return
        self._t_imu = t
        c0, c1, c2 = self._cols
        if self._increment:  # plain floats: this runs for every IMU sample
            self._s0 += row[c0]
            self._s1 += row[c1]
            self._s2 += row[c2]
        else:
            self._s0 += row[c0] * dt
            self._s1 += row[c1] * dt
            self._s2 += row[c2] * dt
        self._acc_t += dt
        if self._acc_t >= DR_STEP_S - 1e-9:
            self._step()

    def _step(self) -> None:
        """One DR step with the mean inputs of the accumulated interval."""
        dt = self._acc_t
        if dt <= 0.0:
            return
        u = np.array([self._s0, self._s1, self._s2]) / dt
        self._s0 = self._s1 = self._s2 = 0.0
        self._acc_t = 0.0
        if self._still:
            f_index = self._accel_index
            if (self._still_t > 0.0
                    and abs(u[f_index] - self._still_sum[f_index] / self._still_t)
                    > MOVE_ACCEL_M_S2):
                self._end_standstill()
            else:
                self._still_sum += u * dt
                self._still_t += dt
                if not self._odo_stop:
                    return
                if self._still_t >= MIN_STOP_S:
                    self._zero_velocity(STOPPED_SIGMA_M_S)  # the wheel has stayed still
                    self._odo_stop = False
                    return
                # a wheel below its cut-off, the stop not yet confirmed: the car may still
                # roll, so the DR goes on (held, its speed stayed where the wheel stopped
                # reading: 0.28 +- 0.02 m/s two seconds into a SUMO stop the car had come
                # down to 0.05 m/s)
        self._propagate(self._inputs(u - self._bias), dt)

    def _end_standstill(self) -> None:
        self._still = self._odo_stop = False
        if self._still_t > 0.0 and (self._first_stop or self._still_t >= MIN_STOP_S):
            mean = self._still_sum / self._still_t
            for i in self._gyro_channels:
                self._bias[i] = mean[i]
            if self._first_stop:  # the residual bias's noise follows the calibration's length
                self._tuning = self._make_tuning(self._still_t)
        self._first_stop = False

    def on_odometer(self, t: float, row: np.ndarray) -> None:
        """A stopped wheel starts a standstill; a speed ends it (module docstring)."""
        stopped = abs(float(row[self._odo_speed])) < STOPPED_M_S
        if stopped and not self._still and self.config["standstill_calibration"]:
            self._step()  # the motion up to the stop
            self._odo_stop = self._datasheet  # (module docstring)
            if self._odo_stop:
                self._zero_velocity(self._stop_sigma)
            self._still = True
            self._lateral = self._lateral_var = 0.0
            self._still_sum[:] = 0.0
            self._still_t = 0.0
            self._still_fixes = 0
            self._still_speed2 = 0.0
        elif not stopped and self._still:
            self._end_standstill()

    def _test_still(self, speed: float) -> None:
        """End the standstill on a fix's ``speed`` (m/s) that its noise at rest does not explain
        (module docstring); otherwise add the fix to that noise's estimate."""
        if self._still_fixes >= MIN_STILL_FIXES:
            scatter = math.sqrt(self._still_speed2 / (2.0 * self._still_fixes))  # per axis
            if speed > max(MOVE_SPEED_M_S, MOVING_SIGMAS * scatter):
                self._end_standstill()
                return
        self._still_fixes += 1
        self._still_speed2 += speed**2

    def on_gnss_fix(self, t: float, row: np.ndarray) -> None:
        fix, lat, lon, vn, ve, hdop = (float(row[i]) for i in self._fix_cols)
        if not (fix > 0 and math.isfinite(lat) and math.isfinite(vn)):
            return
        if self._still:
            self._test_still(math.hypot(vn, ve))
        self._step()  # bring the state to the fix time (no-op on the 10 Hz grid)
        z = np.array([(math.radians(lat) - self._lat0) * self._rn,
                      (math.radians(lon) - self._lon0) * self._re * math.cos(self._lat0),
                      math.hypot(vn, ve)])  # eq. 18
        r = self._tuning.r(hdop, self._matching.scale)
        if not self._datasheet:
            self._update(z, r)
            return
        x, p = self._predicted()
        std_pos, std_vel = self._accuracy.read(row)
        if (np.isfinite(std_vel[:2]).all() and math.isfinite(hdop)
                and not (self._velocity_needs_heading and p[4, 4] >= ALIGNED_HEADING_VAR)):
            self._velocity_update(z[:2], np.array([vn, ve]), std_pos, std_vel[:2], hdop, x, p)
            return
        z[2], speed_sigma = self._fix_speed(vn, ve, x, std_vel)
        reported = bool(np.isfinite(std_pos[:2]).all())
        excess = self._fix_model.excess_sigma(std_pos, hdop, math.nan) if reported else None
        r = self._tuning.reported_r(r, excess, speed_sigma)
        if p[4, 4] >= ALIGNED_HEADING_VAR:
            # the heading not yet found: the fixes weighted as eq. 35 weighs them, which lets the
            # 180 deg prior of eq. 33 converge (the sigma points span half a turn until then)
            r = np.maximum(r, PAPER_R)
        hph, nu = p[:2, :2], z[:2] - x[:2]
        d2 = normalised_innovation_squared(nu, hph + r[:2, :2])
        gate = chi2_threshold(2, GATE_PROBABILITY)
        if d2 > gate and p[4, 4] < ALIGNED_HEADING_VAR:
            r[:2, :2] *= d2 / gate  # an outlier (a reflected signal): weighted down to the gate
        self._update(z, r)
        if not reported:  # the fix's scatter learnt from its innovations instead
            self._matching.add(nu, hph, self._tuning.white_position_var(hdop))

    def _velocity_update(self, pos: np.ndarray, vel: np.ndarray, std_pos: np.ndarray,
                         std_vel: np.ndarray, hdop: float, x: np.ndarray, p: np.ndarray
                         ) -> None:
        """A fix that reports its velocity's 1-sigma ``std_vel`` (datasheet tuning): its north
        and east position ``pos`` and velocity ``vel`` (``_fix_rows``). The position is the
        truth plus the fix's correlated error, e = g u: two unit-variance Gauss-Markov states
        u whose gain g is this fix's drive-long 1-sigma from its own report
        (``FixErrorModel.reported_drive_long_sigma``; a receiver's report is 2-3 m for the
        first half minute, while its Hatch filters converge, then 1.2-1.5 m on open sky, so
        states sized once at the first fix kept the budget's), plus the
        budget's white part and the reported excess (reflections) as white noise; the
        velocity's noise is the reported one (and the IMU's lateral velocity error across the
        heading, ``_velocity_noise``). Weighted as eq. 35 weighs the fixes until the heading
        is found, and down to the 99.9 % gate beyond it, as ``on_gnss_fix``."""
        self._fix_gain = self._fix_model.reported_drive_long_sigma(std_pos, hdop, math.nan)[:2]
        white = self._fix_model.white_sigma(hdop, math.nan)[:2] ** 2
        excess = self._fix_model.excess_sigma(std_pos, hdop, math.nan)[:2] ** 2
        r = np.zeros((4, 4))
        r[[0, 1], [0, 1]] = white + excess
        aligned = p[4, 4] < ALIGNED_HEADING_VAR
        if not aligned:
            r[[0, 1], [0, 1]] = np.maximum(r[[0, 1], [0, 1]], PAPER_R.diagonal()[:2])
        r[2:, 2:] = self._velocity_noise(x, np.maximum(std_vel, MIN_SPEED_SIGMA_M_S))
        z = np.concatenate([pos, vel])
        zhat, h = self._fix_rows(x[None, :])
        nu = (z - zhat[0])[:2]
        d2 = normalised_innovation_squared(nu, (h[:2] @ p @ h[:2].T) + r[:2, :2])
        gate = chi2_threshold(2, GATE_PROBABILITY)
        if d2 > gate and aligned:
            r[:2, :2] *= d2 / gate  # an outlier (a reflected signal): weighted down to the gate
        self._nonlinear_update(z, r)

    def _fix_rows(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """h(x) = [P_N + g_N u_N, P_E + g_E u_E, v_N, v_E] of a fix (``_velocity_update``) for
        states (k, n) with the fix's correlated error g u (the last two states u, the gain g
        ``_fix_gain``), and its Jacobian at the first row."""
        raise NotImplementedError

    def _velocity_noise(self, x: np.ndarray, std_vel: np.ndarray) -> np.ndarray:
        """2 x 2 noise of a fix's north and east velocity rows with 1-sigma ``std_vel``."""
        return np.diag(std_vel**2)

    def _nonlinear_update(self, z: np.ndarray, r: np.ndarray) -> None:
        """Update with ``z`` of ``_fix_rows`` and its noise ``r``."""
        raise NotImplementedError

    def _fix_speed(self, vn: float, ve: float, x: np.ndarray, std_vel: np.ndarray
                   ) -> tuple[float, float]:
        """The speed row of a fix with the datasheet tuning and its 1-sigma from the fix's
        reported velocity 1-sigma ``std_vel`` (NED; NaN when not reported): eq. 18's norm of
        the fix's velocity, the 1-sigma along it (``ground_track_sigma``; DRM2 overrides it)."""
        return math.hypot(vn, ve), ground_track_sigma(vn, ve, std_vel[0], std_vel[1])[0]

    # -- output ----------------------------------------------------------------------------
    @property
    def _accel_index(self) -> int:
        return self._imu_columns.index("accel_x")

    def _row(self, x: np.ndarray, p: np.ndarray, vn: float, ve: float, pitch: float,
             p_vel: np.ndarray) -> list[float]:
        """The navigation columns (NaN where not estimated), then std_n, std_e, std_vn and
        std_ve (``p_vel``: the 2 x 2 covariance of vn, ve)."""
        lat = self._lat0 + x[0] / self._rn
        lon = self._lon0 + x[1] / (self._re * math.cos(self._lat0))
        nan = math.nan
        return [math.degrees(lat), math.degrees(lon), nan, vn, ve, nan, nan, pitch,
                float(wrap_angle(x[4])), math.sqrt(p[0, 0]), math.sqrt(p[1, 1]),
                math.sqrt(max(p_vel[0, 0], 0.0)), math.sqrt(max(p_vel[1, 1], 0.0))]

    def _accel_bias(self, x: np.ndarray, axis: int) -> float:
        """The estimated accelerometer bias of the ``axis``-th bias state (NaN without one)."""
        return float(x[8 + axis]) if self._bias_states > axis else math.nan


def _sf(d: float) -> float:
    """SPEC section 7 scale-factor error s (measured = (1 + s) true) of the compensation
    error d (true = (1 - d) measured)."""
    return d / (1.0 - d)


class _Drm2(_ChoDr):
    """DRM2 model (eqs. 4-8, 14b)."""

    _model = "drm2"
    _velocity_states = (2,)
    _imu_columns = ("accel_x", "gyro_y", "gyro_z")
    _gyro_channels = (1, 2)
    output_columns = (*NAV_COLUMNS, "std_n", "std_e", "std_vn", "std_ve", "std_pitch", "std_yaw",
                      "accel_scale_factor_x", "gyro_scale_factor_y", "gyro_scale_factor_z",
                      "gyro_bias_y", "gyro_bias_z", "accel_bias_x", "speed_h")

    def _initial_state(self) -> np.ndarray:
        init = self.initial
        yaw = float(init.attitude[2])
        v = float(init.velocity[0] * math.cos(yaw) + init.velocity[1] * math.sin(yaw))
        return np.array([0.0, 0.0, v, float(init.attitude[1]), yaw, 0.0, 0.0, 0.0])

    def _inputs(self, u: np.ndarray) -> np.ndarray:
        """The pitch and heading rates of a body rolled by phi in a turn (datasheet tuning on a
        car; ZYX Euler rates on a level road): theta_dot = w_y cos(phi) - w_z sin(phi),
        psi_dot = w_y sin(phi) + w_z cos(phi), where eqs. 24d-e integrate w_y and w_z alone.
        The roll is phi = -k V w_z (``cho2006_tuning``), so the pitch rate is w_y + k V w_z^2
        to first order, and w_z alone loses w_z phi^2 / 2 of the heading rate (w_y = psi_dot
        sin(phi) in the turn): 0.16 deg over ``urban_canyon``'s 90 deg turns at 0.67 g (3.4
        deg of roll), which the heading measured by the fix's cross-track velocity under an
        ideal gyro's process noise kept (seeds 1-2 yaw (error / sigma)^2 34 and 33). An error
        in phi moves this rate by theta_dot times it, to first order: nil in a level turn.
        The pitch's 1 / cos(theta) is left out: taken at the pitch state, whose error is the
        forward accelerometer's bias over g (1-2 deg), it put tan(theta) times that error into
        the heading rate on the garage's 7 deg ramps (unseen garage seed 2 yaw 0.47 -> 7.0),
        a coupling the propagation's Jacobian does not carry."""
        k, arm = self._tuning.roll_gradient, self._tuning.rear_axle_m
        if not (k or arm):
            return u
        roll = -k * self._estimate()[0][2] * u[2]
        out = np.append(u, arm * u[2])  # the IMU's lateral velocity (``_measure``)
        out[1] += k * self._estimate()[0][2] * u[2] ** 2
        out[2] = u[1] * math.sin(roll) + u[2] * math.cos(roll)
        self._lateral = float(out[3])
        self._lateral_var = self._tuning.lateral_variance(self._lateral)
        return out

    def _q_step(self, u: np.ndarray) -> np.ndarray:
        """Q with the pitch-rate error of the unknown part of the roll (w_z sigma_roll, held
        over a turn: ``cho2006_tuning.TURN_HOLD_S``)."""
        sigma = self._tuning.roll_sigma
        if not sigma:
            return self._tuning.q
        q = self._tuning.q.copy()
        q[3, 3] += (u[2] * sigma) ** 2 * TURN_HOLD_S
        q[0, 0] += self._lateral_var * LATERAL_HOLD_S  # the lateral velocity's error
        q[1, 1] += self._lateral_var * LATERAL_HOLD_S
        return q

    def _transition(self, x: np.ndarray, w: np.ndarray | None, u: np.ndarray,
                    dt: float) -> np.ndarray:
        return drm2_transition(x, w, u, dt, self._g)

    def _jacobian(self, x: np.ndarray, u: np.ndarray, dt: float) -> np.ndarray:
        return drm2_jacobian(x, u, dt, self._g)

    def _measure(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """h(x) = [P_N, P_E, V] for states (k, n) and its (constant) Jacobian (eq. 16); with
        the datasheet tuning the speed row is the fix's velocity along the heading
        (``_fix_speed``), which keeps V's sign (the norm would let the EKF settle on -V)."""
        return x[:, :3], np.eye(3, x.shape[1])

    def _fix_speed(self, vn: float, ve: float, x: np.ndarray, std_vel: np.ndarray
                   ) -> tuple[float, float]:
        """The speed row of a fix with the datasheet tuning: the fix's velocity along the
        estimated heading, V + lat sin(dpsi) with the heading's error dpsi, unbiased with the
        noise of one horizontal axis of the fix's velocity (its reported 1-sigma ``std_vel``
        projected on the heading; NaN when not reported). Eq. 18's norm of it is rectified:
        at a stop, with 1-sigma s per axis, its mean is s sqrt(pi / 2) (Rayleigh), 0.04 m/s at
        s = 0.03, which held the SUMO city's stopped cars at 0.05 m/s under a sigma of
        0.006 (east velocity (error / sigma)^2 50 over a 23 s stop); in a turn it exceeds V by
        lat^2 / (2 V) of the IMU's lateral velocity lat."""
        c, s = math.cos(float(x[4])), math.sin(float(x[4]))
        return vn * c + ve * s, math.hypot(c * std_vel[0], s * std_vel[1])

    _velocity_needs_heading = True  # its velocity rows turn with the heading

    def _fix_rows(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The fix's position with its correlated error, and its velocity: the speed V along
        the heading and the IMU's lateral velocity ``lat`` across it (eq. 5); the cross-track
        row observes the heading directly, which eq. 18's speed leaves to the position."""
        k, (g_n, g_e) = x.shape[1] - self._fix_states, self._fix_gain
        v, psi, lat = x[:, 2], x[:, 4], self._lateral
        c, s = np.cos(psi), np.sin(psi)
        zs = np.column_stack([x[:, 0] + g_n * x[:, k], x[:, 1] + g_e * x[:, k + 1],
                              v * c - lat * s, v * s + lat * c])
        h = np.zeros((4, x.shape[1]))
        h[0, 0] = h[1, 1] = 1.0
        h[0, k], h[1, k + 1] = g_n, g_e
        h[2, 2], h[3, 2] = c[0], s[0]
        h[2, 4], h[3, 4] = -v[0] * s[0] - lat * c[0], v[0] * c[0] - lat * s[0]
        return zs, h

    def _velocity_noise(self, x: np.ndarray, std_vel: np.ndarray) -> np.ndarray:
        """The fix's velocity noise and the error of the IMU's lateral velocity across the
        heading (``Tuning.lateral_variance``)."""
        across = np.array([-math.sin(float(x[4])), math.cos(float(x[4]))])
        return np.diag(std_vel**2) + self._lateral_var * np.outer(across, across)

    def solution(self, t: float) -> list[float]:
        x, p = self._estimate()
        v, th, psi, lat = x[2], x[3], x[4], self._lateral
        c, s = math.cos(psi), math.sin(psi)
        jac = np.array([[c, -v * s - lat * c], [s, v * c - lat * s]])  # (vn, ve) / (V, psi)
        across = np.array([-s, c])
        p_vel = jac @ p[np.ix_([2, 4], [2, 4])] @ jac.T + self._lateral_var * np.outer(across,
                                                                                      across)
        return [*self._row(x, p, v * c - lat * s, v * s + lat * c, th, p_vel),
                math.sqrt(p[3, 3]), math.sqrt(p[4, 4]), _sf(x[5]), _sf(x[6]), _sf(x[7]),
                self._bias[1], self._bias[2], self._accel_bias(x, 0), v]


class _Drm1(_ChoDr):
    """DRM1 model (eqs. 2-3)."""

    _model = "drm1"
    _velocity_states = (2, 3)
    _imu_columns = ("accel_x", "accel_y", "gyro_z")
    _gyro_channels = (2,)
    output_columns = (*NAV_COLUMNS, "std_n", "std_e", "std_vn", "std_ve", "std_yaw",
                      "accel_scale_factor_x", "accel_scale_factor_y", "gyro_scale_factor_z",
                      "gyro_bias_z", "accel_bias_x", "accel_bias_y")

    def _initial_state(self) -> np.ndarray:
        init = self.initial
        return np.array([0.0, 0.0, float(init.velocity[0]), float(init.velocity[1]),
                         float(init.attitude[2]), 0.0, 0.0, 0.0])

    def _inputs(self, u: np.ndarray) -> np.ndarray:
        """The lateral specific force of a body rolled out of a turn (datasheet tuning on a
        car): the y accelerometer tilts with the roll phi = -k a_y (``cho2006_tuning``) and
        senses gravity's share g k a_y beside the lateral acceleration a_y = V w_z, which the
        level frame of eq. 2 would take for acceleration (8 % of every turn's at 5 deg/g)."""
        k = self._tuning.roll_gradient
        if not k:
            return u
        x = self._estimate()[0]
        return np.array([u[0], u[1] - self._g * k * math.hypot(x[2], x[3]) * u[2], u[2]])

    def _q_step(self, u: np.ndarray) -> np.ndarray:
        """Q with the lateral acceleration error of the roll gradient's spread (``cho2006_
        tuning.ROLL_GRADIENT_SPREAD``, held over a turn: ``TURN_HOLD_S``)."""
        if not self._tuning.roll_gradient:
            return self._tuning.q
        x = self._estimate()[0]
        error = self._g * ROLL_GRADIENT_SPREAD * math.hypot(x[2], x[3]) * u[2]
        q = self._tuning.q.copy()
        q[2, 2] += error**2 * TURN_HOLD_S
        q[3, 3] += error**2 * TURN_HOLD_S
        return q

    def _transition(self, x: np.ndarray, w: np.ndarray | None, u: np.ndarray,
                    dt: float) -> np.ndarray:
        return drm1_transition(x, w, u, dt, self._g)

    def _jacobian(self, x: np.ndarray, u: np.ndarray, dt: float) -> np.ndarray:
        return drm1_jacobian(x, u, dt, self._g)

    def _measure(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """h(x) = [P_N, P_E, |V|] for states (k, 8) and its Jacobian at the first row."""
        speed = np.hypot(x[:, 2], x[:, 3])
        h = np.zeros((3, x.shape[1]))
        h[0, 0] = h[1, 1] = 1.0
        if speed[0] > 0.0:
            h[2, 2:4] = x[0, 2:4] / speed[0]
        return np.column_stack([x[:, 0], x[:, 1], speed]), h

    def _fix_rows(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The fix's position with its correlated error, and DRM1's two velocity states."""
        k, (g_n, g_e) = x.shape[1] - self._fix_states, self._fix_gain
        h = np.eye(4, x.shape[1])
        h[0, k], h[1, k + 1] = g_n, g_e
        return np.column_stack([x[:, 0] + g_n * x[:, k], x[:, 1] + g_e * x[:, k + 1], x[:, 2],
                                x[:, 3]]), h

    def solution(self, t: float) -> list[float]:
        x, p = self._estimate()
        return [*self._row(x, p, x[2], x[3], math.nan, p[2:4, 2:4]), math.sqrt(p[4, 4]),
                _sf(x[5]), _sf(x[6]), _sf(x[7]), self._bias[2], self._accel_bias(x, 0),
                self._accel_bias(x, 1)]


class _Ekf(_ChoDr):
    """The EKF (eqs. 15-17): total-state propagation, the Jacobian's covariance, and the
    Joseph-form update of ``estimators.toolbox.kalman``."""

    def _start_filter(self, x0: np.ndarray, p0: np.ndarray) -> None:
        self._x, self._p = x0, p0

    def _propagate(self, u: np.ndarray, dt: float) -> None:
        phi = self._jacobian(self._x, u, dt)
        self._x = self._transition(self._x[None, :], None, u, dt)[0]
        _, self._p = kf_predict(self._x, self._p, phi, self._q_step(u) * dt)

    def _update(self, z: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        zhat, h = self._measure(self._x[None, :])
        rows = [0, 1, 2] if h[2].any() else [0, 1]
        nu = z[rows] - zhat[0, rows]
        self._x, self._p, s = kf_update(self._x, self._p, nu, h[rows], r[np.ix_(rows, rows)])
        self._x[4] = wrap_angle(self._x[4])
        return nu, s

    def _linear_update(self, index: list[int], z: np.ndarray, r: np.ndarray) -> None:
        h = np.eye(len(self._x))[index]
        self._x, self._p, _ = kf_update(self._x, self._p, z - self._x[index], h, r)

    def _nonlinear_update(self, z: np.ndarray, r: np.ndarray) -> None:
        zhat, h = self._fix_rows(self._x[None, :])
        self._x, self._p, _ = kf_update(self._x, self._p, z - zhat[0], h, r)
        self._x[4] = wrap_angle(self._x[4])

    def _estimate(self) -> tuple[np.ndarray, np.ndarray]:
        return self._x, self._p


class Drm1Ekf(_Drm1, _Ekf):
    """2-D DR/GPS EKF on the DRM1 unit (two accelerometers + yaw gyro)."""

    name = "dr2d_drm1_ekf"
    paper = f"{PAPER}: DRM1 (eqs. 2-3) with an EKF, GPS position and speed (eq. 18)"

    def _measure(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        zhat, h = super()._measure(x)
        if np.hypot(x[0, 2], x[0, 3]) < MIN_SPEED_UPDATE_M_S:
            h[2] = 0.0  # no speed row: the EKF leaves it out
        return zhat, h


class Drm2Ekf(_Drm2, _Ekf):
    """2-D DR/GPS EKF on the DRM2 unit (forward accelerometer + pitch and yaw gyros)."""

    name = "dr2d_drm2_ekf"
    paper = f"{PAPER}: DRM2 (eqs. 4-8, 14b) with the EKF of eqs. 15-17"


class Drm2Spkf(_Drm2):
    """2-D DR/GPS scaled simplex sigma-point filter on the DRM2 unit (eqs. 19-32)."""

    name = "dr2d_drm2_spkf"
    paper = f"{PAPER}: DRM2 with the scaled simplex sigma-point filter (eqs. 19-32)"
    defaults = {"standstill_calibration": True, "tuning": "datasheet", "alpha": 0.3,
                "beta": 2.0, "w0": 0.0, "sigma_set": "auto"}
    config_help = {
        **_ChoDr.config_help,
        "alpha": ("", "spread of the simplex sigma points, in [1e-4, 1] (eq. 21)"),
        "beta": ("", "prior-distribution weight of the central point, 2 for a Gaussian (eq. 21)"),
        "w0": ("", "weight of the central sigma point (Julier 2003)"),
        "sigma_set": ("", "auto (simplex with paper tuning, symmetric with datasheet), simplex "
                          "or symmetric"),
    }

    def _start_filter(self, x0: np.ndarray, p0: np.ndarray) -> None:
        checks = (("alpha", 1e-4 <= self.config["alpha"] <= 1.0, "must be in [1e-4, 1] (eq. 21)"),
                  ("w0", 0.0 <= self.config["w0"] < 1.0, "must be in [0, 1)"),
                  ("beta", self.config["beta"] >= 0.0, "must not be negative"),
                  ("sigma_set", self.config["sigma_set"] in ("auto", *SIGMA_SETS),
                   f"must be auto or one of {', '.join(SIGMA_SETS)}"))
        problems = [f"config key {key!r} of estimator {self.name} {rule}, got "
                    f"{self.config[key]!r}" for key, ok, rule in checks if not ok]
        if problems:
            raise InputError([Problem("config", None, "", p) for p in problems])
        plus, minus = angle_hooks([4])
        points = self.config["sigma_set"]
        if points == "auto":  # the paper's set with the paper's tuning (module docstring)
            points = "simplex" if self.config["tuning"] == "paper" else "symmetric"
        self._ukf = SigmaPointFilter(x0, p0, points=points,
                                     alpha=self.config["alpha"],
                                     beta=self.config["beta"], w0=self.config["w0"],
                                     boxplus=plus, boxminus=minus, augment=True)
        self._since_draw = 0.0

    def _propagate(self, u: np.ndarray, dt: float) -> None:
        if self._since_draw >= DRAW_INTERVAL_S - 1e-9:
            self._ukf.covariance(redraw=True)  # eq. 26; the next propagation draws afresh
            self._since_draw = 0.0
        self._ukf.propagate(self._transition, u, dt,  # eqs. 22-25
                            q=self._q_step(u) * DRAW_INTERVAL_S)
        self._since_draw += dt

    def _update(self, z: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if self._ukf.sigma is not None:
            self._ukf.covariance()  # eq. 26
        self._since_draw = 0.0
        out = self._ukf.update(lambda xs: self._measure(xs)[0], z, r)  # eqs. 27-32
        if self._datasheet:
            self._repair_covariance()
        return out

    def _repair_covariance(self) -> None:
        """Eq. 29 subtracts K P_yy K^T from P; while the heading points still span half a
        turn (eq. 33's 180 deg) the points' P_yy and P_xy are not a joint covariance with P,
        and P can lose its definiteness (a negative heading variance 3 s after moving off,
        seen on an outage drive). The nearest positive-definite matrix replaces it
        (``ukf.psd_sqrt``, Higham 1988); the paper's tuning keeps eq. 29 as printed."""
        if np.linalg.eigvalsh(self._ukf.p)[0] < 0.0:
            root = psd_sqrt(self._ukf.p)
            self._ukf.p = root @ root.T

    def _linear_update(self, index: list[int], z: np.ndarray, r: np.ndarray) -> None:
        """A measurement linear in the states: the Kalman update itself (the points would
        only approximate it); the next propagation draws fresh points."""
        if self._ukf.sigma is not None:
            self._ukf.covariance(redraw=True)
        self._since_draw = 0.0
        h = np.eye(len(self._ukf.x))[index]
        self._ukf.x, self._ukf.p, _ = kf_update(self._ukf.x, self._ukf.p,
                                                z - self._ukf.x[index], h, r)

    def _nonlinear_update(self, z: np.ndarray, r: np.ndarray) -> None:
        if self._ukf.sigma is not None:
            self._ukf.covariance()  # eq. 26
        self._since_draw = 0.0
        self._ukf.update(lambda xs: self._fix_rows(xs)[0], z, r)  # eqs. 27-32
        self._repair_covariance()

    def _estimate(self) -> tuple[np.ndarray, np.ndarray]:
        return self._ukf.x, self._ukf.p

    def _predicted(self) -> tuple[np.ndarray, np.ndarray]:
        if self._ukf.sigma is not None:
            self._ukf.covariance()  # eq. 26, from the propagated points (kept for the update)
        return self._ukf.x, self._ukf.p
