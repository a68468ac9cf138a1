"""Noise and initial uncertainty of the Cho & Choi 2006 filters (``estimators.builtin.cho2006``):
the paper's printed values, or values derived from what a user knows.

* ``paper_tuning``: P0, Q and R of eqs. 33-35 (R = 15 m per position axis and 0.3 m/s on the
  speed, whatever the receiver reports); the reproduction of the paper uses these.
* ``datasheet_tuning``: the default. The navigation states keep eq. 33's priors (a user without
  a compass knows nothing of the heading; the paper's 50 m, 5 m/s and 10 deg pitch), and
  everything else comes from the dataset's ``datasheet`` (docs/dataset-format.md):

  - the sensor-error states: each scale factor's 1-sigma is the datasheet's ``scale_factor``
    (eq. 33 gives 1, a 100 % error), each accelerometer bias's the datasheet's turn-on ``bias``
    with its Gauss-Markov sigma and bias instability added in quadrature;
  - Q: the angle and velocity random walks of the gyros' and accelerometers' ``noise_density``
    (Groves 2013, section 4.4.3: the variance of the integrated white noise grows as N^2 t);
    on the heading and pitch also the gyro bias left after the standstill calibration, the
    calibration's own noise N / sqrt(T_still) with the datasheet's in-run instability, its
    g-sensitivity at 0.1 g and its temperature coefficient over the warm-up the datasheet's
    ``temperature`` block gives (a constant offset is calibrated away), held
    over ``BIAS_HOLD_S`` (its correlated growth b t counted as the random walk that reaches the
    same spread then: q = b^2 T); on the accelerometer biases the datasheet's random walk and
    instability (a Gauss-Markov bias of sigma s and time T drifts by 2 s^2 / T per second);
  - R from each fix's own HDOP (``gnss_fix.hdop``): per horizontal axis the variance
    (HDOP sigma_UERE)^2 / 2, sigma_UERE = sqrt(sis_error^2 + (MULTIPATH_ELEVATION_FACTOR
    multipath)^2) from the receiver's datasheet (signal in space and code multipath; the Hatch
    filter leaves the tracking noise a few centimetres), at least ``MIN_FIX_SIGMA_M``, raised
    to the fixes' measured scatter by covariance matching (``gating.FixNoiseMatching``: a
    street canyon's reflected signals leave HDOP unchanged) and counted as correlated over
    ``FIX_CORRELATION_S`` (``gnss_model.correlated_noise_inflation``; the signal-in-space and
    canyon errors hold for minutes, and a filter treating them as white believes the mean
    of its fixes to a fraction of their sigma); the speed's 1-sigma HDOP sigma_rate / sqrt(2)
    with the pseudorange-rate noise of an FLL at 40 dB-Hz (``RATE_SIGMA_M_S``, scaled by the
    datasheet's ``tracking_noise``). A fix that reports its own accuracy (``std_*`` of
    ``gnss_fix``, the receiver's least squares with its reflected signals;
    ``Tuning.reported_r``; with its velocity's 1-sigma too, the fix's correlated error is
    two states instead, ``cho2006._ChoDr._velocity_update``) replaces the matching: the
    position's reported 1-sigma beyond the receiver's budget
    (``toolbox.datasheet.FixErrorModel.excess_sigma``: the reflections, which leave HDOP
    unchanged) is added to the HDOP's variance and counted as correlated
    like it, and the speed row's 1-sigma is the fix's reported velocity 1-sigma along it. With
    the HDOP's 0.04 m/s a canyon's reflected Doppler (0.2-0.6 m/s, reported so) left DRM2's
    velocity (error / sigma)^2 at 2-4 on the unseen canyon, and the matching, which follows
    the fixes' scatter only after it, left ``urban_canyon``'s north position at 6-27 (seeds
    1-2); with the report every axis is at most 1 there (the position now too cautious, 0.07-0.7,
    where the DR coasts through the canyon);
  - the car's model errors (``vehicle`` in the datasheet, absent on a rigid body): the
    forward-acceleration error of the planar model on a real body (surge and side slip,
    ``CAR_ACCEL_SIGMA_M_S2``); for DRM2 the body's roll and the IMU's lateral velocity. Its
    pitch integrates the y gyro alone (eq. 24d), but a body rolled by phi pitches at w_y
    cos(phi) - w_z sin(phi) (ZYX Euler rates); a car rolls out of a turn by ``ROLL_GRADIENT``
    per lateral acceleration V w_z, which DRM2 compensates (``Drm2._inputs``), and the rest of
    the roll (``ROLL_SIGMA``) enters Q as w_z^2 ROLL_SIGMA^2 TURN_HOLD_S (it keeps its sign
    through a turn). Uncompensated, a 0.3 g turn at 4.6 deg/g (landnav's automotive body)
    leaks 1.4 deg of roll times the yaw rate into the pitch: 2.2 deg of pitch error per 90 deg
    turn, always of the same sign, which the term g sin(theta) turns into speed error. Eq. 5
    moves the IMU along its heading; an IMU ahead of the rear axle (the datasheet's
    ``rear_axle``, where the wheels roll without side slip) moves sideways at w_z times that
    distance, the kinematic side slip (5 deg in a 20 m turn); its error (the gyro's noise,
    and the understeer that cancels it near 20 m/s: ``LATERAL_FRACTION`` of it) enters Q;
  - DRM1's accelerometer biases also take the road's grade and bank, in their prior (the
    start's road, ``ROAD_SLOPE_SIGMA``: a crowned road's camber alone, 1-2 %, is the size of
    a MEMS turn-on bias, and a sigma of the bias alone left SUMO canyon's yaw at 11) and as
    a random walk (``ROAD_SLOPE_SIGMA`` per ``ROAD_SLOPE_HOLD_S``): its level frame (eq. 2)
    senses g sin(grade) as acceleration. On a car its y accelerometer rolls out of a turn
    with the body by ``ROLL_GRADIENT`` per lateral acceleration and senses gravity's share,
    g k V w_z, 8 % of the turn's acceleration at 5 deg/g, which the level frame integrates
    into cross-track velocity of one sign per turn (0.6 m/s after a 90 deg junction at 5 m/s);
    DRM1 removes it (``Drm1._inputs``) and takes the gradient's spread
    (``ROLL_GRADIENT_SPREAD``, Gillespie's 3-7 deg/g) as velocity noise held over a turn;
  - a stop: the odometer's zero reading bounds the speed by the wheel's cut-off
    (``stopped_speed_sigma``), and a zero held for 2 s is a stop.

Public names
------------
PAPER_P0, PAPER_Q, PAPER_R, TUNINGS, TURN_HOLD_S, Tuning, paper_tuning,
datasheet_tuning, stopped_speed_sigma.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from estimators.toolbox.datasheet import fix_error_model
from estimators.toolbox.gnss_model import correlated_noise_inflation
from estimators.toolbox.installation import Installation
from simulator.earth import G0_M_S2 as G0

DEG = math.pi / 180.0
TUNINGS = ("datasheet", "paper")

# eqs. 33-35. DRM2 state order [P_N, P_E, V, theta, psi, d_ax, d_gy, d_gz]; DRM1 (not printed)
# [P_N, P_E, V_N, V_E, psi, d_ax, d_ay, d_gz], term by term
PAPER_P0 = {
    "drm2": np.diag([50.0**2, 50.0**2, 5.0**2, (10 * DEG) ** 2, (180 * DEG) ** 2, 1.0, 1.0, 1.0]),
    "drm1": np.diag([50.0**2, 50.0**2, 5.0**2, 5.0**2, (180 * DEG) ** 2, 1.0, 1.0, 1.0]),
}
PAPER_Q = {
    "drm2": np.diag([0.0, 0.0, 0.1**2, (0.1 * DEG) ** 2, (0.1 * DEG) ** 2, 0.0, 0.0, 0.0]),
    "drm1": np.diag([0.0, 0.0, 0.1**2, 0.1**2, (0.1 * DEG) ** 2, 0.0, 0.0, 0.0]),
}
PAPER_R = np.diag([15.0**2, 15.0**2, 0.3**2])  # north, east (m), speed (m/s)

BIAS_HOLD_S = 10.0  # s over which a residual gyro bias is counted as a random walk
DRIVING_ACCEL_M_S2 = 0.1 * 9.80665  # a drive's rms acceleration, on the g-sensitivity
MULTIPATH_ELEVATION_FACTOR = 2.0  # code multipath at 20-30 deg elevation / zenith (DO-229D J.2.4)
FIX_CORRELATION_S = 30.0  # s: a fix's error counted as correlated over this (module docstring)
FIX_INFLATION = correlated_noise_inflation(FIX_CORRELATION_S, 1.0)  # on a 1 Hz fix's sigma
MIN_FIX_SIGMA_M = 0.1  # the smallest fix 1-sigma per axis believed
RATE_SIGMA_M_S = 0.04  # pseudorange-rate noise at 40 dB-Hz, 2 Hz FLL (Kaplan & Hegarty eq. 8.37)
MIN_SPEED_SIGMA_M_S = 0.01
CAR_ACCEL_SIGMA_M_S2 = 0.05  # planar model's forward-acceleration error on a real body, 1 s
ROLL_GRADIENT = 5.0 * DEG / G0  # rad per m/s^2: a passenger car's 3-7 deg/g (Gillespie 1992)
ROLL_SIGMA = 0.75 * DEG  # rad: the roll gradient's spread and the camber's net share
ROLL_GRADIENT_SPREAD = 2.0 * DEG / G0  # rad per m/s^2: Gillespie's 3-7 deg/g about ROLL_GRADIENT
ROAD_SLOPE_SIGMA = 0.03  # rad: grade and bank of a road, which DRM1's level frame ignores
ROAD_SLOPE_HOLD_S = 20.0  # s over which a road keeps its grade
TURN_HOLD_S = 10.0
LATERAL_FRACTION = 1.0  # the lateral velocity's error in a turn's transient, share of it
LATERAL_HOLD_S = 1.0  # s over which that error keeps its sign
DR_RATE_HZ = 10.0  # the filters' DR rate (cho2006.DR_STEP_S)
# the model's own floor: the 10 Hz trapezoidal DR step's error with error-free sensors (eq. 24)
MIN_ACCEL_NOISE = 0.01  # m/s^2/sqrt(Hz)
MIN_GYRO_NOISE = 2e-5  # rad/s/sqrt(Hz)
MIN_SCALE_SIGMA = 1e-4  # a scale-factor state's smallest prior (an ideal sensor's)
MIN_BIAS_SIGMA = 1e-4  # m/s^2, an accelerometer-bias state's smallest prior


@dataclass(frozen=True)
class Tuning:
    """P0 and Q (variance growth per second) of a filter's states, and its fix noise.

    ``uere_m`` None means the fixed ``PAPER_R``; otherwise the fix's position variance per
    axis is (HDOP uere_m)^2 / 2 (``white_position_var``), times the covariance-matching scale
    and the correlation inflation squared, and the speed's (HDOP speed_sigma_m_s)^2 / 2.
    """

    p0: np.ndarray
    q: np.ndarray
    uere_m: float | None = None
    speed_sigma_m_s: float = 0.0
    roll_gradient: float = 0.0  # rad per m/s^2 of lateral acceleration (0: no body roll)
    roll_sigma: float = 0.0  # rad, the roll not explained by roll_gradient
    rear_axle_m: float = 0.0  # m, the IMU ahead of the rear axle (its lateral velocity's arm)
    lateral_noise_m_s: float = 0.0  # the gyro noise's share of the lateral velocity, 1-sigma

    def lateral_variance(self, lateral_m_s: float) -> float:
        """Error variance of the IMU's lateral velocity ``lateral_m_s`` = arm w_z: the gyro's
        noise over a DR step and ``LATERAL_FRACTION`` of it (module docstring)."""
        return self.lateral_noise_m_s**2 + (LATERAL_FRACTION * lateral_m_s) ** 2

    def white_position_var(self, hdop: float) -> float:
        """The position variance per axis of a fix reporting ``hdop``, as if its errors were
        independent between fixes (m^2)."""
        return max(hdop * (self.uere_m or 0.0) / math.sqrt(2.0), MIN_FIX_SIGMA_M) ** 2

    def r(self, hdop: float, scale: float = 1.0) -> np.ndarray:
        """The 3 x 3 noise of a fix [north, east, speed] reporting ``hdop``, the position's
        variance times ``scale`` (``FixNoiseMatching``)."""
        if self.uere_m is None or not math.isfinite(hdop):
            return PAPER_R.copy() if self.uere_m is None else np.diag([1e6, 1e6, 1.0])
        pos = self.white_position_var(hdop) * scale * FIX_INFLATION**2
        speed = max(hdop * self.speed_sigma_m_s / math.sqrt(2.0), MIN_SPEED_SIGMA_M_S)
        return np.diag([pos, pos, speed**2])

    def reported_r(self, r: np.ndarray, excess_ne: np.ndarray | None, speed_sigma: float
                   ) -> np.ndarray:
        """The noise ``r`` of a fix with what the fix reports of its own accuracy (module
        docstring): the north and east 1-sigma ``excess_ne`` (m; None when not reported) of
        its reported error beyond the receiver's budget (reflected signals,
        ``FixErrorModel.excess_sigma``) added to the HDOP's variance, counted as correlated
        like it, and the speed row's ``speed_sigma`` (m/s, NaN when not reported)."""
        r = r.copy()
        if excess_ne is not None:
            r[0, 0] += excess_ne[0] ** 2 * FIX_INFLATION**2
            r[1, 1] += excess_ne[1] ** 2 * FIX_INFLATION**2
        if math.isfinite(speed_sigma):
            r[2, 2] = max(speed_sigma, MIN_SPEED_SIGMA_M_S) ** 2
        return r


