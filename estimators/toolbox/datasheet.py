"""Noise and initial uncertainty of a filter from what a user knows before the drive: the
dataset's ``datasheet`` (``Estimator.datasheet``: each sensor's data-sheet parameters, SI units)
and the fix's own dilution of precision. One home for the translation, so that every filter
that tunes itself "from the datasheet" means the same thing.

* ``imu_error_model``: the IMU's white noises are its noise densities; its in-run biases a
  first-order Gauss-Markov process whose steady-state sigma is the bias instability, the extra
  Gauss-Markov term and the bias random walk over the correlation time in quadrature (Groves
  2013, section 4.4.3 and eq. 14.84 for the Gauss-Markov PSD 2 sigma^2 / tau); the turn-on
  bias range the initial bias uncertainty (the g-sensitivity of a gyro under gravity is a
  turn-on bias too). Scale-factor and misalignment errors are not states: a scale-factor error
  s acts as a bias s x on a reading x, which moves by s dx when the reading changes, so
  ``InsFilter`` adds (s dx)^2 to the bias's process noise over each interval
  (``InsNoise.gyro_scale_sigma``, ``accel_scale_sigma``; the gyro's g-sensitivity times the
  change of specific force likewise). A filter with the yaw-response states of ``InsFilter``
  takes their 1-sigma from ``ImuErrorModel.yaw_response_sigma``: the gyro misalignment for x
  and y, the scale factor for z.
* ``fix_error_model``: the position error of a receiver's fix, per unit DOP, from the one
  receiver error budget (``simulator.datasheet.range_error_budget``), split by time behaviour:

  - correlated over the drive (``correlated_sigma``, correlation time ``CORRELATED_TAU_S``):
    signal in space, the ionosphere's and the troposphere's residuals. Per axis: north and
    east HDOP / sqrt(2), down VDOP times that range error.
  - the rest, code tracking noise after the Hatch filter and multipath: correlated over the
    carrier-smoothing time T, so given to the filter as the white noise of the same
    low-frequency spectrum, variance 2 sigma^2 T / dt at the fix interval dt (Brown & Hwang,
    4th ed., section 2.9: a first-order Gauss-Markov process's PSD at zero frequency is
    2 sigma^2 T).
  - velocity: 0.05 m/s per range rate (u-blox NEO-M8 data sheet; the ``automotive`` FLL's
    0.024-0.08 m/s at 45-35 dB-Hz, docs/gnss-errors.md) times the DOP.
  - the drive-long part from the report (``FixErrorModel.reported_drive_long_sigma``): a fix
    that reports its own position 1-sigma (the receiver's least squares with the
    ionosphere's common residual and its field over the sky, ``simulator.gnss.fix``) knows
    its geometry's share of the drive-long error per axis, which the budget's DOP scaling
    spreads evenly over north and east: its reported variance less the smoothed part, capped
    at the budget's correlated part (the rest is the excess below). On open sky the report
    is the smaller (``automotive`` receiver on the unseen open road and SUMO city: north
    1.4-1.5 m, east 1.0-1.25 m against the budget's 1.7 m per axis, seed 1).
  - what the fix itself reports (``FixAccuracy``: its ``std_*`` columns, a receiver's own
    accuracy, ``simulator.gnss.fix``; a real receiver's NMEA GST standard deviations of the
    latitude, longitude and altitude errors, or u-blox's hAcc and vAcc: the pseudorange errors'
    statistics mapped into the position, G Sigma G^T of the weighted least squares, Misra &
    Enge 2011, section 6.1, the whole error with no split by time behaviour): its velocity
    1-sigma replaces the datasheet's. For ``ins_odo_ekf``, ``dr3d_ekf``, ``dr2d_odo_ekf``
    and ``ins_lkf`` its position 1-sigma r sizes the drive-long part (``FixSplit``): per
    axis and unit DOP, the smallest so far of ``reported_drive_long_sigma`` (the bullet
    above: sqrt(r^2 - (s DOP)^2), at most the budget's correlated part) over the DOP.
    The budget cannot know the hour or the sky: its correlated 2.2 m (the ``automotive``
    receiver) is a bound for a midday ionosphere, while the fix's report holds the day's
    broadcast delays and the satellites' geometry per axis (on the unseen ``open_road``, seed
    1, the report per unit DOP (HDOP / sqrt(2) horizontally) is 1.98 m north, 1.63 m east,
    2.47 m down at its median, on ``sumo_city`` 1.84, 1.31 and 2.05; the simulated fixes'
    realised error per unit DOP over twenty seeds, ``simulator.datasheet``, 1.2-1.35 m
    horizontally), so a filter sized by the budget alone was too cautious horizontally on
    open sky (mean (error / sigma)^2 0.04-0.1 on some drives' north or east). Why the
    smallest: the drive-long error (ionosphere, orbits) changes over tens of minutes, while
    the report rises from one epoch to the next with the signals the receiver suspects (a
    faded direct signal's share of a reflection's extra path: 1.3-2.5 m per VDOP from one
    fix to the next on the unseen canyon's open stretches, seed 1; the first fixes, before
    the carrier smoothing converges: 4.05 m per DOP north at the first fix of ``open_road``
    seed 1); those rises are the excess below, not a larger drive-long error (taken at each
    fix, with the states' gain at each fix's DOPs, the report's jumps and a canyon's jumps of
    VDOP, 1.7 to 5.5, moved the filter's modelled fix error with them: the unseen canyon's
    height (error / sigma)^2 0.31 -> 4.1, seeds 1-3). Only north and east
    (``REPORTED_AXES``): the height keeps the budget's part. A street canyon's reflections
    sink the fix (an extra path is never negative, so their mean adds up in the height and the
    clock, ``simulator.datasheet.nlos_delay_moments``), which the excess's zero-mean states
    below do not hold: its reflected fixes pulled the filter's height 2-3 m down (seed 2), which the
    budget's larger part covers; with the height's part from the report (1.3-1.5 m per VDOP
    on the canyon's open stretches) the unseen canyon's seed 2 height (error / sigma)^2 was
    1.3 (``ins_odo_ekf``) and 2.0 (``ins_lkf``), against 0.44 and 0.68 with the budget's (seed 1:
    0.02 and 0.06 against 0.004 and 0.09): within the goal either way, kept on the budget. The
    filters carry the part as a unit-variance Gauss-Markov state per axis whose fix row is
    its 1-sigma at the first fix's DOPs times the state, e = g_k u, g_k shrinking with the
    smallest report. The report's variance beyond that part and the smoothed one
    (``FixErrorModel.excess_sigma``: beyond the budget, for a filter that takes the budget's
    correlated part) is error the budget does not hold, the reflected (NLOS) signals of a street
    canyon. That excess is not white: a reflection's extra path lasts while the street's
    geometry does (the fixes of the simulated canyons, their error over the excess: the height's
    stays near -1.2 for minutes, the horizontal's correlation is 0.2-0.6 after 20 s and 0.0-0.4
    after 40 s, seeds 1-5 of canyon, urban_canyon and sumo_city_canyon), so a filter carries it
    as states: a unit-variance first-order Gauss-Markov u per axis of correlation time
    ``NLOS_TIME_CONSTANT_S`` whose fix row is the excess, e = excess_k u (a known time-varying
    gain on a stationary process: zero on open sky, where u is unobserved and inert). Not all of
    it is slow: from one epoch to the next the horizontal error over the excess keeps a
    correlation of only 0.4-0.8 (the set of reflected satellites changes), the height's 0.8-0.9.
    ``FixErrorModel.nlos_split`` gives the share ``NLOS_WHITE_SHARE`` of the excess variance
    (north, east, down: 0.5, 0.5, 0.1, the drives' lag-one correlation rounded down) to the
    fix's white noise and the rest to the states' gain; with all of it slow the filter read the
    epoch-to-epoch jumps as motion (the unseen canyon's 2-D yaw error 2-3 deg against a sigma of
    0.7-1 deg).

* ``odometer_speed_sigma``: the white 1-sigma of an odometer's speed: the tick count's
  quantisation, 1 / (``ticks_per_meter`` dt) over an interval dt = 1 / ``rate``, uniform, so
  divided by sqrt(12) (a CAN speed timed by its tooth edges instead has the step
  ``speed_resolution``), in quadrature with a 0.05 m/s floor (the wheel's own motion on the
  road that the body does not share: chosen). ``odometer_delay_s``: how old the speed is
  when stamped, the ``latency`` plus half the counting interval of a counted speed
  (``odometer_window_s``): a tick count's mean over the interval, or a CAN speed's mean between
  the first and the last tooth edge inside it (``tooth_timing``, ``simulator.sensors.odometer``),
  both stamped at the interval's end (the ``automotive`` CAN speed at 50 Hz, 20 ms latency:
  30.0 ms against the truth's speed and acceleration by least squares above 4 m/s, 39 ms at
  1-4 m/s where the edges are sparse; ``sumo_city_canyon`` seed 1). A CAN speed's age grows
  where its edges are sparse, at a reading v (``odometer_window_s(datasheet, v)``): with
  edges g = 1 / (``ticks_per_meter`` v) apart, the last edge before the stamp is on average
  g / 2 old, and the span it is timed over is the window's edges, dt - g on average, when
  g <= dt / 2, else one edge pair, g (the first edge is at least the one before the last):
  the mean's age is the latency plus g / 2 + span / 2, that is latency + max(dt / 2, g)
  (the ``automotive`` wheel's 42.5 mm teeth at 1 m/s: 62 ms, at its 2 km/h cut-off 97 ms;
  taken as 30 ms, the speed of the last second of a stop at 2 m/s^2 read 0.06-0.13 m/s
  fast, ``sumo_city`` seed 1). The same g is its spread (a bound: the age is uniform over
  g around its mean).

Public names
------------
ImuErrorModel, imu_error_model, FixErrorModel, fix_error_model, FixAccuracy, FixSplit,
fix_position_rows,
fix_velocity_sigma, ground_track_sigma, odometer_speed_sigma, odometer_delay_s, odometer_window_s,
CORRELATED_TAU_S, NLOS_TIME_CONSTANT_S, MIN_DRIVE_LONG_SIGMA_M.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from estimators.toolbox.ins_filter import InsNoise
from simulator.datasheet import range_error_budget

CORRELATED_TAU_S = 1800.0  # ionosphere and ephemeris residuals change over tens of minutes
RANGE_RATE_SIGMA_M_S = 0.05  # a car receiver's range-rate noise (u-blox NEO-M8: 0.05 m/s)
DEFAULT_BIAS_TAU_S = 600.0  # correlation time of the in-run bias when the sheet gives none
SCALE_FACTOR_TIME_S = 4.0  # s: a scale-factor error adds up over a quarter turn of 30 m radius
# at 12 m/s; filters without scale-factor states take it as white noise over that time
NLOS_TIME_CONSTANT_S = 60.0  # a reflected fix error's correlation time (module docstring)
NLOS_WHITE_SHARE = np.array([0.5, 0.5, 0.1])  # its variance's white share, NED (docstring)
REPORTED_AXES = np.array([True, True, False])  # axes whose drive-long part the report sizes
MIN_DRIVE_LONG_SIGMA_M = 0.1  # the smallest drive-long fix error believed from a report, m
FIX_STD_COLUMNS = ("std_n", "std_e", "std_d", "std_vn", "std_ve", "std_vd")


@dataclass(frozen=True)
class ImuErrorModel(InsNoise):
    """The filter's IMU noise (``ins_filter.InsNoise``: per axis, SI units, white noise
    densities, in-run Gauss-Markov bias sigma and correlation time, scale-factor 1-sigma with
    misalignment, the gyro's g-sensitivity) and the turn-on bias 1-sigma a filter's P0 takes."""

    accel_bias_initial: float = 0.0
    gyro_bias_initial: float = 0.0
    gyro_scale_factor: float = 0.0
    gyro_misalignment: float = 0.0

    @property
    def yaw_response_sigma(self) -> np.ndarray:
        """1-sigma of the gyro triad's response to the z rate (``InsFilter``'s yaw-response
        states): misalignment towards z on x and y, the scale factor on z."""
        return np.array([self.gyro_misalignment, self.gyro_misalignment,
                         self.gyro_scale_factor])


def _value(group: Mapping[str, Any], key: str) -> float:
    """A per-axis datasheet value as one number (the largest axis), 0 when absent."""
    v = group.get(key)
    if v is None:
        return 0.0
    if isinstance(v, Mapping):  # a fixed true value given as {fixed: ...}: a known value
        return 0.0
    return float(np.max(np.abs(np.atleast_1d(np.asarray(v, dtype=float)))))


def _group(imu: Mapping[str, Any], name: str) -> tuple[float, float, float, float, float, float]:
    g = imu.get(name) or {}
    tau = float(g.get("bias_correlation_time") or DEFAULT_BIAS_TAU_S)
    in_run = math.sqrt(_value(g, "bias_instability") ** 2 + _value(g, "gauss_markov_sigma") ** 2
                       + _value(g, "random_walk") ** 2 * tau / 3.0)
    scale = math.hypot(_value(g, "scale_factor"), _value(g, "misalignment"))
    return (_value(g, "noise_density"), in_run, tau, _value(g, "bias"), scale,
            _value(g, "g_sensitivity"))


def imu_error_model(datasheet: Mapping[str, Any]) -> ImuErrorModel:
    """The IMU's error model (module docstring) from a dataset's ``datasheet``.

    The random walk's variance over the correlation time tau, K^2 tau / 3 (the mean variance of
    a random walk over an interval of length tau), joins the instability. The turn-on bias
    adds the gyro's g-sensitivity times gravity in quadrature. Floors keep a perfect sensor's
    filter numerically sound: 1e-6 of a typical MEMS value.
    """
    imu = datasheet.get("imu") or {}
    a_noise, a_run, a_tau, a_bias, a_scale, _ = _group(imu, "accel")
    g_noise, g_run, g_tau, g_bias, g_scale, g_sens = _group(imu, "gyro")
    g_bias = math.hypot(g_bias, g_sens * 9.80665)
    return ImuErrorModel(accel_noise=max(a_noise, 1e-9), gyro_noise=max(g_noise, 1e-10),
                         accel_bias_sigma=max(a_run, 1e-8), gyro_bias_sigma=max(g_run, 1e-10),
                         accel_bias_tau=a_tau, gyro_bias_tau=g_tau,
                         accel_bias_initial=max(a_bias, 1e-6),
                         gyro_bias_initial=max(g_bias, 1e-8),
                         accel_scale_sigma=a_scale, gyro_scale_sigma=g_scale,
                         gyro_g_sensitivity=g_sens,
                         gyro_scale_factor=_value(imu.get("gyro") or {}, "scale_factor"),
                         gyro_misalignment=_value(imu.get("gyro") or {}, "misalignment"))


@dataclass(frozen=True)
class FixErrorModel:
    """A receiver's fix error per unit DOP (module docstring): the user range errors in m
    (``correlated_range``, ``white_range``: the latter already the white equivalent at the fix
    interval; ``smoothed_range`` the smoothed error's own 1-sigma), their correlation time,
    and the range-rate 1-sigma (m/s)."""

    correlated_range: float
    white_range: float
    correlated_tau: float
    range_rate: float
    smoothed_range: float = 0.0

    def correlated_sigma(self, hdop: float, vdop: float) -> np.ndarray:
        """NED 1-sigma (m) of the drive-long correlated error at these DOPs."""
        return self.correlated_range * _axes(hdop, vdop)

    def white_sigma(self, hdop: float, vdop: float) -> np.ndarray:
        """NED 1-sigma (m) of the white-equivalent remainder at these DOPs."""
        return self.white_range * _axes(hdop, vdop)

    def velocity_sigma(self, hdop: float, vdop: float) -> np.ndarray:
        """NED 1-sigma (m/s) of the fix's velocity at these DOPs."""
        return self.range_rate * _axes(hdop, vdop)

    def reported_drive_long_sigma(self, reported: np.ndarray, hdop: float, vdop: float
                                  ) -> np.ndarray:
        """NED 1-sigma (m) of the drive-long correlated error of a fix that reports its own
        position 1-sigma ``reported`` (module docstring, "the drive-long part from the
        report"): the reported variance less the budget's smoothed part at the DOPs, at most
        the budget's ``correlated_sigma`` (what the report holds beyond the budget is the
        ``excess_sigma``), at least ``MIN_DRIVE_LONG_SIGMA_M``; the budget's on an axis the
        fix does not report (NaN)."""
        budget = self.correlated_sigma(hdop, vdop)
        smoothed = self.smoothed_range * _axes(hdop, vdop)
        reported = np.asarray(reported, dtype=float)
        own = np.sqrt(np.maximum(reported**2 - smoothed**2, 0.0))
        own = np.clip(own, np.minimum(MIN_DRIVE_LONG_SIGMA_M, budget), budget)
        return np.where(np.isfinite(reported), own, budget)

    def excess_sigma(self, reported: np.ndarray, hdop: float, vdop: float) -> np.ndarray:
        """NED 1-sigma (m) of a fix's reported position error beyond this budget at its DOPs
        (the correlated and smoothed parts in quadrature): 0 where the report is within it or
        not finite."""
        budget = (self.correlated_range**2 + self.smoothed_range**2) * _axes(hdop, vdop) ** 2
        extra = np.nan_to_num(np.asarray(reported, dtype=float) ** 2 - budget, nan=0.0)
        return np.sqrt(np.maximum(extra, 0.0))

    def nlos_split(self, reported: np.ndarray, hdop: float, vdop: float
                   ) -> tuple[np.ndarray, np.ndarray]:
        """The ``excess_sigma`` split into the gain of the unit NLOS states and the variance
        added to the fix's white noise (NED; module docstring)."""
        excess2 = self.excess_sigma(reported, hdop, vdop) ** 2
        return np.sqrt((1.0 - NLOS_WHITE_SHARE) * excess2), NLOS_WHITE_SHARE * excess2


def _axes(hdop: float, vdop: float) -> np.ndarray:
    h = hdop / math.sqrt(2.0) if math.isfinite(hdop) and hdop > 0 else 1.0
    v = vdop if math.isfinite(vdop) and vdop > 0 else 2.0
    return np.array([h, h, v])


def fix_error_model(datasheet: Mapping[str, Any]) -> FixErrorModel:
    """The fix error model (module docstring) from the datasheet's ``gnss`` block; a block
    without these keys (an ``ideal`` receiver) gives a 0.1 m floor."""
    gnss = datasheet.get("gnss") or {}
    budget = range_error_budget(gnss)
    white = budget.smoothed
    if budget.smoothing_s > 0:  # the white noise of the smoothed error's low-frequency spectrum
        white *= math.sqrt(2.0 * budget.smoothing_s * float(gnss.get("rate") or 1.0))
    return FixErrorModel(correlated_range=max(budget.correlated_m(), 0.1),
                         white_range=max(white, 0.1), correlated_tau=CORRELATED_TAU_S,
                         range_rate=RANGE_RATE_SIGMA_M_S, smoothed_range=budget.smoothed)


class FixAccuracy:
    """A fix stream's own accuracy columns (``FIX_STD_COLUMNS``, module docstring), read from
    a row: ``position`` and ``velocity`` NED 1-sigma, NaN where the stream or the row has
    none."""

    def __init__(self, columns: Mapping[str, int]):
        self._cols = [columns.get(c) for c in FIX_STD_COLUMNS]

    def read(self, row: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(position 1-sigma (3,), m; velocity 1-sigma (3,), m/s) of a fix row."""
        std = np.array([float(row[i]) if i is not None else math.nan for i in self._cols])
        return std[:3], std[3:]


class FixSplit:
    """A fix stream's reported position 1-sigma split by time behaviour (module docstring),
    fix after fix: the drive-long part (north and east: its 1-sigma per unit DOP the smallest
    report so far less the smoothed part, at most the budget's correlated range error; down:
    the budget's), the budget's
    smoothed part, and the excess beyond both (the reflected fixes' states' gain and the
    white share, ``NLOS_WHITE_SHARE``)."""

    def __init__(self, model: FixErrorModel):
        self.model = model
        self.range_m = np.full(3, model.correlated_range)  # drive-long, per unit DOP, NED
        self.first_axes: np.ndarray | None = None  # the first fix's DOP per axis

    def split(self, reported: np.ndarray, hdop: float, vdop: float
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(drive-long 1-sigma (3,), m, at the first fix's DOPs (the states' size, as a
        filter sized them once before: scaled by each fix's DOPs, a street canyon's jumps of
        VDOP from 1.7 to 5.5 moved the modelled error with them); the reflected-fix states'
        gain (3,), m; the white noise's variance (3,), m^2) of a fix of ``reported`` position
        1-sigma (NED; NaN: no report on that axis, no excess) at its DOPs."""
        model = self.model
        axes = _axes(hdop, vdop)
        report2 = np.asarray(reported, dtype=float) ** 2
        smoothed2 = (model.smoothed_range * axes) ** 2
        finite = np.isfinite(report2)
        own = model.reported_drive_long_sigma(reported, hdop, vdop) / axes
        self.range_m = np.where(finite & REPORTED_AXES, np.minimum(self.range_m, own),
                                self.range_m)
        if self.first_axes is None:
            self.first_axes = axes
        excess2 = np.where(finite, np.maximum(report2 - (self.range_m * axes) ** 2 - smoothed2,
                                              0.0), 0.0)
        return (self.range_m * self.first_axes, np.sqrt((1.0 - NLOS_WHITE_SHARE) * excess2),
                model.white_sigma(hdop, vdop) ** 2 + NLOS_WHITE_SHARE * excess2)


def fix_position_rows(fix_split: FixSplit, reported: np.ndarray, hdop: float, vdop: float,
                      dz: np.ndarray, h: np.ndarray, states: np.ndarray, first: int
                      ) -> np.ndarray:
    """A fix's position rows with its error states (module docstring): six unit states, the
    drive-long error's (north, east, down) at column ``first`` and the reflected fixes' after
    them, of estimate ``states`` (6,). Adds their part e = g u to the innovation rows ``dz``
    (3,) and to ``h`` (3, n) in place, the gains ``FixSplit.split`` gives for the fix's
    ``reported`` position 1-sigma, and returns the rows' noise covariance (3, 3): the white
    remainder at the DOPs and the excess's white share."""
    correlated, nlos, white = fix_split.split(reported, hdop, vdop)
    dz += correlated * states[:3] + nlos * states[3:6]
    h[:, first:first + 3] = np.diag(correlated)
    h[:, first + 3:first + 6] = np.diag(nlos)
    return np.diag(white)


def fix_velocity_sigma(model: FixErrorModel, reported: np.ndarray, hdop: float, vdop: float
                       ) -> np.ndarray:
    """NED 1-sigma (m/s) of a fix's velocity: its ``reported`` own where finite, else the
    datasheet's at its DOPs (``FixErrorModel.velocity_sigma``)."""
    return np.where(np.isfinite(reported), reported, model.velocity_sigma(hdop, vdop))


def ground_track_sigma(vn: float, ve: float, std_vn: float, std_ve: float
                       ) -> tuple[float, float]:
    """1-sigma of the ground speed (m/s) and course (rad) of a horizontal velocity with
    independent north and east errors (first order: the speed's gradient is the unit velocity,
    the course's the perpendicular over the speed); NaN where a sigma is not finite or the
    car stands."""
    speed2 = vn * vn + ve * ve
    if not (math.isfinite(std_vn) and math.isfinite(std_ve)) or speed2 <= 0.0:
        return math.nan, math.nan
    var_speed = (vn * vn * std_vn**2 + ve * ve * std_ve**2) / speed2
    var_course = (ve * ve * std_vn**2 + vn * vn * std_ve**2) / (speed2 * speed2)
    return math.sqrt(var_speed), math.sqrt(var_course)


ODOMETER_FLOOR_M_S = 0.05  # wheel motion the body does not share, m/s (chosen)


def odometer_speed_sigma(datasheet: Mapping[str, Any], speed: float = 1.0) -> float:
    """White 1-sigma of the odometer's speed, m/s (module docstring); a reading of exactly 0
    below a ``min_speed`` cut-off may be any speed under it (uniform: min_speed / sqrt(3))."""
    odo = datasheet.get("odometer") or {}
    min_speed = float(odo.get("min_speed") or 0.0)
    if speed == 0.0 and min_speed > 0:
        return math.hypot(ODOMETER_FLOOR_M_S, min_speed / math.sqrt(3.0))
    rate = float(odo.get("rate") or 10.0)
    ticks = float(odo.get("ticks_per_meter") or 0.0)
    if odo.get("tooth_timing"):
        step = float(odo.get("speed_resolution") or 0.0)
    else:
        step = rate / ticks if ticks > 0 else float(odo.get("speed_resolution") or 0.0)
    return math.hypot(ODOMETER_FLOOR_M_S, step / math.sqrt(12.0))


def odometer_delay_s(datasheet: Mapping[str, Any], speed: float = math.inf) -> float:
    """Age of the odometer's speed at its time stamp, s, for a reading ``speed`` (m/s; the
    default: fast enough that a CAN speed's edges are dense), module docstring."""
    odo = datasheet.get("odometer") or {}
    return float(odo.get("latency") or 0.0) + odometer_window_s(datasheet, speed)


def odometer_window_s(datasheet: Mapping[str, Any], speed: float = math.inf) -> float:
    """The share of ``odometer_delay_s`` beyond the latency, and its spread, s (module
    docstring): half the interval a counted speed is the mean over; for a CAN speed timed by
    its tooth edges (``tooth_timing``) at a reading ``speed`` (m/s, not 0) the larger of that
    and the edges' spacing in time; 0 for an instantaneous speed."""
    odo = datasheet.get("odometer") or {}
    ticks = float(odo.get("ticks_per_meter") or 0.0)
    if ticks <= 0:
        return 0.0
    half = 0.5 / float(odo.get("rate") or 10.0)
    if odo.get("tooth_timing") and speed != 0.0:
        return max(half, 1.0 / (ticks * abs(speed)))
    return half
