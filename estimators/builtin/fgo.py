"""``fgo_lc``: a loosely coupled factor-graph smoother on GTSAM (Dellaert & Kaess, "Factor
Graphs for Robot Perception", 2017), run as a fixed-lag smoother whose output at each time uses
only the past, so it is causal like every other estimator.

The graph, in a local NED frame fixed at the initial position (an Earth-fixed frame: the Earth
rate enters as GTSAM's Coriolis rate, constant in that frame):

* Keyframes (pose X_k, velocity V_k, IMU bias B_k) at every GNSS fix and, in a gap without
  fixes, every ``keyframe_interval`` seconds.
* IMU preintegration with bias states between keyframes (Forster et al., "On-Manifold
  Preintegration for Real-Time Visual-Inertial Odometry", IEEE T-RO 33(1), 2017; GTSAM's
  ``CombinedImuFactor``, the bias a random walk). The white noises are the datasheet's noise
  densities; the bias random walk is the datasheet's rate/acceleration random walk plus the
  bias instability B as a random walk over ``BIAS_TIME_S`` (2 B^2 / tau); the first bias has
  the datasheet's turn-on bias as its prior. The triads' scale-factor and misalignment errors
  and the gyro's g-sensitivity (datasheet 1-sigmas) are white noise over
  ``SCALE_FACTOR_TIME_S`` on the readings of each IMU sample, the specific force taken less
  gravity (``_scale_noise``; the shared parameters are set before each sample is integrated):
  without them the preintegration trusted the IMU to 2 mm/s per second through a 2 m/s^2
  acceleration that a 1 mrad misalignment alone turns into 2 mm/s^2 of vertical error, and the
  smoother averaged the fixes' vertical velocity over its whole window (quickstart seed 1:
  down velocity (error / sigma)^2 4.1 -> 0.66). The normal-gravity change across the drive (the
  local vertical turns by d / R from the frame's origin) is added to each specific-force sample
  with the current attitude, so the constant gravity of the preintegration stays exact.
* GNSS: the fix's position at the antenna (the datasheet's lever arm) is the antenna's
  position plus the fix's own error, as the filters model it (``toolbox.datasheet.
  fix_error_model``): its drive-long part (the signal-in-space error and the ionosphere's
  residual) a unit-variance first-order Gauss-Markov variable u of correlation time
  ``CORRELATED_TAU_S`` (30 min) times each fix's gain, its drive-long 1-sigma per axis from
  its own report (``reported_drive_long_sigma``: the reported 1-sigma less the smoothed
  part, at most the budget's correlated range error times the DOP; the budget's 1.7 m per
  axis on open sky against a report of 1.0-1.5 m left the horizontal (error / sigma)^2 at
  0.07-0.9; a receiver reports 2-3 m while its Hatch filters converge, so the gain follows
  each fix rather than the first), plus white noise, the smoothed
  error's white equivalent in quadrature with the fix's reported accuracy beyond the budget
  (``excess_sigma``: the reflected signals of a canyon; ``std_*`` of ``gnss_fix``). The
  horizontal sigma was once the budget without the ionosphere (0.6 m of range error for the
  ``automotive`` receiver, 2.2 m with it) correlated over the carrier smoothing's 100 s: the
  smoother averaged a drive-long error away (the quickstart's north (error / sigma)^2 36, 29
  and 11 on three of eight seeds). Its NED
  velocity, a prior on V_k with the fix's own velocity accuracy (``std_vn, std_ve, std_vd``;
  0.1/0.1/0.2 m/s without them; the lever arm's rotation term left out: 0.3 m/s at most in a
  tight turn, inside the velocity sigma).
* Odometer and non-holonomic constraint at each keyframe: the body velocity at the rear axle,
  R^T v + w x r = (s, 0, 0), with the odometer's speed s, forward sigma 0.1 m/s + 3 % of s and
  the car body's lateral and vertical sigmas (``toolbox.constraints.NonholonomicNoise``), as a
  custom factor on (X_k, V_k).

``IncrementalFixedLagSmoother`` (iSAM2) keeps ``lag`` seconds of keyframes; the solution between
keyframes is the latest keyframe's estimate predicted with the IMU preintegrated since it, and
its std columns the keyframe's marginal covariance plus the preintegration's. Attitude sigmas
map the navigation-frame rotation covariance to ZYX Euler angles (``_euler_sigma``).

``fgo_tc`` is the same smoother on the raw measurements: each epoch's corrected pseudoranges
and pseudorange rates (``toolbox.gnss_model``: broadcast corrections, Sagnac rotation; the
L1/E1/B1 signals) against the antenna's position and velocity and a two-state receiver clock
per keyframe [c dt, c dt'] linked by the oscillator's process noise
(``gnss_model.clock_noise``); one clock, so the first system's satellites only. A
pseudorange's error is not white (docs/gnss-errors.md): taken as white with the receiver's
reported 1-sigma, the smoother averaged drive-long errors away (quickstart seed 1: down
(error / sigma)^2 26.8). Its drive-long parts are variables, as the tightly coupled filters
carry them as states (``tc_ekf``; Brown & Hwang, 4th ed., the augmented state of coloured
measurement noise), each a first-order Gauss-Markov process of ``RANGE_ERROR_TAU_S``:

* the broadcast ionosphere's relative residual common to the satellites, one variable with
  each satellite's broadcast delay I as its coefficient, 1-sigma |scale - 1| from the receiver
  datasheet's ``iono_scale`` (``simulator.datasheet.iono_residual_fractions``);
* the residual's smooth field over the sky (1-sigma f = scale ``iono_residual``): three
  variables shared by the satellites, the field's value and its north and east gradient at
  the receiver's zenith pierce point, with coefficients I rho (1, x_n / L, x_e / L) from each
  satellite's pierce-point offset x (``toolbox.iono_field``). A gradient across the sky is a
  range error growing with the direction to the satellite, which the position takes in
  whole; with the field taken as common plus an independent share per satellite
  (``IONO_FIELD_OWN_SHARE``), quickstart seed 2's east had (error / sigma)^2 15.4: a
  drive-long 2.2 m against a sigma of 0.5-0.7 m, the gradient's 2.3 m of east in the
  least-squares position (the simulated residual of each satellite, ``truth_gnss``);
* one per satellite: the signal-in-space error, the field's remainder f I sqrt(1 - rho^2
  (1 + |x|^2 / L^2)) and the troposphere's zenith residual over sin(elevation), in
  quadrature;
* the rest of the reported variance (code noise and multipath after the Hatch filter) white,
  inflated by the correlated-noise factor of the carrier-smoothing time
  (``gnss_model.correlated_noise_inflation``: the white noise of the same low-frequency
  spectrum); and the reflected-signal (NLOS) delay its C/N0 deficit announces, its expected
  value p mu taken off the pseudorange and its variance p (mu^2 + s^2) - (p mu)^2 added
  (``gnss_model.nlos_delay``, the model of the receiver's own fix accuracy; an extra path
  is never negative, and as a zero-mean p (20 m)^2 the unseen canyon's reflections sank
  the height: seed 2 height (error / sigma)^2 5.4 -> 3.8).

A range-error variable stands for ``RANGE_ERROR_STEP_S`` (its timestamp refreshed at each
use, so that the fixed-lag window keeps it), then a new one follows, linked by the process's
transition; one that left the window in an outage starts again from the stationary prior.
Range-rate sigma: the receiver's (at least 2 cm/s).

Public classes
--------------
FgoLooselyCoupled, FgoTightlyCoupled.
"""