def paper_tuning(model: str) -> Tuning:
    """Eqs. 33-35 for ``model`` ``"drm1"`` or ``"drm2"``."""
    return Tuning(PAPER_P0[model].copy(), PAPER_Q[model].copy())


def _axis(value: Any, axis: int) -> float:
    """A datasheet parameter for one axis (x, y, z = 0, 1, 2): a number or a list of three."""
    if value is None:
        return 0.0
    if isinstance(value, (list, tuple)):
        return float(value[axis] or 0.0)
    return float(value)


def _bias_terms(group: Mapping[str, Any], axis: int) -> tuple[float, float]:
    """Turn-on 1-sigma (bias, Gauss-Markov sigma, instability in quadrature) and the in-run
    drift of the bias (variance growth per second) of one axis of an IMU datasheet group."""
    turn_on = _axis(group.get("bias"), axis)
    gm = _axis(group.get("gauss_markov_sigma"), axis)
    gm_time = _axis(group.get("gauss_markov_correlation_time"), axis)
    instability = _axis(group.get("bias_instability"), axis)
    walk = _axis(group.get("random_walk"), axis)
    sigma = math.sqrt(turn_on**2 + gm**2 + instability**2)
    growth = walk**2 + (2.0 * gm**2 / gm_time if gm_time > 0.0 else 0.0)
    growth += instability**2 / BIAS_HOLD_S
    return sigma, growth


