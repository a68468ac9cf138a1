"""The dead-reckoning filters of Park et al., "MEMS 3D DR/GPS Integrated System for Land Vehicle
Application Robust to GPS Outages", IEEE Access 7, 2019 (``seeds/004_...``).

* ``dr2d_odo_ekf`` (``Dr2dOdoEkf``): the conventional 2-D DR/GPS of section II-B. The position
  integrates the odometer speed along the heading (eqs. 15-16); a 5-state EKF on
  [dp_N, dp_E, dv, dpsi, deps_z] (eq. 17) is updated with the GPS north/east position and
  ground speed (eqs. 18-19).
* ``dr3d_ekf`` (``Dr3dEkf``): the proposed 3-D DR/GPS of section III. The attitude quaternion
  integrates the three gyros (eq. 3), the position integrates the odometer speed, scaled by
  the estimated odometer scale factor, along the body x axis resolved in NED (eqs. 20-21); a
  10-state EKF on [dp_N, dp_E, dp_D, ds, psi_N, psi_E, psi_D, deps_x, deps_y, deps_z]
  (eq. 23) with the error model of eqs. 28-32 is updated in two steps (section III-C): step 1
  at 20 Hz with roll and pitch from the accelerometers (g-slave, eqs. 34-35) and the
  barometric height (eqs. 36-37); step 2 at each GPS epoch with the GPS position, ground speed
  and course (eqs. 38-41). The three noise adaptation rules of section III-D are on with
  ``adaptive`` (default).

Both are closed-loop error-state EKFs on ``estimators.toolbox.kalman.ErrorState``; the nominal
solution is propagated at every IMU sample's arrival in lean scalar form, the covariance and the
20 Hz measurements once per ``step`` (0.05 s, the paper's 20 Hz) with the gyro increments of
the step summed (coning over 50 ms is negligible at a car's rates).

Choices where the paper is silent or inconsistent (also in docs/reproduction_park2019.md):

* Sign of the attitude error. Park writes C_b^n(estimate) = (I - [dpsi x]) C_b^n (eq. 24); the
  toolbox convention (``estimators.toolbox.nav_error``) is C_b^n(estimate) = (I + [psi x])
  C_b^n, so psi = -dpsi and the signs of the psi columns of eqs. 30, 37 and 41 flip: eq. 28
  becomes dp' = C_b^n [u, 0, 0]^T ds - (v^n x) psi, the gyro-bias block of eq. 30 stays
  -C_b^n (the bias state is estimate minus truth, so the corrected rate is too low by it).
* Odometer scale factor. Eq. 20 writes v = s u (u the odometer reading) with a multiplicative
  error s (1 + ds), while eqs. 26, 30 and 41 use an additive ds (dv = ds u). The additive form
  of eqs. 26/30/41 is implemented (ds = s(estimate) - s). The solution's
  ``odometer_scale_factor`` column is SPEC section 7's ratio of measured to true speed, 1 / s.
* Tilt measurement Jacobian. Eq. 37 is the level, small-roll approximation of the exact
  linearisation d(roll, pitch)/d psi = rows 1-2 of M(roll, pitch) C_n^b (M the Euler-rate
  matrix); the exact rows are used (identical on level ground, better on a 15 % ramp). The
  course row of eq. 41 is likewise the exact yaw Jacobian (``toolbox.aiding.heading``: the
  course is the heading of the body x axis, the car does not slide). The accelerometers give
  roll = atan2(-f_y, -f_z), pitch = atan2(f_x, sqrt(f_y^2 + f_z^2)) in the FRD frame (eqs.
  34-35 written for FRD) from the mean specific force of the step.
* GPS speed is the horizontal ground speed, so its prediction is s u cos(pitch), not s u
  (eq. 39); the Jacobian has u cos(pitch) on ds and -s u sin(pitch) on the pitch error. Course
  is used only while moving forwards faster than ``course_min_speed`` (it is undefined at
  standstill and points backwards while reversing).
* Barometer: the ``altitude`` column of the ``baro`` stream (its standard-atmosphere pressure
  altitude; a stream without it is not used). Its bias is removed "simply" with GPS height
  (section III-C): the offset h_baro - h_GPS is averaged (first-order filter,
  ``baro_offset_time_constant``) over good 3-D fixes (``gps_height_max_vdop``) and frozen
  without them; the barometer is used from the first such fix on. GPS height enters step 2
  only on such fixes.
* Adaptation rules (section III-D), thresholds as printed: (1) | ||f|| - g | > 0.059 m/s^2
  inflates the tilt noise from ``tilt_sigma`` to ``tilt_sigma_inflated``; (2) a speed below
  5 m/s inflates the GPS speed and course noise to their ``*_inflated`` values; (3) a barometric
  innovation over 2.5 m inflates the barometer noise to ``baro_sigma_inflated``. The inflated
  values are not printed: five times (speed, course) and twenty times (barometer) the nominal;
  for the tilt 30 deg, thirty times: a manoeuvre flagged by rule 1 lasts seconds, and its tilt
  error (9 deg at 1.5 m/s^2) must not pull the attitude through 20 updates a second (with
  10 deg it still did, by 9 deg). The "g" of rule 1 is the specific-force norm measured at
  standstill (odometer reading zero), normal gravity before the first standstill: the residual
  accelerometer bias Park assumes (7 mg, section III-B) exceeds the 0.059 m/s^2 threshold
  itself, so against normal gravity the rule flags standstill and passes moderate
  accelerations. With ``adaptive: false`` the nominal values are used always.
* Gauss-Markov time constants (eq. 29) are not printed: tau_1 = 3600 s for the scale factor
  (tyre wear and pressure change over hours), tau_2 = 600 s for the gyro biases; process noise
  from the SMI130 gyro noise density (Table 1) and small steady-state sigmas.
* The 2-D filter's velocity-error state dv (eq. 17) is an additive odometer speed error with a
  Gauss-Markov model (sigma ``speed_error_sigma``, tau ``speed_error_time_constant``), applied
  while the wheels turn (a wheel-speed sensor reads exactly zero at standstill). Its heading
  integrates the z gyro with the vertical Earth and transport rate of a level frame (a 2-D DR
  has no tilt: eq. 3 reduces to a rotation about the body z axis). It estimates no height:
  ``alt``, ``vd``, roll and pitch are NaN.

* ``tuning`` (both filters; default ``datasheet``). ``paper``: Park's states and the values
  above, which the reproduction (``simulator.reproduce.park2019``) asks for explicitly so its
  figures stay put. ``datasheet``: the gyro noise, in-run and turn-on bias of the datasheet's
  IMU (``toolbox.datasheet``), and the states Park's model lacks, without which it claimed a
  confidence it did not have (0.12 deg of roll against 5 deg of error on the quickstart): the
  fix's drive-long error (north, east and, in 3-D, down; ``toolbox.datasheet.
  fix_error_model``: unit states whose gain at each fix is the drive-long part of the fix's
  reported accuracy, per unit DOP the smallest report so far less the budget's smoothed
  noise, capped at the budget's correlated part, ``FixSplit``; sized by the budget alone,
  2.2 m of range error, the position was too cautious on open sky; its white remainder as
  the GPS noise);
  in 3-D the accelerometers' roll and pitch error (their turn-on bias over g, the g-slave's
  dominant error) and the barometer offset's error (set at the first good fix, a random walk
  of the datasheet's weather drift; its white noise the sensor's); in 2-D the z gyro's
  scale-factor error as bias process noise (s times the change of rate). In 3-D also the car
  under the IMU (the datasheet's ``vehicle`` block, ``toolbox.installation``): the truth's
  attitude is the body's, which yaws by the side slip and pitches on its springs relative to
  the path the odometer counts, and Park's model (velocity along body x) turned both into
  confident errors: the GPS course pulled the yaw to the path's heading (11 deg apart in an
  8 m turn), the barometer's height rate the pitch to the path's grade (the squat, 0.3 deg
  per m/s^2; open road pitch (error/sigma)^2 6.5, SUMO city 14, yaw 14). Here the IMU's
  velocity is ``car_body_velocity`` (the rear axle along x, w_z L sideways, the squat k a
  below x with k a random-constant state, prior ``NonholonomicNoise.pitch_compliance``), in
  the position, the course (the tyres' slip and the fix's velocity noise its variance; the
  fix's velocity noise the speed's) and the g-slave (the specific force loses d v/dt + w x v
  of that velocity, the odometer's acceleration over 0.5 s, the IMU's sideways L dw_z/dt from
  the gyro over one step; the tilt is taken from the specific force and the attitude averaged
  over the odometer acceleration's 0.5 s, the window that acceleration is the mean of: the
  step's own specific force against it lagged the acceleration by 0.25 s, which the jerk of
  SUMO's junctions turned into a roll and pitch error of one sign, and through the turns the
  accelerometers' tilt states took it for their bias, sumo_city_canyon seed 1 roll (error /
  sigma)^2 7.0 -> 0.58); what it leaves out (the tyres'
  slip, the suspension's travel: ``NonholonomicNoise``) is velocity noise correlated over
  1 s; the g-slave's variance adds the odometer acceleration's noise (two speeds of the
  datasheet's noise 0.5 s apart) and the tyres' slip turned by the yaw rate; the gyro scale
  factor is bias process noise (a helix turns it into yaw); each fix row passes a chi-square
  gate (0.999) against reflected canyon heights. Both filters read the fix's own accuracy
  (``std_*`` of ``gnss_fix``, ``toolbox.datasheet.FixAccuracy``): its velocity 1-sigma sets the
  speed's and the course's noise, and its position 1-sigma beyond its drive-long and smoothed
  parts (the reflected signals of a street canyon) is carried by unit NLOS states (north, east
  and, in 3-D, down; ``FixSplit``): on the SUMO canyon's seeds 1-2 dr3d_ekf's height went from
  11 / 27 to 1.0 / 2.3 and dr2d_odo_ekf's north from 10 / 2.5 to 0.7 / 1.1.

Public names
------------
Dr2dOdoEkf, Dr3dEkf, car_body_velocity.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from estimators.base import NAV_COLUMNS, Estimator
from estimators.toolbox.aiding import barometric_height, gnss_position, heading
from estimators.toolbox.constraints import NonholonomicNoise
from estimators.toolbox.datasheet import (
    NLOS_TIME_CONSTANT_S,
    FixAccuracy,
    FixSplit,
    fix_error_model,
    ground_track_sigma,
    imu_error_model,
    odometer_speed_sigma,
)
from estimators.toolbox.gating import rows_passing, threshold_variance
from estimators.toolbox.gauss_markov import gauss_markov_continuous
from estimators.toolbox.installation import Installation
from estimators.toolbox.kalman import ErrorState
from estimators.toolbox.nav_error import euler_error_jacobian
from estimators.toolbox.strapdown import attitude_step, frame_rates, radii
from simulator.earth import OMEGA_E_RAD_S, dcm_to_euler, normal_gravity, quat_to_dcm, wrap_angle
from simulator.errors import InputError

PAPER = ("Park et al. 2019, MEMS 3D DR/GPS Integrated System for Land Vehicle Application "
         "Robust to GPS Outages, IEEE Access 7")
DEG = math.pi / 180.0
ACCEL_NORM_THRESHOLD_M_S2 = 0.059  # Park section III-D rule 1 (0.006 g)
LOW_SPEED_THRESHOLD_M_S = 5.0  # Park section III-D rule 2 ("approximately 4 ~ 6 m/s")
BARO_INNOVATION_THRESHOLD_M = 2.5  # Park section III-D rule 3 (80 % of one floor)
_LEVEL = np.array([1.0, 0.0, 0.0, 0.0])  # identity quaternion
TUNINGS = ("datasheet", "paper")
G0 = 9.80665  # m/s^2
# dr3d_ekf's states added by the datasheet tuning after Park's ten: the accelerometers' roll and
# pitch error, the barometer's offset error, the fix's correlated north, east, down error,
# the body's pitch on its springs per forward acceleration (the velocity's angle below the body
# x axis per m/s^2, a random constant), and the reflected fixes' north, east, down error in
# units of the fix's reported excess (``toolbox.datasheet``)
TILT, BARO, FIX, SQUAT, NLOS = slice(10, 12), 12, slice(13, 16), 16, slice(17, 20)
N_DR3D_SHEET = 20
GATE_PROBABILITY = 0.999  # the fixes' chi-square gate with the datasheet tuning
SLIP_TIME_S = 1.0  # correlation time of the tyres' unmodelled slip velocity (a turn's length)
METRES_PER_PASCAL = 0.0833  # height per pascal near sea level (standard atmosphere), m/Pa
ACCEL_WINDOW_S = 0.5  # odometer speeds differenced for the along-track acceleration, s
BARO_RATE_TIME_S = 600.0  # the weather's constant pressure rate as a random walk over 10 min


@njit(cache=True)
def _dr3d_navigate(q: np.ndarray, c_old: np.ndarray, pos: np.ndarray, v_prev: np.ndarray,
                   dtheta: np.ndarray, v_body: np.ndarray, u: float, dt: float,
                   f: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                           np.ndarray]:
    """The 3-D DR navigation processor over one step (eqs. 3, 20-21) and the error model's
    time-varying blocks (eqs. 28-32, toolbox psi sign) written into ``f`` (10, 10).

    q, c_old: attitude at the step start; pos: latitude, longitude (rad), height (m); v_prev:
    NED velocity of the previous step (for the transport rate); dtheta: bias-corrected gyro
    increment (rad); v_body: the IMU's body-frame velocity (m/s), [s u, 0, 0] in Park's model;
    u: odometer reading (m/s). Returns q, C_b^n, position, NED velocity at the step end and the
    step's mean C_b^n (the body axes the velocity was resolved on)."""
    lat, lon, h = pos[0], pos[1], pos[2]
    w_ie, w_en = frame_rates(lat, h, v_prev)
    w_in = w_ie + w_en
    q_new, c_new = attitude_step(q, w_in * dt, dtheta)
    c_mid = 0.5 * (c_old + c_new)
    x_axis = c_mid[:, 0]
    v = v_body[0] * x_axis + v_body[1] * c_mid[:, 1] + v_body[2] * c_mid[:, 2]
    rn, re = radii(lat)
    lat_new = lat + v[0] * dt / (rn + h)
    lon_new = lon + v[1] * dt / ((re + h) * np.cos(lat_new))
    h_new = h - v[2] * dt
    # eq. 28: dp' = C_b^n [u, 0, 0]^T ds - (v^n x) psi
    f[0:3, 3] = u * x_axis
    f[0, 4], f[0, 5], f[0, 6] = 0.0, v[2], -v[1]
    f[1, 4], f[1, 5], f[1, 6] = -v[2], 0.0, v[0]
    f[2, 4], f[2, 5], f[2, 6] = v[1], -v[0], 0.0
    # eqs. 30-32: psi' = -w_in x psi - dw_in + C_b^n dw_ib, dw_ib = -(gyro bias error)
    f[4, 4], f[4, 5], f[4, 6] = 0.0, w_in[2], -w_in[1]
    f[5, 4], f[5, 5], f[5, 6] = -w_in[2], 0.0, w_in[0]
    f[6, 4], f[6, 5], f[6, 6] = w_in[1], -w_in[0], 0.0
    # F_31: dw_in from latitude (north error) and height (down error; h = -p_D)
    d_lat = 1.0 / (rn + h)
    f[4, 0] = d_lat * OMEGA_E_RAD_S * np.sin(lat)
    f[5, 0] = 0.0
    f[6, 0] = d_lat * (OMEGA_E_RAD_S * np.cos(lat) + v[1] / ((re + h) * np.cos(lat) ** 2))
    f[4:7, 2] = -w_en * d_lat
    f[4:7, 7:10] = -c_new
    return q_new, c_new, np.array([lat_new, lon_new, h_new]), v, c_mid


