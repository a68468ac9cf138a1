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
  the datasheet's turn-on bias as its prior. The normal-gravity change across the drive (the
  local vertical turns by d / R from the frame's origin) is added to each specific-force sample
  with the current attitude, so the constant gravity of the preintegration stays exact.
* GNSS: the fix's position at the antenna (the datasheet's lever arm) is the antenna's
  position plus the fix's own error, as the filters model it (``toolbox.datasheet.
  fix_error_model``): its drive-long part (the signal-in-space error and the ionosphere's
  residual, the budget's correlated range error times the DOP) a first-order Gauss-Markov
  state of correlation time ``CORRELATED_TAU_S`` (30 min), plus white noise, the smoothed
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
and pseudorange rates (``toolbox.gnss_model``: broadcast corrections, Sagnac rotation) against
the antenna's position and velocity and a two-state receiver clock per keyframe [c dt, c dt']
linked by the oscillator's process noise (``gnss_model.clock_noise``); code sigma the
receiver's reported one in quadrature with the horizontal UERE scaled by C/N0, range-rate sigma
the receiver's (at least 2 cm/s); one clock, so the first system's satellites only.

Public classes
--------------
FgoLooselyCoupled, FgoTightlyCoupled.
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np

from estimators.base import Estimator
from estimators.toolbox.config_help import shared_help
from estimators.toolbox.constraints import NonholonomicNoise
from estimators.toolbox.datasheet import FixAccuracy, fix_error_model
from estimators.toolbox.gnss_model import clock_noise, predict, raw_epoch
from estimators.toolbox.installation import Installation
from simulator.datasheet import fix_uere_m
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
DEFAULT_UERE_M = 3.0  # a datasheet without a receiver error budget
FIX_VELOCITY_SIGMA_M_S = np.array([0.1, 0.1, 0.2])  # NED, without the fix's own std_v*
DEFAULT_DOP = 1.5

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
        params.setGyroscopeCovariance(np.eye(3) * max(float(gyro.get("noise_density") or 0),
                                                      1e-5) ** 2)
        params.setAccelerometerCovariance(np.eye(3) * max(float(
            accel.get("noise_density") or 0), 1e-4) ** 2)
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
        force = force + self._state.pose().rotation().matrix().T @ (g_here - self._g0)
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
        sigma = model.correlated_sigma(hdop, vdop)
        std_pos, std_vel = self._accuracy.read(row)
        white = np.hypot(model.white_sigma(hdop, vdop), model.excess_sigma(std_pos, hdop, vdop))
        e_key = self._e(k)
        current = self._smoother.calculateEstimate()
        if self._e_key is None:
            graph.add(gtsam.PriorFactorVector(e_key, np.zeros(3),
                                              gtsam.noiseModel.Diagonal.Sigmas(sigma)))
            values.insert(e_key, np.zeros(3))
        elif current.exists(self._e_key):
            phi = math.exp(-(t - self._t_e) / model.correlated_tau)
            graph.add(gtsam.CustomFactor(
                gtsam.noiseModel.Diagonal.Sigmas(sigma * math.sqrt(1.0 - phi * phi)),
                [self._e_key, e_key], partial(_markov_error, phi, self._e_key, e_key)))
            values.insert(e_key, phi * current.atVector(self._e_key))
        else:  # the last error state left the window in an outage: its forecast as prior
            phi = math.exp(-(t - self._t_e) / model.correlated_tau)
            cov = phi * phi * self._e_cov + np.diag(sigma**2) * (1.0 - phi * phi)
            graph.add(gtsam.PriorFactorVector(e_key, phi * self._e_last,
                                              gtsam.noiseModel.Gaussian.Covariance(cov)))
            values.insert(e_key, phi * self._e_last)
        graph.add(gtsam.CustomFactor(
            gtsam.noiseModel.Diagonal.Sigmas(white),
            [self._x(k), e_key], partial(_fix_error, ned, self._antenna, self._x(k),
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


def _fix_error(measured: np.ndarray, arm: np.ndarray, pose_key: int, error_key: int,
               this, values, jacobians):
    """Custom-factor error of a fix: antenna position t + R l plus the fix's correlated error
    e, minus the measured position; Jacobians on the pose tangent (rotation, translation;
    R' = R Exp(d) moves R l by -R [l x] d, t' = t + R dt) and on e."""
    pose = values.atPose3(pose_key)
    err = values.atVector(error_key)
    rot = pose.rotation().matrix()
    if jacobians is not None:
        skew = np.array([[0.0, -arm[2], arm[1]], [arm[2], 0.0, -arm[0]],
                         [-arm[1], arm[0], 0.0]])
        jacobians[0] = np.hstack([-rot @ skew, rot])
        jacobians[1] = np.eye(3)
    return pose.translation() + rot @ arm + err - measured


def _markov_error(phi: float, before: int, after: int, this, values, jacobians):
    """Custom-factor error of a first-order Gauss-Markov step: e_k - phi e_(k-1)."""
    if jacobians is not None:
        jacobians[0] = -phi * np.eye(3)
        jacobians[1] = np.eye(3)
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


def _random_walk(group: dict) -> float:
    """Continuous-time bias random-walk PSD from a datasheet group: the random walk's own PSD
    plus the bias instability B as a random walk over BIAS_TIME_S (2 B^2 / tau), at least
    ``BIAS_WALK_FLOOR``."""
    walk = float(group.get("random_walk") or 0.0) ** 2
    instability = 2.0 * float(group.get("bias_instability") or 0.0) ** 2 / BIAS_TIME_S
    return max(walk + instability, BIAS_WALK_FLOOR)


class FgoTightlyCoupled(FgoLooselyCoupled):
    """Fixed-lag factor-graph smoother on pseudoranges and pseudorange rates with receiver
    clock states (``fgo_lc``'s IMU, odometer and NHC factors)."""

    name = "fgo_tc"
    needs = ("imu", "gnss_raw")
    uses = ("odometer",)
    paper = ("baseline: GTSAM fixed-lag smoother, IMU preintegration (Forster et al. 2017) "
             "with pseudorange, Doppler, clock, odometer and non-holonomic factors")
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
        self._sigma_floor = fix_uere_m(self.datasheet.get("gnss") or {}, ionosphere=False) \
            or DEFAULT_UERE_M

    def _c(self, k: int) -> int:
        return self._g.symbol("c", k)

    def on_gnss_fix(self, t: float, row: np.ndarray) -> None:
        """Not used: the tightly coupled smoother takes the raw measurements."""

    def on_gnss_raw(self, t: float, block: np.ndarray) -> None:
        cols = self._raw
        if "health" in cols:
            block = block[block[:, cols["health"]] == 0]
        if "elevation" in cols:
            block = block[~(block[:, cols["elevation"]] < self._mask)]
        ep = raw_epoch(block, cols)
        ok = (np.isfinite(ep.pseudorange) & np.isfinite(ep.range_rate)
              & np.isfinite(ep.sat_pos).all(axis=1))
        if "system_code" in cols:  # one clock: the first system's satellites only
            codes = block[:, cols["system_code"]]
            ok &= codes == codes[ok][0] if ok.any() else ok
        if ok.sum() < 4:
            if t - self._t_key >= float(self.config["keyframe_interval"]):
                self._keyframe(t, None)
            return
        cn0 = block[:, cols["cn0"]][ok] if "cn0" in cols else np.full(ok.sum(), 45.0)
        sigma_code = np.hypot(np.nan_to_num(ep.pseudorange_std[ok], nan=1.0),
                              self._sigma_floor / np.sqrt(np.clip(
                                  10 ** ((cn0 - 45.0) / 20.0), 0.1, 1.0)))
        sigma_rate = np.where(np.isfinite(ep.range_rate_std[ok]), ep.range_rate_std[ok], 0.1)
        self._keyframe(t, (ep.sat_pos[ok], ep.sat_vel[ok], ep.pseudorange[ok],
                           ep.range_rate[ok], sigma_code, np.maximum(sigma_rate, 0.02)))

    def _gnss_factors(self, graph, values, stamps: dict, k: int, t: float,
                      epoch: tuple) -> None:
        gtsam = self._g
        sat_pos, sat_vel, rho, rate, sigma_code, sigma_rate = epoch
        c_key = self._c(k)
        current = self._smoother.calculateEstimate()
        if self._c_key is None:
            pose = values.atPose3(self._x(k))
            antenna = self._origin + self._c_ne0 @ (pose.translation()
                                                    + pose.rotation().matrix() @ self._antenna)
            v_ecef = self._c_ne0 @ values.atVector(self._v(k))
            geometric, geometric_rate, _ = predict(sat_pos, sat_vel, antenna, v_ecef)
            start = np.array([np.median(rho - geometric), np.median(rate - geometric_rate)])
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
        sigma = np.concatenate([sigma_code, sigma_rate])
        graph.add(gtsam.CustomFactor(
            gtsam.noiseModel.Diagonal.Sigmas(sigma), [self._x(k), self._v(k), c_key],
            partial(_range_error, epoch[:4], self._antenna, self._origin, self._c_ne0,
                    self._x(k), self._v(k), c_key)))
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


def _range_error(epoch: tuple, arm: np.ndarray, origin: np.ndarray, c_ne: np.ndarray,
                 pose_key: int, vel_key: int, clock_key: int, this, values, jacobians):
    """Custom-factor error of an epoch's corrected pseudoranges and range rates against the
    antenna's state (``toolbox.gnss_model.predict``: Sagnac rotation, flight time) and the
    clock [cb, d]; Jacobians on the pose tangent (rotation, translation), the velocity and
    the clock (the range rates' dependence on the position is left out: 1e-4 of theirs)."""
    sat_pos, sat_vel, rho, rate = epoch
    pose = values.atPose3(pose_key)
    rot = pose.rotation().matrix()
    v = values.atVector(vel_key)
    clock = values.atVector(clock_key)
    antenna = origin + c_ne @ (pose.translation() + rot @ arm)
    predicted, predicted_rate, los = predict(sat_pos, sat_vel, antenna, c_ne @ v,
                                             clock[0], clock[1])
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
    return np.concatenate([predicted - rho, predicted_rate - rate])