def _gyro_rate_noise(gyro: Mapping[str, Any], axis: int, still_s: float,
                     warmup_k: float) -> float:
    """Variance growth per second of an angle integrated from one gyro axis whose bias was
    calibrated over ``still_s`` seconds of standstill, in a unit whose temperature moves by
    ``warmup_k`` after it (module docstring)."""
    density = _axis(gyro.get("noise_density"), axis)
    instability = _axis(gyro.get("bias_instability"), axis)
    gm = _axis(gyro.get("gauss_markov_sigma"), axis)
    walk = _axis(gyro.get("random_walk"), axis)
    g_sensitivity = _axis(gyro.get("g_sensitivity"), axis) * DRIVING_ACCEL_M_S2
    temperature = _axis(gyro.get("temperature_coefficient"), axis) * warmup_k
    calibration = density / math.sqrt(max(still_s, 1.0))
    residual = (calibration**2 + instability**2 + gm**2 + walk**2 * BIAS_HOLD_S
                + g_sensitivity**2 + temperature**2)
    return density**2 + residual * BIAS_HOLD_S


def _receiver(gnss: Mapping[str, Any]) -> tuple[float, float]:
    """sigma_UERE (m) and the pseudorange-rate 1-sigma (m/s) of the receiver's datasheet."""
    sis = float(gnss.get("sis_error") or 0.0)
    multipath = float(gnss.get("multipath") or 0.0) * MULTIPATH_ELEVATION_FACTOR
    uere = max(math.hypot(sis, multipath), MIN_FIX_SIGMA_M)
    tracking = gnss.get("tracking_noise")
    rate = RATE_SIGMA_M_S * (1.0 if tracking is None else float(tracking))
    return uere, rate