def car_body_velocity(speed: float, yaw_rate: float, rear_lever: float, odometer_lever: float,
                      squat: float, accel: float) -> np.ndarray:
    """The IMU's body-frame (FRD) velocity on a car, m/s: the rear axle rolls along the body's
    x axis (the kinematic bicycle model, Rajamani 2012, eq. 2.29), at the speed vr that gives
    the odometer's point (``odometer_lever`` ahead of the rear axle: the centre of gravity,
    ``toolbox.installation``) the ``speed``: vr^2 + (w_z d)^2 = speed^2; the IMU,
    ``rear_lever`` L ahead of the rear axle, moves sideways at w_z L; the body pitches nose up
    on its springs by ``squat`` k (rad per m/s^2) times the forward acceleration a, so the
    path lies k a below its x axis: v = [vr, w_z L, vr k a]."""
    vr = math.copysign(math.sqrt(max(speed * speed - (yaw_rate * odometer_lever) ** 2, 0.0)),
                       speed)
    return np.array([vr, yaw_rate * rear_lever, vr * squat * accel])


# config key -> (SI unit, meaning), of both filters (`landnav estimators dr3d_ekf`)
CONFIG_HELP = {
    "tuning": ("", "datasheet: noise and states from the manifest's datasheet (default); "
                   "paper: Park et al.'s model and values, for the reproduction"),
    "adaptive": ("", "the noise adaptation rules of section III-D"),
    "baro": ("", "barometric height in step 1"),
    "step": ("s", "propagation period (step 1 of section III-C)"),
    "gyro_noise_density": ("rad/s/sqrt(Hz)", "gyro white noise (Table 1)"),
    "gyro_bias_sigma": ("rad/s", "gyro bias, Gauss-Markov steady state"),
    "gyro_bias_time_constant": ("s", "its time constant (tau_2 of eq. 29)"),
    "gyro_bias_initial": ("rad/s", "initial gyro-bias uncertainty (Table 1 zero-point offset)"),
    "scale_sigma": ("1", "odometer scale factor, Gauss-Markov steady state"),
    "scale_time_constant": ("s", "its time constant (tau_1 of eq. 29)"),
    "scale_initial": ("1", "initial scale-factor uncertainty"),
    "position_initial": ("m", "initial position uncertainty per axis"),
    "attitude_initial": ("rad", "initial roll and pitch uncertainty"),
    "heading_initial": ("rad", "initial yaw uncertainty"),
    "tilt_sigma": ("rad", "accelerometer roll and pitch noise"),
    "tilt_sigma_inflated": ("rad", "the same while accelerating (adaptive)"),
    "baro_sigma": ("m", "barometric height noise"),
    "baro_sigma_inflated": ("m", "the same when the adaptive rules inflate it"),
    "baro_offset_time_constant": ("s", "time constant of the barometer height offset"),
    "gps_horizontal_sigma": ("m", "GPS horizontal position noise"),
    "gps_vertical_sigma": ("m", "GPS height noise"),
    "gps_height_max_vdop": ("", "largest VDOP at which the GPS height is used"),
    "gps_speed_sigma": ("m/s", "GPS speed noise"),
    "gps_speed_sigma_inflated": ("m/s", "the same when the adaptive rules inflate it"),
    "gps_course_sigma": ("rad", "GPS course noise"),
    "gps_course_sigma_inflated": ("rad", "the same when the adaptive rules inflate it"),
    "course_min_speed": ("m/s", "speed above which the GPS course is used"),
    "speed_error_sigma": ("m/s", "odometer speed error, Gauss-Markov steady state"),
    "speed_error_time_constant": ("s", "its time constant"),
}