from __future__ import annotations

import math
from dataclasses import replace
from functools import partial

import numpy as np

from estimators.base import Estimator
from estimators.toolbox.config_help import shared_help
from estimators.toolbox.constraints import NonholonomicNoise
from estimators.toolbox.datasheet import SCALE_FACTOR_TIME_S, FixAccuracy, fix_error_model
from estimators.toolbox.gnss_model import (
    clock_noise,
    nlos_delay,
    predict,
    raw_epoch,
    select,
    single_frequency,
)
from estimators.toolbox.installation import Installation
from estimators.toolbox.iono_field import SHARED_TERMS
from estimators.toolbox.range_budget import CORRELATION_TIME_S, range_budget
from simulator.datasheet import cn0_template
from simulator.earth import (
    OMEGA_E_RAD_S,
    dcm_to_euler,
    ecef_to_geodetic,
    ecef_to_ned,
    euler_to_dcm,
    geodetic_to_ecef,
    gravity_ned,
    ned_to_ecef_matrix,
)
from simulator.errors import InputError, Problem

BIAS_TIME_S = 300.0       # the bias instability taken as a random walk over this time
BIAS_WALK_FLOOR = 1e-16  # an ideal IMU's bias still walks a little (the information stays finite)
ODOMETER_FLOOR_M_S = 0.1
ODOMETER_SCALE = 0.03     # unmodelled odometer scale error, 1-sigma
FIX_VELOCITY_SIGMA_M_S = np.array([0.1, 0.1, 0.2])  # NED, without the fix's own std_v*
DEFAULT_DOP = 1.5
RANGE_ERROR_TAU_S = CORRELATION_TIME_S  # correlation time of the drive-long range errors
RANGE_ERROR_STEP_S = 5.0  # a range-error variable stands for this long (a constant meanwhile)

OUTPUT_COLUMNS = ("lat", "lon", "alt", "vn", "ve", "vd", "roll", "pitch", "yaw",
                  "std_n", "std_e", "std_d", "std_vn", "std_ve", "std_vd",
                  "std_roll", "std_pitch", "std_yaw",
                  "accel_bias_x", "accel_bias_y", "accel_bias_z",
                  "gyro_bias_x", "gyro_bias_y", "gyro_bias_z")


def _euler_sigma(roll: float, pitch: float, yaw: float, cov_psi: np.ndarray) -> np.ndarray:
    """1-sigma of roll, pitch, yaw from the covariance of a small rotation error psi resolved in
    the navigation frame: d(euler) = M psi with M the inverse of the Euler-rate matrix in the
    navigation frame (Groves 2013, eq. 2.58 written for psi^n)."""
    cy, sy = math.cos(yaw), math.sin(yaw)
    cp = max(math.cos(pitch), 1e-6)
    tp = math.sin(pitch) / cp
    m = np.array([[cy / cp, sy / cp, 0.0], [-sy, cy, 0.0], [cy * tp, sy * tp, 1.0]])
    return np.sqrt(np.maximum(np.diag(m @ cov_psi @ m.T), 0.0))