def datasheet_tuning(model: str, datasheet: Mapping[str, Any], still_s: float) -> Tuning:
    """The default tuning (module docstring) of ``model`` (``"drm1"``, ``"drm2"``) from a
    manifest's ``datasheet``; the states are the paper's and the accelerometer biases (one for
    DRM2's forward axis, two for DRM1) appended. ``still_s``: the initial standstill's length."""
    imu = datasheet.get("imu") or {}
    gyro, accel = imu.get("gyro") or {}, imu.get("accel") or {}
    warmup = abs(float((imu.get("temperature") or {}).get("warmup") or 0.0))
    car = (datasheet.get("vehicle") or {}).get("preset", "rigid") != "rigid"
    uere, rate = _receiver(datasheet.get("gnss") or {})
    p0 = PAPER_P0[model].diagonal().copy()
    q = np.zeros(8)
    accel_axes = (0,) if model == "drm2" else (0, 1)
    gyro_sf = (1, 2) if model == "drm2" else (2,)
    car_accel = CAR_ACCEL_SIGMA_M_S2**2 if car else 0.0
    if model == "drm2":
        q[2] = _axis(accel.get("noise_density"), 0) ** 2 + car_accel
        q[3] = _gyro_rate_noise(gyro, 1, still_s, warmup)
        p0[5] = max(_axis(accel.get("scale_factor"), 0), MIN_SCALE_SIGMA) ** 2
    else:
        q[2] = q[3] = max(_axis(accel.get("noise_density"), a) ** 2 for a in (0, 1)) + car_accel
        p0[5] = max(_axis(accel.get("scale_factor"), 0), MIN_SCALE_SIGMA) ** 2
        p0[6] = max(_axis(accel.get("scale_factor"), 1), MIN_SCALE_SIGMA) ** 2
    q[4] = _gyro_rate_noise(gyro, 2, still_s, warmup)
    for i in gyro_sf:
        p0[5 + i] = max(_axis(gyro.get("scale_factor"), i), MIN_SCALE_SIGMA) ** 2
    bias_p0, bias_q = [], []
    for a in accel_axes:
        sigma, growth = _bias_terms(accel, a)
        road = (G0 * ROAD_SLOPE_SIGMA) ** 2 if model == "drm1" else 0.0
        bias_p0.append(max(sigma, MIN_BIAS_SIGMA) ** 2 + road)  # the start's grade and bank
        bias_q.append(growth + road / ROAD_SLOPE_HOLD_S)
    rear = Installation.from_datasheet(datasheet).rear_axle
    arm = float(-rear[0]) if model == "drm2" and car and rear is not None else 0.0
    q[2:4] = np.maximum(q[2:4], MIN_ACCEL_NOISE**2 if model == "drm1" else
                        [MIN_ACCEL_NOISE**2, MIN_GYRO_NOISE**2])
    q[4] = max(q[4], MIN_GYRO_NOISE**2)
    lateral_noise = arm * _axis(gyro.get("noise_density"), 2) * math.sqrt(DR_RATE_HZ)
    # the fix's correlated north and east error over its 1-sigma at each fix (unit variance)
    bias_p0 += [1.0, 1.0]
    bias_q += [2.0 / fix_error_model(datasheet).correlated_tau] * 2
    return Tuning(np.diag([*p0, *bias_p0]), np.diag([*q, *bias_q]), uere, rate,
                  ROLL_GRADIENT if car else 0.0, ROLL_SIGMA if car else 0.0, arm, lateral_noise)


def stopped_speed_sigma(datasheet: Mapping[str, Any]) -> float:
    """1-sigma of the speed when the odometer reads zero: the reading's cut-off (its
    ``min_speed``, its ``speed_resolution``, or one tick per output interval,
    rate / ticks_per_meter), the true speed uniform below it (cut-off / sqrt(3));
    ``MIN_SPEED_SIGMA_M_S`` without an odometer datasheet."""
    odo = datasheet.get("odometer") or {}
    ticks, rate = float(odo.get("ticks_per_meter") or 0.0), float(odo.get("rate") or 0.0)
    cut = max(float(odo.get("min_speed") or 0.0), float(odo.get("speed_resolution") or 0.0),
              rate / ticks if ticks > 0.0 else 0.0)
    return max(cut / math.sqrt(3.0), MIN_SPEED_SIGMA_M_S)