class _FixColumns:
    """Column positions of the ``gnss_fix`` stream used by both filters."""

    def __init__(self, columns: dict[str, int]):
        self.lat, self.lon, self.alt = columns["lat"], columns["lon"], columns["alt"]
        self.speed, self.course = columns["speed"], columns["course"]
        self.fix, self.hdop, self.vdop = columns["fix"], columns["hdop"], columns["vdop"]
        self.vn, self.ve = columns["vn"], columns["ve"]
        self.accuracy = FixAccuracy(columns)

    def reported(self, row: np.ndarray) -> tuple[np.ndarray, float, float]:
        """A fix row's own position 1-sigma (NED, m), ground-speed 1-sigma (m/s) and course
        1-sigma times its speed (m/s, across the track); NaN where it reports none."""
        std_pos, std_vel = self.accuracy.read(row)
        vn, ve = float(row[self.vn]), float(row[self.ve])
        speed_sigma, course_sigma = ground_track_sigma(vn, ve, std_vel[0], std_vel[1])
        return std_pos, speed_sigma, course_sigma * math.hypot(vn, ve)


class _StepAccumulator:
    """IMU samples summed over one filter step: gyro increments, mean specific force. Rate
    samples are integrated by the trapezoidal rule between consecutive samples (the first
    sample holds over the interval before it); increments are summed."""

    def __init__(self, columns: dict[str, int], increments: bool, t0: float):
        # column of each axis, None for an axis the unit lacks (read as zero)
        self.cols = [columns.get(a) for a in ("gyro_x", "gyro_y", "gyro_z", "accel_x",
                                              "accel_y", "accel_z")]
        self.has_accel = None not in self.cols[3:]
        self.increments = increments
        self.t = t0
        self.prev: list[float] | None = None
        self.reset()

    def reset(self) -> None:
        self.sums = [0.0] * len(self.cols)  # rad, then m/s (body FRD)
        self.dt = 0.0

    @property
    def dtheta(self) -> list[float]:
        """Summed angle increment of the step, rad."""
        return self.sums[:3]

    @property
    def dvel(self) -> list[float]:
        """Summed velocity increment (specific force integrated) of the step, m/s."""
        return self.sums[3:6]

    def add(self, t: float, row: np.ndarray) -> None:
        dt = t - self.t
        if dt <= 0.0:
            return
        self.t = t
        now = [0.0 if c is None else float(row[c]) for c in self.cols]
        sums = self.sums
        if self.increments:
            for k, x in enumerate(now):
                sums[k] += x
        else:
            prev = now if self.prev is None else self.prev
            for k, x in enumerate(now):
                sums[k] += 0.5 * (x + prev[k]) * dt
            self.prev = now
        self.dt += dt