def _odometer_error(measured: np.ndarray, arm_term: np.ndarray, pose_key: int, vel_key: int,
                    this, values, jacobians):
    """Custom-factor error R^T v + w x r - (s, 0, 0) and its Jacobians (pose tangent:
    rotation first; R' = R Exp(d) gives d(R^T v) = (R^T v) x d)."""
    pose = values.atPose3(pose_key)
    v = values.atVector(vel_key)
    rot = pose.rotation().matrix()
    body = rot.T @ v
    if jacobians is not None:
        skew = np.array([[0.0, -body[2], body[1]], [body[2], 0.0, -body[0]],
                         [-body[1], body[0], 0.0]])
        jacobians[0] = np.hstack([skew, np.zeros((3, 3))])
        jacobians[1] = rot.T
    return body + arm_term - measured


class FgoLooselyCoupled(Estimator):
    """Fixed-lag factor-graph smoother: IMU preintegration, GNSS fixes, odometer and NHC."""

    name = "fgo_lc"
    needs = ("imu", "gnss_fix")
    uses = ("odometer",)
    paper = ("baseline: GTSAM fixed-lag smoother, IMU preintegration (Forster et al. 2017) "
             "with GNSS position/velocity, odometer and non-holonomic factors")
    defaults = {"lag": 10.0, "keyframe_interval": 1.0, "odometer": True, "nhc": True}
    config_help = {
        "lag": ("s", "keyframes the fixed-lag smoother keeps"),
        "keyframe_interval": ("s", "time between keyframes (and their GNSS fixes)"),
        "odometer": ("", "odometer speed factors, when the dataset has an odometer"),
        **shared_help("nhc"),
    }
    output_columns = OUTPUT_COLUMNS

    def setup(self) -> None:
        try:
            import gtsam
        except ImportError:
            raise InputError([Problem("fgo_lc", None, "", "needs GTSAM, which is not "
                                      "installed: pip install -e \".[fgo]\" (or pip install "
                                      "gtsam)")]) from None

        self._g = gtsam
        init = self.initial
        self._lat0, self._lon0, self._alt0 = (float(x) for x in init.position)
        self._origin = geodetic_to_ecef(self._lat0, self._lon0, self._alt0).ravel()
        self._c_ne0 = ned_to_ecef_matrix(self._lat0, self._lon0)
        self._g0 = gravity_ned(np.array([self._lat0]), np.array([self._alt0])).ravel()
        sheet = self.datasheet
        imu = sheet.get("imu") or {}
        gyro, accel = imu.get("gyro") or {}, imu.get("accel") or {}
        params = gtsam.PreintegrationCombinedParams.MakeSharedD(float(self._g0[2]))
        self._gyro_psd = max(_sheet_value(gyro, "noise_density"), 1e-5) ** 2
        self._accel_psd = max(_sheet_value(accel, "noise_density"), 1e-4) ** 2
        # scale factor, misalignment (each 1-sigma) and the gyro's g-sensitivity, as white
        # noise over SCALE_FACTOR_TIME_S (``_scale_noise``)
        self._gyro_scale = (_sheet_value(gyro, "scale_factor"),
                            _sheet_value(gyro, "misalignment"))
        self._accel_scale = (_sheet_value(accel, "scale_factor"),
                             _sheet_value(accel, "misalignment"))
        self._g_sensitivity = _sheet_value(gyro, "g_sensitivity")
        params.setGyroscopeCovariance(np.eye(3) * self._gyro_psd)
        params.setAccelerometerCovariance(np.eye(3) * self._accel_psd)
        params.setIntegrationCovariance(np.eye(3) * 1e-8)
        params.setBiasOmegaCovariance(np.eye(3) * _random_walk(gyro))
        params.setBiasAccCovariance(np.eye(3) * _random_walk(accel))
        w_ie = OMEGA_E_RAD_S * np.array([math.cos(self._lat0), 0.0, -math.sin(self._lat0)])
        params.setOmegaCoriolis(w_ie)
        self._params = params
        site = Installation.from_datasheet(sheet)
        self._antenna = site.antenna if site.antenna is not None else np.zeros(3)
        self._rear = site.rear_axle if site.rear_axle is not None else np.zeros(3)
        self._slip = NonholonomicNoise(site.wheelbase or 2.7)
        # the fix's error (``toolbox.datasheet.fix_error_model``, as the filters read it): the
        # drive-long part a first-order Gauss-Markov state per keyframe, the rest white
        self._fix_model = fix_error_model(sheet)
        self._e_key: int | None = None   # the last fix-error state, its time, value, covariance
        self._t_e = 0.0
        self._e_last = np.zeros(3)
        self._e_cov = np.zeros((3, 3))
        c = self.columns
        self._imu_cols = [c["imu"].get(a) for a in ("gyro_x", "gyro_y", "gyro_z", "accel_x",
                                                     "accel_y", "accel_z")]
        self._increments = self.imu_output == "increment"
        fix_cols = c.get("gnss_fix", {})
        self._fix_cols = [fix_cols.get(k) for k in ("lat", "lon", "alt", "vn", "ve", "vd",
                                                    "fix")]
        self._accuracy = FixAccuracy(fix_cols)
        self._hdop = fix_cols.get("hdop")
        self._vdop = fix_cols.get("vdop")
        self._speed_col = c.get("odometer", {}).get("speed")
        self._speeds: list[float] = []

        c_bn = euler_to_dcm(*init.attitude)
        pose = gtsam.Pose3(gtsam.Rot3(c_bn), np.zeros(3))
        vel = np.asarray(init.velocity, dtype=float)
        bias_sigma = np.r_[[max(float(accel.get("bias") or 0), 1e-3)] * 3,
                           [max(float(gyro.get("bias") or 0), 1e-5)] * 3]
        # QR: a MEMS bias walks 1e-5 of its turn-on range per keyframe, and Cholesky's
        # normal equations (the square of that ratio) are declared indeterminate
        isam = gtsam.ISAM2Params()
        isam.setFactorization("QR")
        self._smoother = gtsam.IncrementalFixedLagSmoother(float(self.config["lag"]), isam)
        graph = gtsam.NonlinearFactorGraph()
        values = gtsam.Values()
        stamps = {}
        k = 0
        graph.add(gtsam.PriorFactorPose3(self._x(k), pose, gtsam.noiseModel.Diagonal.Sigmas(
            np.r_[[math.radians(2.0)] * 2, math.radians(5.0), [5.0] * 3])))
        graph.add(gtsam.PriorFactorVector(self._v(k), vel,
                                          gtsam.noiseModel.Isotropic.Sigma(3, 0.5)))
        graph.add(gtsam.PriorFactorConstantBias(self._b(k), gtsam.imuBias.ConstantBias(),
                                                gtsam.noiseModel.Diagonal.Sigmas(bias_sigma)))
        values.insert(self._x(k), pose)
        values.insert(self._v(k), vel)
        values.insert(self._b(k), gtsam.imuBias.ConstantBias())
        for key in (self._x(k), self._v(k), self._b(k)):
            stamps[key] = init.t
        self._update(graph, values, stamps)
        self._k = 0
        self._t_key = init.t
        self._state = gtsam.NavState(pose, vel)
        self._bias = gtsam.imuBias.ConstantBias()
        self._pim = gtsam.PreintegratedCombinedMeasurements(params, self._bias)
        self._t_imu = init.t
        self._last_rate = np.zeros(3)
        self._last_force = np.zeros(3)
        self._cov = np.diag(np.r_[[math.radians(2.0)] * 2, math.radians(5.0), [5.0] * 3,
                                  [0.5] * 3]) ** 2
        self._first_output = True

    def _x(self, k: int) -> int:
        return self._g.symbol("x", k)

    def _v(self, k: int) -> int:
        return self._g.symbol("v", k)

    def _b(self, k: int) -> int:
        return self._g.symbol("b", k)

    def _e(self, k: int) -> int:
        return self._g.symbol("e", k)

    def _update(self, graph, values, stamps: dict[int, float]) -> None:
        stamp_map = self._g.FixedLagSmootherKeyTimestampMap()
        for key, t in stamps.items():
            stamp_map.insert((key, t))
        self._smoother.update(graph, values, stamp_map)

    def on_imu(self, t: float, row: np.ndarray) -> None:
        dt = t - self._t_imu
        if dt <= 0.0:
            return
        sample = np.array([row[i] if i is not None else 0.0 for i in self._imu_cols])
        if self._increments:
            sample = sample / dt
        rate, force = sample[:3], sample[3:]
        # the normal gravity at the current position, in the frame fixed at the origin, minus
        # the constant gravity of the preintegration, as seen in the body frame
        pos = self._state.pose().translation()
        lat, lon, alt = ecef_to_geodetic(self._origin + self._c_ne0 @ pos)
        g_here = self._c_ne0.T @ ned_to_ecef_matrix(lat, lon) @ gravity_ned(
            np.array([lat]), np.array([alt])).ravel()
        rot_t = self._state.pose().rotation().matrix().T
        force = force + rot_t @ (g_here - self._g0)
        motion = force + rot_t @ self._g0  # the specific force less gravity, body axes
        self._params.setGyroscopeCovariance(np.diag(
            self._gyro_psd + _scale_noise(self._gyro_scale, rate)
            + SCALE_FACTOR_TIME_S * (self._g_sensitivity**2) * float(motion @ motion)))
        self._params.setAccelerometerCovariance(np.diag(
            self._accel_psd + _scale_noise(self._accel_scale, motion)))
        self._pim.integrateMeasurement(force, rate, dt)
        self._t_imu = t
        self._last_rate, self._last_force = rate, force

    def on_odometer(self, t: float, row: np.ndarray) -> None:
        self._speeds.append(float(row[self._speed_col]))

    def on_gnss_fix(self, t: float, row: np.ndarray) -> None:
        lat, lon, alt, vn, ve, vd, fix = (float(row[i]) for i in self._fix_cols)
        if fix < 2 or not all(math.isfinite(x) for x in (lat, lon, alt)):
            if t - self._t_key >= float(self.config["keyframe_interval"]):
                self._keyframe(t, None)
            return
        self._keyframe(t, (lat, lon, alt, vn, ve, vd, row))

    def _keyframe(self, t: float, measurement: object | None) -> None:
        """A new keyframe at ``t``: the IMU factor since the last one, the GNSS factors of
        ``measurement`` (``_gnss_factors``), the odometer factor, the smoother's update."""
        gtsam = self._g
        if t - self._t_key < 1e-3 or self._pim.deltaTij() <= 0.0:
            return
        k = self._k + 1
        graph = gtsam.NonlinearFactorGraph()
        values = gtsam.Values()
        graph.add(gtsam.CombinedImuFactor(self._x(k - 1), self._v(k - 1), self._x(k),
                                          self._v(k), self._b(k - 1), self._b(k), self._pim))
        predicted = self._pim.predict(self._state, self._bias)
        values.insert(self._x(k), predicted.pose())
        values.insert(self._v(k), predicted.velocity())
        values.insert(self._b(k), self._bias)
        stamps = {self._x(k): t, self._v(k): t, self._b(k): t}
        if measurement is not None:
            self._gnss_factors(graph, values, stamps, k, t, measurement)
        if self._speeds and self.config["odometer"]:
            speed = float(np.mean(self._speeds))
            lateral, vertical = self._slip.sigma(speed, float(self._last_rate[2]),
                                                 float(self._last_force[0]))
            forward = ODOMETER_FLOOR_M_S + ODOMETER_SCALE * abs(speed)
            arm_term = np.cross(self._last_rate, self._rear)
            rows = [0, 1, 2] if self.config["nhc"] else [0]
            sigmas = np.array([forward, lateral, vertical])[rows]
            measured = np.array([speed, 0.0, 0.0])
            error = partial(_odometer_rows, rows, measured, arm_term, self._x(k), self._v(k))
            graph.add(gtsam.CustomFactor(gtsam.noiseModel.Diagonal.Sigmas(sigmas),
                                         [self._x(k), self._v(k)], error))
        self._speeds = []
        self._update(graph, values, stamps)
        estimate = self._smoother.calculateEstimate()
        self._state = gtsam.NavState(estimate.atPose3(self._x(k)),
                                     estimate.atVector(self._v(k)))
        self._bias = estimate.atConstantBias(self._b(k))
        if measurement is not None:
            self._after_gnss(estimate, k)
        cov_pose = self._smoother.marginalCovariance(self._x(k))
        cov_vel = self._smoother.marginalCovariance(self._v(k))
        rot = self._state.pose().rotation().matrix()
        cov = np.zeros((9, 9))
        cov[:3, :3] = rot @ cov_pose[:3, :3] @ rot.T        # attitude, navigation frame
        cov[3:6, 3:6] = rot @ cov_pose[3:, 3:] @ rot.T      # position (tangent in body axes)
        cov[6:, 6:] = cov_vel
        self._cov = cov
        self._pim.resetIntegrationAndSetBias(self._bias)
        self._k = k
        self._t_key = t

    def _gnss_factors(self, graph, values, stamps: dict, k: int, t: float,
                      fix: tuple) -> None:
        """The fix at the antenna with its Gauss-Markov error state, and its velocity."""
        gtsam = self._g
        lat, lon, alt, vn, ve, vd, row = fix
        ned = ecef_to_ned(geodetic_to_ecef(math.radians(lat), math.radians(lon), alt)
                          .reshape(1, 3), self._lat0, self._lon0, self._alt0).ravel()
        hdop = float(row[self._hdop]) if self._hdop is not None else math.nan
        vdop = float(row[self._vdop]) if self._vdop is not None else math.nan
        hdop = hdop if math.isfinite(hdop) else DEFAULT_DOP
        vdop = vdop if math.isfinite(vdop) else 2 * DEFAULT_DOP
        model = self._fix_model
        std_pos, std_vel = self._accuracy.read(row)
        gain = model.reported_drive_long_sigma(std_pos, hdop, vdop)  # e = gain u, u unit
        white = np.hypot(model.white_sigma(hdop, vdop), model.excess_sigma(std_pos, hdop, vdop))
        e_key = self._e(k)
        current = self._smoother.calculateEstimate()
        unit = np.ones(3)
        if self._e_key is None:
            graph.add(gtsam.PriorFactorVector(e_key, np.zeros(3),
                                              gtsam.noiseModel.Diagonal.Sigmas(unit)))
            values.insert(e_key, np.zeros(3))
        elif current.exists(self._e_key):
            phi = math.exp(-(t - self._t_e) / model.correlated_tau)
            graph.add(gtsam.CustomFactor(
                gtsam.noiseModel.Diagonal.Sigmas(unit * math.sqrt(1.0 - phi * phi)),
                [self._e_key, e_key], partial(_markov_error, phi, self._e_key, e_key)))
            values.insert(e_key, phi * current.atVector(self._e_key))
        else:  # the last error state left the window in an outage: its forecast as prior
            phi = math.exp(-(t - self._t_e) / model.correlated_tau)
            cov = phi * phi * self._e_cov + np.eye(3) * (1.0 - phi * phi)
            graph.add(gtsam.PriorFactorVector(e_key, phi * self._e_last,
                                              gtsam.noiseModel.Gaussian.Covariance(cov)))
            values.insert(e_key, phi * self._e_last)
        graph.add(gtsam.CustomFactor(
            gtsam.noiseModel.Diagonal.Sigmas(white),
            [self._x(k), e_key], partial(_fix_error, ned, self._antenna, gain, self._x(k),
                                         e_key)))
        self._e_key, self._t_e = e_key, t
        v_fix = np.array([vn, ve, vd])
        if np.isfinite(v_fix).all():
            graph.add(gtsam.PriorFactorVector(
                self._v(k), v_fix,
                gtsam.noiseModel.Diagonal.Sigmas(np.where(np.isfinite(std_vel), std_vel,
                                                          FIX_VELOCITY_SIGMA_M_S))))
        stamps[e_key] = t

    def _after_gnss(self, estimate, k: int) -> None:
        self._e_last = estimate.atVector(self._e_key)
        self._e_cov = self._smoother.marginalCovariance(self._e_key)

    def solution(self, t: float) -> list[float]:
        if t - self._t_key >= 2.0 * float(self.config["keyframe_interval"]):
            self._keyframe(t, None)  # a gap with no fix row at all: keep the graph growing
        state = self._pim.predict(self._state, self._bias) if self._pim.deltaTij() > 0 \
            else self._state
        rot = state.pose().rotation().matrix()
        cov = self._cov.copy()
        if self._pim.deltaTij() > 0:  # the preintegration's own covariance, rotated
            grow = self._pim.preintMeasCov()
            r0 = self._state.pose().rotation().matrix()
            cov[:3, :3] += r0 @ grow[:3, :3] @ r0.T
            cov[3:6, 3:6] += r0 @ grow[3:6, 3:6] @ r0.T
            cov[6:, 6:] += r0 @ grow[6:9, 6:9] @ r0.T
        ecef = self._origin + self._c_ne0 @ state.pose().translation()
        lat, lon, alt = ecef_to_geodetic(ecef)
        lat, lon, alt = float(lat), float(lon), float(alt)
        to_here = ned_to_ecef_matrix(lat, lon).T @ self._c_ne0  # origin NED -> local NED
        v = to_here @ state.velocity()
        c_bn = to_here @ rot
        roll, pitch, yaw = (float(a) for a in dcm_to_euler(c_bn))
        cov_att = to_here @ cov[:3, :3] @ to_here.T
        std_att = _euler_sigma(roll, pitch, yaw, cov_att)
        std_pos = np.sqrt(np.diag(to_here @ cov[3:6, 3:6] @ to_here.T))
        std_vel = np.sqrt(np.diag(to_here @ cov[6:, 6:] @ to_here.T))
        bias = self._bias
        return [math.degrees(lat), math.degrees(lon), alt, *v, roll, pitch, yaw, *std_pos,
                *std_vel, *std_att, *bias.accelerometer(), *bias.gyroscope()]