class _OdometerDeadReckoning(Estimator):
    """What both Park dead-reckoning filters take alike: IMU samples summed into steps of
    ``config["step"]`` s (a step runs ``_step`` when complete), the latest odometer speed, and
    the fix columns."""

    def _take_inputs(self) -> None:
        self._u = 0.0  # latest odometer reading, m/s
        self._u_history: list[tuple[float, float]] = []
        self._accel = 0.0  # along-track acceleration from the odometer, m/s^2
        self._imu = _StepAccumulator(self.columns["imu"], self.imu_output == "increment",
                                     self.initial.t)
        self._odo = self.columns["odometer"]["speed"]
        self._fix = _FixColumns(self.columns["gnss_fix"])

    def _step(self) -> None:
        raise NotImplementedError

    def on_imu(self, t: float, row: np.ndarray) -> None:
        acc = self._imu
        acc.add(t, row)
        if acc.dt >= self.config["step"] - 1e-9:
            self._step()

    def on_odometer(self, t: float, row: np.ndarray) -> None:
        self._u = float(row[self._odo])
        # the along-track acceleration over the last ACCEL_WINDOW_S (its mean, the speed's
        # difference across the window)
        self._u_history.append((t, self._u))
        while len(self._u_history) > 2 and t - self._u_history[1][0] >= ACCEL_WINDOW_S:
            self._u_history.pop(0)
        t0, u0 = self._u_history[0]
        self._accel = (self._u - u0) / (t - t0) if t - t0 > 0 else 0.0

    def _take_fix(self, row: np.ndarray) -> bool:
        """Whether a fix epoch has a position; if so the dead reckoning is first brought up to
        it (the part step since the last complete one)."""
        fx = self._fix
        if not (row[fx.fix] > 0 and math.isfinite(row[fx.lat])):
            return False
        if self._imu.dt > 0.0:
            self._step()
        return True