def _fix_error(measured: np.ndarray, arm: np.ndarray, gain: np.ndarray, pose_key: int,
               error_key: int, this, values, jacobians):
    """Custom-factor error of a fix: antenna position t + R l plus the fix's correlated error
    gain u (u the unit-variance error variable), minus the measured position; Jacobians on
    the pose tangent (rotation, translation; R' = R Exp(d) moves R l by -R [l x] d,
    t' = t + R dt) and on u."""
    pose = values.atPose3(pose_key)
    err = gain * values.atVector(error_key)
    rot = pose.rotation().matrix()
    if jacobians is not None:
        skew = np.array([[0.0, -arm[2], arm[1]], [arm[2], 0.0, -arm[0]],
                         [-arm[1], arm[0], 0.0]])
        jacobians[0] = np.hstack([-rot @ skew, rot])
        jacobians[1] = np.diag(gain)
    return pose.translation() + rot @ arm + err - measured


def _markov_error(phi: float, before: int, after: int, this, values, jacobians):
    """Custom-factor error of a first-order Gauss-Markov step: e_k - phi e_(k-1)."""
    if jacobians is not None:
        dim = len(values.atVector(after))
        jacobians[0] = -phi * np.eye(dim)
        jacobians[1] = np.eye(dim)
    return values.atVector(after) - phi * values.atVector(before)


def _odometer_rows(rows: list[int], measured: np.ndarray, arm_term: np.ndarray, pose_key: int,
                   vel_key: int, this, values, jacobians):
    """``_odometer_error`` on the rows in use (forward only without the NHC)."""
    full = [None, None] if jacobians is not None else None
    error = _odometer_error(measured, arm_term, pose_key, vel_key, this, values, full)
    if jacobians is not None:
        jacobians[0] = full[0][rows]
        jacobians[1] = full[1][rows]
    return error[rows]


def _sheet_value(group: dict, key: str) -> float:
    """A datasheet value as one number (the largest axis of a per-axis list), 0 when absent or
    given as a known value ({fixed: ...})."""
    value = group.get(key)
    if value is None or isinstance(value, dict):
        return 0.0
    return float(np.max(np.abs(np.atleast_1d(np.asarray(value, dtype=float)))))


def _scale_noise(scale: tuple[float, float], reading: np.ndarray) -> np.ndarray:
    """Per axis, the white-noise PSD of a triad's scale-factor error s and misalignment m
    (1-sigma each) on a reading x: the error s x_i + m (x_j, x_k) of axis i has the variance
    s^2 x_i^2 + m^2 (|x|^2 - x_i^2), taken as white over ``SCALE_FACTOR_TIME_S`` (PSD: that
    times the time; a constant error adds up over a turn or an acceleration, as the filters'
    datasheet tuning takes it, ``tc_ekf``)."""
    sf, mis = scale
    x2 = reading * reading
    return SCALE_FACTOR_TIME_S * (sf * sf * x2 + mis * mis * (float(x2.sum()) - x2))