class Dr3dEkf(_OdometerDeadReckoning):
    """Park et al. 2019 proposed 10-state 3-D DR/GPS EKF (eqs. 20-41, section III-D)."""

    name = "dr3d_ekf"
    needs = ("imu", "odometer", "gnss_fix")
    uses = ("baro",)
    paper = PAPER + ", section III (eqs. 20-41)"
    output_columns = (*NAV_COLUMNS, "std_n", "std_e", "std_d", "std_roll", "std_pitch",
                      "std_yaw", "odometer_scale_factor", "gyro_bias_x", "gyro_bias_y",
                      "gyro_bias_z")
    defaults = {
        "tuning": "datasheet",  # "paper": Park's 10 states and the values below only
        "adaptive": True,  # section III-D noise adaptation rules
        "baro": True,  # barometric height in step 1
        "step": 0.05,  # s, step-1 period (20 Hz, section III-C)
        "gyro_noise_density": 0.02 * DEG,  # rad/s/sqrt(Hz), SMI130 (Table 1)
        "gyro_bias_sigma": 0.01 * DEG,  # rad/s, Gauss-Markov steady state
        "gyro_bias_time_constant": 600.0,  # s, tau_2 of eq. 29
        "gyro_bias_initial": 1.0 * DEG,  # rad/s, P0 (Table 1 zero-point offset)
        "scale_sigma": 0.01,  # Gauss-Markov steady state of s (1 = true distance per reading)
        "scale_time_constant": 3600.0,  # s, tau_1 of eq. 29
        "scale_initial": 0.05,  # P0 of the scale factor
        "position_initial": 3.0,  # m, P0 per axis
        "attitude_initial": 1.0 * DEG,  # rad, P0 roll and pitch
        "heading_initial": 5.0 * DEG,  # rad, P0 yaw
        "tilt_sigma": 1.0 * DEG,  # rad, accelerometer roll/pitch noise
        "tilt_sigma_inflated": 30.0 * DEG,
        "baro_sigma": 0.5,  # m
        "baro_sigma_inflated": 10.0,  # m
        "baro_offset_time_constant": 60.0,  # s
        "gps_horizontal_sigma": 3.0,  # m
        "gps_vertical_sigma": 5.0,  # m
        "gps_height_max_vdop": 3.0,
        "gps_speed_sigma": 0.1,  # m/s
        "gps_speed_sigma_inflated": 0.5,
        "gps_course_sigma": 1.0 * DEG,  # rad
        "gps_course_sigma_inflated": 5.0 * DEG,
        "course_min_speed": 1.0,  # m/s
    }
    config_help = {k: CONFIG_HELP[k] for k in defaults}

    def setup(self) -> None:
        c = self.config
        init = self.initial
        self._pos = np.array(init.position, dtype=float)  # latitude, longitude (rad), height
        self._q = init.quaternion
        self._cbn = quat_to_dcm(self._q)
        self._v_ned = np.zeros(3)
        self._s = 1.0  # metres per odometer metre (eq. 20)
        self._bias = np.zeros(3)  # gyro bias estimate, rad/s
        self._zero3 = np.zeros(3)
        self._take_inputs()
        self._baro_col = self.columns.get("baro", {}).get("altitude")
        self._use_baro = bool(c["baro"]) and self._baro_col is not None
        self._baro_h = math.nan
        self._baro_new = False
        self._baro_offset: float | None = None
        self._t_offset = init.t
        p0 = np.diag(np.r_[[c["position_initial"] ** 2] * 3, c["scale_initial"] ** 2,
                           [c["attitude_initial"] ** 2] * 2, c["heading_initial"] ** 2,
                           [c["gyro_bias_initial"] ** 2] * 3])
        # rule 1's reference norm: normal gravity until the first standstill, then the mean
        # specific-force norm measured at standstill (it absorbs the accelerometer bias)
        self._g = float(np.squeeze(normal_gravity(self._pos[0], self._pos[2])))
        self._still_norm_sum = 0.0
        self._still_steps = 0
        if c["tuning"] not in TUNINGS:
            raise InputError(f"dr3d_ekf: config tuning must be one of {', '.join(TUNINGS)}, "
                             f"got {c['tuning']!r}")
        self._sheet = c["tuning"] == "datasheet"
        n = N_DR3D_SHEET if self._sheet else 10
        self._tilt_bias = np.zeros(2)  # accelerometer tilt error estimate (roll, pitch), rad
        self._baro_bias = 0.0  # barometer offset error estimate, m
        self._fix_error = np.zeros(3)  # the fix's drive-long error estimate, units of its gain
        self._nlos = np.zeros(3)  # the reflected fixes' error estimate, units of the excess
        if self._sheet:
            p0 = self._datasheet_states(p0)
        self._kf = ErrorState(p0)
        self._eye = np.eye(n)
        self._f = np.zeros((n, n))  # eq. 30; the time-varying blocks are filled each step
        # eq. 29: first-order Gauss-Markov scale factor and gyro biases
        f_gm, q_gm = gauss_markov_continuous(
            [c["scale_time_constant"], *[c["gyro_bias_time_constant"]] * 3],
            [c["scale_sigma"], *[c["gyro_bias_sigma"]] * 3])
        self._f[3, 3] = f_gm[0]
        self._f[7:10, 7:10] = np.diag(f_gm[1:])
        self._q_c = np.zeros(n)
        self._q_c[3] = q_gm[0]
        self._q_c[4:7] = c["gyro_noise_density"] ** 2
        self._q_c[7:10] = q_gm[1:]
        self._v_body = np.zeros(3)  # the IMU's body-frame velocity over the last step, m/s
        self._squat = 0.0  # the body's pitch per forward acceleration estimate, rad per m/s^2
        self._yaw_accel = 0.0  # the yaw rate's change over the last ACCEL_WINDOW_S, rad/s^2
        if self._sheet:
            self._q_c[4:7] = self._imu_model.gyro_noise**2
            self._q_c[TILT] = 2 * self._imu_model.accel_bias_sigma**2 / (
                self._imu_model.accel_bias_tau * G0**2)
            self._f[TILT, TILT] = -1.0 / self._imu_model.accel_bias_tau
            self._q_c[BARO] = self._baro_rate_sigma**2 * BARO_RATE_TIME_S
            self._f[FIX, FIX] = -1.0 / self._fix_model.correlated_tau
            self._q_c[FIX] = 2.0 / self._fix_model.correlated_tau
            self._f[NLOS, NLOS] = -np.eye(3) / NLOS_TIME_CONSTANT_S
            self._q_c[NLOS] = 2.0 / NLOS_TIME_CONSTANT_S

    def _datasheet_states(self, p0: np.ndarray) -> np.ndarray:
        """``tuning: datasheet`` (class docstring): the gyro noise, in-run and turn-on bias of
        the datasheet's IMU (``toolbox.datasheet``) and P0 with the six added states."""
        imu = self._imu_model = imu_error_model(self.datasheet)
        self._fix_model = fix_error_model(self.datasheet)
        self._fix_split = FixSplit(self._fix_model)
        baro = self.datasheet.get("baro") or {}
        self._baro_rate_sigma = float(baro.get("weather_drift") or 0.0) * METRES_PER_PASCAL
        self._baro_noise = math.hypot(float(baro.get("noise") or 0.0),
                                      float(baro.get("resolution") or 0.0) / math.sqrt(12.0)
                                      ) * METRES_PER_PASCAL
        p = np.zeros((N_DR3D_SHEET, N_DR3D_SHEET))
        p[:10, :10] = p0
        p[7:10, 7:10] = np.eye(3) * imu.gyro_bias_initial**2
        p[TILT, TILT] = np.eye(2) * (imu.accel_bias_initial / G0) ** 2
        p[FIX, FIX] = np.eye(3)  # unit states (their gain is the fix's drive-long part)
        # the car's body (class docstring): the rear axle behind the IMU, the odometer's point
        # (the centre of gravity) ahead of the rear axle, the tyres' slip and the body's pitch
        site = Installation.from_datasheet(self.datasheet)
        rear = site.rear_axle if site.rear_axle is not None else np.zeros(3)
        odo = site.odometer if site.odometer is not None else rear
        self._rear_lever = float(-rear[0])
        self._odo_lever = float(odo[0] - rear[0])
        self._car = NonholonomicNoise(site.wheelbase or 2.7)
        # the odometer's acceleration: two speeds ACCEL_WINDOW_S apart
        self._accel_sigma = (math.sqrt(2.0) * odometer_speed_sigma(self.datasheet, 1.0)
                             / ACCEL_WINDOW_S)
        # the g-slave's steps over the odometer acceleration's window: (dt, specific force
        # less the car's acceleration but the along-track one, nominal roll, pitch)
        self._window: list[tuple[float, np.ndarray, float, float]] = []
        self._rate_prev = np.zeros(3)
        p[SQUAT, SQUAT] = self._car.pitch_compliance**2 if site.rear_axle is not None else 0.0
        p[NLOS, NLOS] = np.eye(3)  # unit states (their gain is the fix's excess)
        return p

    # -- messages ---------------------------------------------------------------------------
    def on_baro(self, t: float, row: np.ndarray) -> None:
        if self._baro_col is not None:
            self._baro_h = float(row[self._baro_col])
            self._baro_new = True

    def on_gnss_fix(self, t: float, row: np.ndarray) -> None:
        if not self._take_fix(row):
            return
        fx = self._fix
        c = self.config
        lat, lon, alt = math.radians(row[fx.lat]), math.radians(row[fx.lon]), float(row[fx.alt])
        good_height = row[fx.fix] >= 2 and row[fx.vdop] <= c["gps_height_max_vdop"]
        dops = float(row[fx.hdop]), float(row[fx.vdop])
        std_pos, speed_sigma, cross_sigma = fx.reported(row)
        if self._sheet:  # the report's drive-long part, reflected excess and white noise
            correlated, gain, white = self._fix_split.split(std_pos, *dops)
        if good_height and math.isfinite(self._baro_h):
            if self._sheet and self._baro_offset is None:  # the offset's error is a state
                self._baro_offset = self._baro_h - alt
                self._reset_states(slice(BARO, BARO + 1), np.sqrt(
                    correlated[2:] ** 2 + self._fix_model.white_sigma(*dops)[2:] ** 2))
            elif not self._sheet:
                self._track_baro_offset(t, self._baro_h - alt)
        n = 3 if good_height else 2
        n_x = len(self._eye)
        dz, h_pos = gnss_position(self._q, self._pos, np.array([lat, lon, alt]), n_states=n_x)
        var = [c["gps_horizontal_sigma"] ** 2] * 2 + [c["gps_vertical_sigma"] ** 2] * (n - 2)
        if self._sheet:  # the fix is the truth plus its drive-long error, plus white noise
            dz += correlated * self._fix_error
            h_pos[:, FIX] = np.diag(correlated)
            var = list(white[:n])
            dz += gain * self._nlos
            h_pos[:, NLOS] = np.diag(gain)
        keep = np.arange(n)
        if self._sheet:  # a reflected fix's metres the receiver does not announce: each row
            # behind a chi-square gate (one degree of freedom, GATE_PROBABILITY)
            h_n = h_pos[:n]
            s_diag = np.einsum("ij,jk,ik->i", h_n, self._kf.p, h_n) + np.array(var)
            keep = keep[rows_passing(dz[:n], s_diag, GATE_PROBABILITY)]
            var = [var[k] for k in keep]
        rows = [h_pos[keep]]
        dzs = [dz[keep]]
        speed = self._s * self._u
        slow = c["adaptive"] and speed < LOW_SPEED_THRESHOLD_M_S
        jac = euler_error_jacobian(self._cbn)
        pitch = -math.asin(self._cbn[2, 0])
        if math.isfinite(row[fx.speed]):
            h = np.zeros(n_x)
            h[3] = abs(self._u) * math.cos(pitch)
            h[4:7] = -abs(speed) * math.sin(pitch) * jac[1]
            rows.append(h[None])
            dzs.append([abs(speed) * math.cos(pitch) - row[fx.speed]])
            if self._sheet:  # the fix's own speed accuracy, else the datasheet's at its DOPs
                var.append((speed_sigma if math.isfinite(speed_sigma)
                            else self._fix_model.velocity_sigma(*dops)[0]) ** 2)
            else:
                var.append(c["gps_speed_sigma_inflated" if slow else "gps_speed_sigma"] ** 2)
        if speed > c["course_min_speed"] and math.isfinite(row[fx.course]):
            # Park: the course is the heading of the body x axis (no side slip; eq. 41's last
            # row); datasheet: of the IMU's velocity on the car, w_z L to the side
            course = float(row[fx.course])
            h = np.zeros((1, n_x))
            if self._sheet:
                v_b = self._v_body
                course -= math.atan2(v_b[1], v_b[0])
                h[0, 9] = -self._rear_lever * v_b[0] / (v_b[0] ** 2 + v_b[1] ** 2)
                lateral = self._car.sigma(v_b[0], v_b[1] / self._rear_lever
                                          if self._rear_lever else 0.0, 0.0)[0]
                across = (cross_sigma if math.isfinite(cross_sigma)
                          else self._fix_model.velocity_sigma(*dops)[0])
                var.append((across**2 + lateral**2) / (v_b[0] ** 2 + v_b[1] ** 2))
            else:
                var.append(c["gps_course_sigma_inflated" if slow else "gps_course_sigma"] ** 2)
            dz_c, h_c = heading(self._q, course, n_states=9)
            h[0, 4:7] = h_c[0, 6:9]  # the INS layout's psi columns to this filter's
            rows.append(h)
            dzs.append(dz_c)
        self._kf.update(np.concatenate(dzs), np.vstack(rows), np.diag(var))
        self._feedback()

    # -- filter -----------------------------------------------------------------------------
    def _reset_states(self, states: slice, sigma: np.ndarray) -> None:
        """Size added states when their size is first known (the barometer offset's at the
        first good fix): variance sigma^2, no cross-covariance."""
        p = self._kf.p
        p[states, :] = 0.0
        p[:, states] = 0.0
        idx = np.arange(len(p))[states]
        p[idx, idx] = np.asarray(sigma) ** 2

    def _track_baro_offset(self, t: float, offset: float) -> None:
        if self._baro_offset is None:
            self._baro_offset = offset
        else:
            a = min(1.0, (t - self._t_offset) / self.config["baro_offset_time_constant"])
            self._baro_offset += a * (offset - self._baro_offset)
        self._t_offset = t

    def _step(self) -> None:
        """Navigation processor (eqs. 3, 20-21) and covariance over one step, then step 1."""
        acc = self._imu
        dt = acc.dt
        dtheta = np.array(acc.dtheta) - self._bias * dt
        f_b = np.array(acc.dvel) / dt
        acc.reset()
        rate = dtheta / dt
        self._step_dt = dt
        if self._sheet:  # the yaw rate's change over the step (the gyro's noise is small)
            self._yaw_accel = (rate[2] - self._rate_prev[2]) / dt
            v_body = self._body_velocity(rate)
        else:
            v_body = np.array([self._s * self._u, 0.0, 0.0])
        self._v_body = v_body
        self._q, self._cbn, self._pos, self._v_ned, c_mid = _dr3d_navigate(
            self._q, self._cbn, self._pos, self._v_ned, dtheta, v_body, self._u, dt, self._f)
        q_d = np.diag(self._q_c * dt)
        if self._sheet:
            self._nlos *= math.exp(-dt / NLOS_TIME_CONSTANT_S)  # its Gauss-Markov mean
            self._body_error_model(c_mid, rate, q_d, dt)
            # the gyro scale-factor error moves the bias by s d(rate) (toolbox.datasheet)
            q_d[7:10, 7:10] += np.diag((self._imu_model.gyro_scale_sigma
                                        * (rate - self._rate_prev)) ** 2)
            self._rate_prev = rate
        self._kf.predict(self._eye + self._f * dt, q_d)
        if self._imu.has_accel:
            self._step_one(f_b, rate)

    def _body_velocity(self, rate: np.ndarray) -> np.ndarray:
        """The IMU's body-frame velocity on the car (``car_body_velocity``)."""
        if self._u == 0.0:
            return np.zeros(3)
        return car_body_velocity(self._s * self._u, float(rate[2]), self._rear_lever,
                                 self._odo_lever, self._squat, self._s * self._accel)

    def _body_error_model(self, c_mid: np.ndarray, rate: np.ndarray, q_d: np.ndarray,
                          dt: float) -> None:
        """The error model's columns of the car's body (``_body_velocity``): the sideways
        velocity's z-gyro bias (the bias state is estimate minus truth, so w_z L is too low by
        L times it) and the squat state; the tyres' slip and the suspension's travel, which the
        model leaves out, as velocity noise (``NonholonomicNoise`` without its pitch term, now
        a state) correlated over SLIP_TIME_S, white-equivalent on the position (a first-order
        Gauss-Markov process's PSD at zero frequency, 2 sigma^2 T: Brown & Hwang, 4th ed.,
        section 2.9)."""
        v_body = self._v_body
        f = self._f
        f[0:3, 9] = -self._rear_lever * c_mid[:, 1] if self._u != 0.0 else 0.0
        f[0:3, SQUAT] = c_mid[:, 2] * v_body[0] * self._s * self._accel
        if self._u != 0.0:
            lateral, vertical = self._car.sigma(v_body[0], float(rate[2]), 0.0)
            q_d[0, 0] += 2 * lateral**2 * SLIP_TIME_S * dt
            q_d[1, 1] += 2 * lateral**2 * SLIP_TIME_S * dt
            q_d[2, 2] += 2 * vertical**2 * SLIP_TIME_S * dt

    def _step_one(self, f_b: np.ndarray, rate: np.ndarray) -> None:
        """Step 1 of section III-C: g-slave roll and pitch (eqs. 34-37) and barometer. With
        ``tuning: datasheet`` the specific force first loses the car's own acceleration (the
        odometer's along-track acceleration over the last 0.5 s forwards, the turn's
        centripetal s u w_z sideways, -s u w_y down: the car moves along its x axis) and the
        tilt carries the accelerometers' bias as two states."""
        c = self.config
        cbn = self._cbn
        n_x = len(self._eye)
        roll, pitch = math.atan2(cbn[2, 1], cbn[2, 2]), -math.asin(cbn[2, 0])
        jac = euler_error_jacobian(cbn)
        h = np.zeros((2, n_x))
        h[:, 4:7] = jac[:2]
        if self._sheet:  # a = d v_b/dt + w x v_b of the IMU's velocity on the car
            v = self._v_body
            moving = 1.0 if self._u != 0.0 else 0.0
            f_b = f_b - np.array([rate[1] * v[2] - rate[2] * v[1],
                                  moving * self._rear_lever * self._yaw_accel + rate[2] * v[0]
                                  - rate[0] * v[2],
                                  rate[0] * v[1] - rate[1] * v[0]])
            f_tilt, roll, pitch = self._window_mean(f_b, roll, pitch)
            f_tilt[0] -= self._s * self._accel
            f_b = f_b - np.array([self._s * self._accel, 0.0, 0.0])
            roll, pitch = roll + self._tilt_bias[0], pitch + self._tilt_bias[1]
            h[:, TILT] = np.eye(2)
        else:
            f_tilt = f_b
        roll_acc = math.atan2(-f_tilt[1], -f_tilt[2])
        pitch_acc = math.atan2(f_tilt[0], math.hypot(f_tilt[1], f_tilt[2]))
        dz = [math.remainder(roll - roll_acc, 2.0 * math.pi), pitch - pitch_acc]
        norm = math.sqrt(f_b @ f_b)  # rule 1 on the step's own specific force
        if self._u == 0.0:
            self._still_norm_sum += norm
            self._still_steps += 1
            self._g = self._still_norm_sum / self._still_steps
        if c["adaptive"]:
            var = threshold_variance(abs(norm - self._g),
                                     ACCEL_NORM_THRESHOLD_M_S2, c["tilt_sigma"],
                                     c["tilt_sigma_inflated"])
        else:
            var = c["tilt_sigma"] ** 2
        if self._sheet:
            var += self._tilt_model_variance(rate)
        rows, dzs, variances = [h], [dz], [var, var]
        if self._use_baro and self._baro_new and self._baro_offset is not None:
            dz_h, h_h = barometric_height(self._pos[2], self._baro_h,
                                          self._baro_offset + self._baro_bias, n_x)
            var_h = c["baro_sigma"] ** 2
            if self._sheet:  # the offset's error is a state; the rest white
                h_h[0, BARO] = 1.0
                var_h = self._baro_noise**2
            if c["adaptive"]:
                var_h = threshold_variance(abs(dz_h[0]), BARO_INNOVATION_THRESHOLD_M,
                                           math.sqrt(var_h), c["baro_sigma_inflated"])
            rows.append(h_h)
            dzs.append(dz_h)
            variances.append(var_h)
            self._baro_new = False
        self._kf.update(np.concatenate(dzs), np.vstack(rows), np.diag(variances))
        self._feedback()

    def _window_mean(self, f_b: np.ndarray, roll: float, pitch: float
                     ) -> tuple[np.ndarray, float, float]:
        """The step's specific force (less the car's acceleration but the along-track one),
        roll and pitch averaged over the steps of the odometer acceleration's window, whose
        mean that acceleration is: the window's mean specific force is compared with the
        window's mean acceleration, and the tilt it gives with the window's mean attitude
        (the step's alone against the window's acceleration lagged it by ACCEL_WINDOW_S / 2,
        which a junction's jerk turned into degrees of tilt)."""
        win = self._window
        win.append((self._step_dt, f_b, roll, pitch))
        span = sum(w[0] for w in win)
        while span - win[0][0] >= ACCEL_WINDOW_S - 1e-9:
            span -= win.pop(0)[0]
        f_mean = sum(w[0] * w[1] for w in win) / span
        return (f_mean, sum(w[0] * w[2] for w in win) / span,
                sum(w[0] * w[3] for w in win) / span)

    def _tilt_model_variance(self, rate: np.ndarray) -> float:
        """What the car's acceleration removed from the g-slave leaves (``tuning:
        datasheet``), as the white-equivalent variance at the step's rate of errors
        correlated over a time T (2 sigma^2 T / step: a first-order Gauss-Markov process's
        PSD at zero frequency, Brown & Hwang, 4th ed., section 2.9): the odometer's
        acceleration, two speeds of the datasheet's noise ACCEL_WINDOW_S apart (white: a tick
        count's speed
        error is the difference of two quantisation errors, so the next reading's cancels it,
        and a reading held over two steps adds nothing at low frequency), and the tyres' slip
        velocity (``NonholonomicNoise``) turned by the yaw rate (T: SLIP_TIME_S); over g,
        rad^2."""
        if self._u == 0.0 and self._accel == 0.0:
            return 0.0
        step = self.config["step"]
        v = self._v_body[0]
        lateral = self._car.cornering_compliance * v * v * abs(rate[2])  # the tyres' slip
        return ((self._accel_sigma**2 * step
                 + 2 * (rate[2] * lateral) ** 2 * SLIP_TIME_S) / (G0**2 * step))

    def _feedback(self) -> None:
        dx = self._kf.feedback()
        pos = self._pos
        rn, re = radii(pos[0])
        pos[0] -= dx[0] / (rn + pos[2])
        pos[1] -= dx[1] / ((re + pos[2]) * math.cos(pos[0]))
        pos[2] += dx[2]
        self._s -= dx[3]
        tilt = self._cbn[2, 0], self._cbn[2, 1], self._cbn[2, 2]
        self._q, self._cbn = attitude_step(self._q, dx[4:7], self._zero3)
        self._bias -= dx[7:10]
        if self._sheet:
            self._shift_window(*tilt)
            self._tilt_bias -= dx[TILT]
            self._baro_bias -= dx[BARO]
            self._fix_error -= dx[FIX]
            self._squat -= dx[SQUAT]
            self._nlos -= dx[NLOS]

    def _shift_window(self, c20: float, c21: float, c22: float) -> None:
        """A correction's roll and pitch change (from the attitude's last row before it) added
        to the window's stored attitudes (``_window_mean``), which were the same estimate's."""
        c = self._cbn
        d_roll = (math.atan2(c[2, 1], c[2, 2]) - math.atan2(c21, c22))
        d_pitch = math.asin(c20) - math.asin(c[2, 0])
        self._window = [(dt, f, r + d_roll, p + d_pitch) for dt, f, r, p in self._window]

    def solution(self, t: float) -> list[float]:
        p = self._kf.p
        std = np.sqrt(np.diag(p))
        jac = euler_error_jacobian(self._cbn)
        std_att = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", jac, p[4:7, 4:7], jac), 0.0))
        roll, pitch, yaw = dcm_to_euler(self._cbn)
        lat, lon, h = self._pos
        return [math.degrees(lat), math.degrees(lon), h, *self._v_ned, float(roll),
                float(pitch), float(yaw), *std[0:3], *std_att, 1.0 / self._s, *self._bias]