def _random_walk(group: dict) -> float:
    """Continuous-time bias random-walk PSD from a datasheet group: the random walk's own PSD
    plus the bias instability B as a random walk over BIAS_TIME_S (2 B^2 / tau), at least
    ``BIAS_WALK_FLOOR``."""
    walk = float(group.get("random_walk") or 0.0) ** 2
    instability = 2.0 * float(group.get("bias_instability") or 0.0) ** 2 / BIAS_TIME_S
    return max(walk + instability, BIAS_WALK_FLOOR)


class FgoTightlyCoupled(FgoLooselyCoupled):
    """Fixed-lag factor-graph smoother on pseudoranges and pseudorange rates with receiver
    clock states, the pseudoranges' drive-long errors as variables (``toolbox.range_budget``), and
    ``fgo_lc``'s IMU, odometer and NHC factors."""

    name = "fgo_tc"
    needs = ("imu", "gnss_raw")
    uses = ("odometer",)
    paper = ("baseline: GTSAM fixed-lag smoother, IMU preintegration (Forster et al. 2017) "
             "with pseudorange, Doppler, clock, range-error, odometer and non-holonomic "
             "factors")
    defaults = {**FgoLooselyCoupled.defaults, "elevation_mask": 10.0}
    config_help = {**FgoLooselyCoupled.config_help,
                   "elevation_mask": ("deg", "satellites below this elevation are left out")}
    output_columns = OUTPUT_COLUMNS + ("clock_bias", "clock_drift")

    def setup(self) -> None:
        super().setup()
        self._raw = self.columns["gnss_raw"]
        self._mask = math.radians(float(self.config["elevation_mask"]))
        self._c_key: int | None = None
        self._t_c = 0.0
        self._c_last = np.zeros(2)
        self._c_cov = np.eye(2)
        gnss = self.datasheet.get("gnss") or {}
        self._budget = range_budget(gnss)
        self._template = cn0_template(gnss)
        self._chains = {}  # "iono" or a satellite -> (its current variable, created at)
        self._n_vars = 0

    def _c(self, k: int) -> int:
        return self._g.symbol("c", k)

    def on_gnss_fix(self, t: float, row: np.ndarray) -> None:
        """Not used: the tightly coupled smoother takes the raw measurements."""

    def on_gnss_raw(self, t: float, block: np.ndarray) -> None:
        cols = self._raw
        block = single_frequency(block, cols)
        if "health" in cols:
            block = block[block[:, cols["health"]] == 0]
        if "elevation" in cols:
            block = block[~(block[:, cols["elevation"]] < self._mask)]
        ep = raw_epoch(block, cols)
        ok = (np.isfinite(ep.pseudorange) & np.isfinite(ep.range_rate)
              & np.isfinite(ep.sat_pos).all(axis=1))
        codes = block[:, cols["system_code"]] if "system_code" in cols \
            else np.zeros(len(block))
        if ok.any():  # one clock: the first system's satellites only
            ok &= codes == codes[ok][0]
        if ok.sum() < 4:
            if t - self._t_key >= float(self.config["keyframe_interval"]):
                self._keyframe(t, None)
            return
        ep = select(ep, ok)
        shared, bias, white = self._budget.sigmas(ep)
        if self._template is not None and np.isfinite(ep.cn0).all():
            mean, variance = nlos_delay(ep.cn0, ep.elevation, self._template)
            ep = replace(ep, pseudorange=ep.pseudorange - mean)
            white = np.sqrt(white**2 + variance)
        sigma_rate = np.where(np.isfinite(ep.range_rate_std), ep.range_rate_std, 0.1)
        sats = codes[ok] * 1000 + ep.sv
        self._keyframe(t, (ep, sats, shared, bias, white, np.maximum(sigma_rate, 0.02)))

    def _chain(self, graph, values, stamps: dict, current, name: object, t: float,
               sigma: float) -> int:
        """The variable of a drive-long range error ``name`` at ``t`` (a first-order
        Gauss-Markov process of 1-sigma ``sigma``, correlation time ``RANGE_ERROR_TAU_S``):
        the chain's variable while it is younger than ``RANGE_ERROR_STEP_S`` (a constant over
        that step), else a new one linked to it by the process's transition, or a new one
        with the stationary prior when the chain is new or has left the window."""
        gtsam = self._g
        key, since = self._chains.get(name, (None, 0.0))
        if key is not None and current.exists(key) and t - since < RANGE_ERROR_STEP_S:
            stamps[key] = t
            return key
        self._n_vars += 1
        new = gtsam.symbol("r", self._n_vars)
        if key is not None and current.exists(key):
            phi = math.exp(-(t - since) / RANGE_ERROR_TAU_S)
            graph.add(gtsam.CustomFactor(
                gtsam.noiseModel.Isotropic.Sigma(1, sigma * math.sqrt(1.0 - phi * phi)),
                [key, new], partial(_markov_error, phi, key, new)))
            values.insert(new, phi * current.atVector(key))
        else:
            graph.add(gtsam.PriorFactorVector(new, np.zeros(1),
                                              gtsam.noiseModel.Isotropic.Sigma(1, sigma)))
            values.insert(new, np.zeros(1))
        self._chains[name] = (new, t)
        stamps[new] = t
        return new

    def _gnss_factors(self, graph, values, stamps: dict, k: int, t: float,
                      epoch: tuple) -> None:
        gtsam = self._g
        ep, sats, shared, bias, white, sigma_rate = epoch
        c_key = self._c(k)
        current = self._smoother.calculateEstimate()
        if self._c_key is None:
            pose = values.atPose3(self._x(k))
            antenna = self._origin + self._c_ne0 @ (pose.translation()
                                                    + pose.rotation().matrix() @ self._antenna)
            v_ecef = self._c_ne0 @ values.atVector(self._v(k))
            geometric, geometric_rate, _ = predict(ep.sat_pos, ep.sat_vel, antenna, v_ecef)
            start = np.array([np.median(ep.pseudorange - geometric),
                              np.median(ep.range_rate - geometric_rate)])
            graph.add(gtsam.PriorFactorVector(c_key, start,
                                              gtsam.noiseModel.Diagonal.Sigmas([30.0, 3.0])))
            values.insert(c_key, start)
        else:
            dt = t - self._t_c
            phi = np.array([[1.0, dt], [0.0, 1.0]])
            q = clock_noise(dt)
            if current.exists(self._c_key):
                graph.add(gtsam.CustomFactor(gtsam.noiseModel.Gaussian.Covariance(q),
                                             [self._c_key, c_key],
                                             partial(_clock_error, phi, self._c_key, c_key)))
                values.insert(c_key, phi @ current.atVector(self._c_key))
            else:  # the last clock state left the window: its forecast as prior
                graph.add(gtsam.PriorFactorVector(
                    c_key, phi @ self._c_last,
                    gtsam.noiseModel.Gaussian.Covariance(phi @ self._c_cov @ phi.T + q)))
                values.insert(c_key, phi @ self._c_last)
        keys = [self._x(k), self._v(k), c_key]
        gains = []  # per error variable: its coefficient on each pseudorange
        for name, used, gain in zip(SHARED_TERMS, self._budget.shared_in_use(), shared,
                                    strict=True):
            if used:
                keys.append(self._chain(graph, values, stamps, current, name, t, 1.0))
                gains.append(gain)
        for i, (sat, sigma) in enumerate(zip(sats, bias, strict=True)):
            if sigma > 0.0:
                keys.append(self._chain(graph, values, stamps, current, float(sat), t,
                                        float(sigma)))
                gains.append(np.eye(len(sats))[i])
        graph.add(gtsam.CustomFactor(
            gtsam.noiseModel.Diagonal.Sigmas(np.concatenate([white, sigma_rate])), keys,
            partial(_range_error, (ep.sat_pos, ep.sat_vel, ep.pseudorange, ep.range_rate),
                    np.array(gains).reshape(len(gains), len(sats)), self._antenna,
                    self._origin, self._c_ne0, keys)))
        stamps[c_key] = t
        self._c_key, self._t_c = c_key, t

    def _after_gnss(self, estimate, k: int) -> None:
        self._c_last = estimate.atVector(self._c_key)
        self._c_cov = self._smoother.marginalCovariance(self._c_key)

    def solution(self, t: float) -> list[float]:
        row = super().solution(t)
        if self._c_key is None:
            return [*row, math.nan, math.nan]
        dt = t - self._t_c
        return [*row, float(self._c_last[0] + self._c_last[1] * dt), float(self._c_last[1])]