class Dr2dOdoEkf(_OdometerDeadReckoning):
    """Park et al. 2019 conventional 2-D DR/GPS with odometer (section II-B, eqs. 15-19)."""

    name = "dr2d_odo_ekf"
    needs = ("imu", "odometer", "gnss_fix")
    paper = PAPER + ", section II-B (eqs. 15-19)"
    output_columns = (*NAV_COLUMNS, "std_n", "std_e", "std_yaw", "gyro_bias_z")
    defaults = {
        "tuning": "datasheet",  # "paper": the 5 states of eq. 17 and the values below only
        "step": 0.05,  # s, covariance propagation period
        "gyro_noise_density": 0.02 * DEG,  # rad/s/sqrt(Hz), SMI130 (Table 1)
        "gyro_bias_sigma": 0.01 * DEG,  # rad/s, Gauss-Markov steady state
        "gyro_bias_time_constant": 600.0,  # s
        "gyro_bias_initial": 1.0 * DEG,  # rad/s
        "speed_error_sigma": 0.3,  # m/s, Gauss-Markov steady state of dv
        "speed_error_time_constant": 100.0,  # s
        "position_initial": 3.0,  # m
        "heading_initial": 5.0 * DEG,  # rad
        "gps_horizontal_sigma": 3.0,  # m
        "gps_speed_sigma": 0.1,  # m/s
    }
    config_help = {k: CONFIG_HELP[k] for k in defaults}

    def setup(self) -> None:
        c = self.config
        if c["tuning"] not in TUNINGS:
            raise InputError(f"dr2d_odo_ekf: config tuning must be one of "
                             f"{', '.join(TUNINGS)}, got {c['tuning']!r}")
        self._sheet = c["tuning"] == "datasheet"
        init = self.initial
        self._lat, self._lon = float(init.position[0]), float(init.position[1])
        self._h = float(init.position[2])  # for the radii only: the 2-D filter has no height
        self._yaw = float(init.attitude[2])
        self._speed_error = 0.0  # estimated additive odometer speed error, m/s
        self._bias = 0.0  # z-gyro bias estimate, rad/s
        self._fix_error = np.zeros(2)  # the fix's drive-long north, east error, units of its
        # gain (datasheet)
        self._nlos = np.zeros(2)  # the reflected fixes' error, units of the fix's excess
        self._take_inputs()
        n = 9 if self._sheet else 5
        gyro_noise, bias_sigma, bias_tau, bias_initial = (
            c["gyro_noise_density"], c["gyro_bias_sigma"], c["gyro_bias_time_constant"],
            c["gyro_bias_initial"])
        if self._sheet:  # the datasheet's z gyro, and the fix's correlated error as two states
            imu = imu_error_model(self.datasheet)
            gyro_noise, bias_sigma, bias_tau, bias_initial = (
                imu.gyro_noise, imu.gyro_bias_sigma, imu.gyro_bias_tau, imu.gyro_bias_initial)
            self._fix_model = fix_error_model(self.datasheet)
            self._fix_split = FixSplit(self._fix_model)
            self._gyro_scale = imu.gyro_scale_sigma
            self._rate = 0.0
        p0 = np.zeros((n, n))
        p0[:5, :5] = np.diag([c["position_initial"] ** 2] * 2 + [c["speed_error_sigma"] ** 2,
                                                                 c["heading_initial"] ** 2,
                                                                 bias_initial**2])
        self._f = np.zeros((n, n))
        self._q_c = np.zeros(n)
        if self._sheet:
            # the fix's drive-long north, east error: unit states, their gain the part of the
            # fix's reported accuracy (toolbox.datasheet.FixSplit)
            p0[5:7, 5:7] = np.eye(2)
            self._f[5:7, 5:7] = np.eye(2) * (-1.0 / self._fix_model.correlated_tau)
            self._q_c[5:7] = 2.0 / self._fix_model.correlated_tau
            # the reflected fixes' north, east error: unit states, their gain the fix's excess
            p0[7:9, 7:9] = np.eye(2)
            self._f[7:9, 7:9] = -np.eye(2) / NLOS_TIME_CONSTANT_S
            self._q_c[7:9] = 2.0 / NLOS_TIME_CONSTANT_S
        self._kf = ErrorState(p0)
        # Gauss-Markov speed error and z-gyro bias
        f_gm, q_gm = gauss_markov_continuous([c["speed_error_time_constant"], bias_tau],
                                             [c["speed_error_sigma"], bias_sigma])
        self._q_c[2:5] = q_gm[0], gyro_noise**2, q_gm[1]
        self._f[2, 2] = f_gm[0]
        self._f[3, 4] = -1.0  # dpsi' = -(z-gyro bias error)
        self._f[4, 4] = f_gm[1]
        self._eye = np.eye(n)

    def _speed(self) -> float:
        return self._u - self._speed_error if self._u != 0.0 else 0.0

    def _step(self) -> None:
        """Heading (eq. 3 about the body z axis) and position (eqs. 15-16), covariance."""
        acc = self._imu
        dt = acc.dt
        v = self._speed()
        rn, re = radii(self._lat)
        v_ned = np.array([v * math.cos(self._yaw), v * math.sin(self._yaw), 0.0])
        w_ie, w_en = frame_rates(self._lat, self._h, v_ned)
        w_in_d = w_ie[2] + w_en[2]
        yaw_old = self._yaw
        rate = acc.dtheta[2] / dt
        self._yaw += acc.dtheta[2] - (self._bias + w_in_d) * dt
        acc.reset()
        yaw_mid = 0.5 * (yaw_old + self._yaw)
        cy, sy = math.cos(yaw_mid), math.sin(yaw_mid)
        self._lat += v * cy * dt / (rn + self._h)
        self._lon += v * sy * dt / ((re + self._h) * math.cos(self._lat))
        f = self._f
        moving = 1.0 if self._u != 0.0 else 0.0
        f[0, 2], f[1, 2] = cy * moving, sy * moving
        f[0, 3], f[1, 3] = -v * sy, v * cy
        q_d = np.diag(self._q_c * dt)
        if self._sheet:  # the scale-factor error moves the bias by s d(rate) (toolbox.datasheet)
            q_d[4, 4] += (self._gyro_scale * (rate - self._rate)) ** 2
            self._rate = rate
            self._nlos *= math.exp(-dt / NLOS_TIME_CONSTANT_S)  # its Gauss-Markov mean
        self._kf.predict(self._eye + f * dt, q_d)

    def on_gnss_fix(self, t: float, row: np.ndarray) -> None:
        """Eqs. 18-19: GPS north, east position and ground speed."""
        if not self._take_fix(row):
            return
        fx = self._fix
        c = self.config
        # no lever arm: the attitude argument is not used
        dz, _ = gnss_position(_LEVEL, np.array([self._lat, self._lon, self._h]),
                              np.array([math.radians(row[fx.lat]), math.radians(row[fx.lon]),
                                        self._h]), n_states=5)
        n = len(self._eye)
        dz = dz[:2]
        h = self._eye[:2].copy()
        var = [c["gps_horizontal_sigma"] ** 2] * 2
        speed_var = c["gps_speed_sigma"] ** 2
        if self._sheet:  # the fix is the truth plus its drive-long error, plus white noise
            dops = float(row[fx.hdop]), float(row[fx.vdop])
            std_pos, speed_sigma, _ = fx.reported(row)
            correlated, gain, white = self._fix_split.split(std_pos, *dops)
            dz = dz + correlated[:2] * self._fix_error
            h[:, 5:7] = np.diag(correlated[:2])
            var = list(white[:2])
            dz = dz + gain[:2] * self._nlos
            h[:, 7:9] = np.diag(gain[:2])
            speed_var = (speed_sigma if math.isfinite(speed_sigma)
                         else self._fix_model.velocity_sigma(*dops)[0]) ** 2
        if self._u != 0.0 and math.isfinite(row[fx.speed]):
            dz = np.r_[dz, abs(self._speed()) - row[fx.speed]]
            h = np.vstack([h, np.eye(n)[2]])
            var.append(speed_var)
        self._kf.update(dz, h, np.diag(var))
        dx = self._kf.feedback()
        rn, re = radii(self._lat)
        self._lat -= dx[0] / (rn + self._h)
        self._lon -= dx[1] / ((re + self._h) * math.cos(self._lat))
        self._speed_error += dx[2]
        self._yaw -= dx[3]
        self._bias -= dx[4]
        if self._sheet:
            self._fix_error -= dx[5:7]
            self._nlos -= dx[7:9]

    def solution(self, t: float) -> list[float]:
        v = self._speed()
        std = np.sqrt(np.diag(self._kf.p))
        nan = math.nan
        return [math.degrees(self._lat), math.degrees(self._lon), nan,
                v * math.cos(self._yaw), v * math.sin(self._yaw), nan, nan, nan,
                float(wrap_angle(self._yaw)), std[0], std[1], std[3], self._bias]