def _clock_error(phi: np.ndarray, before: int, after: int, this, values, jacobians):
    """Custom-factor error of the two-state clock: c_k - Phi c_(k-1)."""
    if jacobians is not None:
        jacobians[0] = -phi
        jacobians[1] = np.eye(2)
    return values.atVector(after) - phi @ values.atVector(before)


def _range_error(epoch: tuple, gains: np.ndarray, arm: np.ndarray, origin: np.ndarray,
                 c_ne: np.ndarray, keys: list[int], this, values, jacobians):
    """Custom-factor error of an epoch's corrected pseudoranges and range rates against the
    antenna's state (``toolbox.gnss_model.predict``: Sagnac rotation, flight time), the clock
    [cb, d] and the drive-long range errors (keys after the pose, velocity and clock; row j of
    ``gains`` the coefficients of the j-th on the pseudoranges); Jacobians on the pose tangent
    (rotation, translation), the velocity, the clock and the range errors (the range rates'
    dependence on the position is left out: 1e-4 of theirs)."""
    sat_pos, sat_vel, rho, rate = epoch
    pose = values.atPose3(keys[0])
    rot = pose.rotation().matrix()
    v = values.atVector(keys[1])
    clock = values.atVector(keys[2])
    errors = np.array([values.atVector(key)[0] for key in keys[3:]])
    antenna = origin + c_ne @ (pose.translation() + rot @ arm)
    predicted, predicted_rate, los = predict(sat_pos, sat_vel, antenna, c_ne @ v,
                                             clock[0], clock[1])
    if len(errors):
        predicted = predicted + errors @ gains
    m = len(rho)
    if jacobians is not None:
        los_local = los @ c_ne  # (m, 3): unit vectors in the frame at the origin
        skew = np.array([[0.0, -arm[2], arm[1]], [arm[2], 0.0, -arm[0]],
                         [-arm[1], arm[0], 0.0]])
        pose_jac = np.zeros((2 * m, 6))
        pose_jac[:m, :3] = los_local @ rot @ skew
        pose_jac[:m, 3:] = -los_local @ rot
        vel_jac = np.zeros((2 * m, 3))
        vel_jac[m:] = -los_local
        clock_jac = np.zeros((2 * m, 2))
        clock_jac[:m, 0] = 1.0
        clock_jac[m:, 1] = 1.0
        jacobians[0] = pose_jac
        jacobians[1] = vel_jac
        jacobians[2] = clock_jac
        for j in range(len(errors)):
            column = np.zeros((2 * m, 1))
            column[:m, 0] = gains[j]
            jacobians[3 + j] = column
    return np.concatenate([predicted - rho, predicted_rate - rate])
