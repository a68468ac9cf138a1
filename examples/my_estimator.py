"""A third-party estimator, the worked example of docs/estimator_plugins.md (not part of landnav).

A loosely coupled odometer/gyro/GNSS extended Kalman filter in a local level plane. The state is
north and east position (m, from the start), yaw (rad) and the z gyro's bias (rad/s). It is
predicted with the odometer speed and the bias-corrected z gyro at the IMU rate, updated with
each GNSS position fix, and, while the odometer reads zero, with the z gyro itself, which then
measures its own bias (a zero angular rate update, Groves 2013 section 15.3.3). Compare the 2-D
DR/GPS filters of Cho & Choi 2006 (eqs. 24a-b, 24e) and Park et al. 2019.

Why the bias state: a MEMS gyro's turn-on bias (1 deg/s for the quickstart's Bosch SMI130) turns
the heading by a degree every second; without estimating it, the same filter ends 82 m RMS off
on the quickstart drive.

Run it with ``landnav estimate DATASET -e examples.my_estimator:MyEstimator -o sol.parquet``
from a directory where ``examples`` is importable.
"""

from __future__ import annotations

import math

import numpy as np

from estimators.base import NAV_COLUMNS, Estimator
from estimators.toolbox.kalman import predict, update
from simulator.earth import radii_of_curvature


class MyEstimator(Estimator):
    name = "my_estimator"
    needs = ("imu", "odometer")
    uses = ("gnss_fix",)
    paper = "example: 2-D DR/GNSS EKF with a gyro-bias state, after Cho & Choi 2006"
    defaults = {"gnss_sigma": 3.0, "speed_sigma": 0.1, "gyro_psd": 1e-3, "yaw_sigma0": 0.05,
                "bias_sigma0": 0.02, "bias_psd": 1e-5}
    config_help = {  # key -> (SI unit, meaning), shown by `landnav estimators NAME`
        "gnss_sigma": ("m", "GNSS horizontal position noise, 1-sigma"),
        "speed_sigma": ("m/s", "odometer speed noise, 1-sigma"),
        "gyro_psd": ("rad/s/sqrt(Hz)", "z-gyro white noise"),
        "yaw_sigma0": ("rad", "initial yaw uncertainty, 1-sigma"),
        "bias_sigma0": ("rad/s", "z-gyro turn-on bias, 1-sigma"),
        "bias_psd": ("rad/s^2/sqrt(Hz)", "z-gyro bias random walk"),
    }
    output_columns = (*NAV_COLUMNS, "std_n", "std_e", "std_yaw", "gyro_bias_z")

    def setup(self) -> None:
        lat0, lon0, self.alt = self.initial.position
        self.lat0, self.lon0 = lat0, lon0
        rn, re = radii_of_curvature(lat0)
        self.m_per_rad = np.array([rn + self.alt, (re + self.alt) * math.cos(lat0)])
        self.x = np.array([0.0, 0.0, self.initial.attitude[2], 0.0])  # n, e, yaw, gyro bias
        self.p = np.diag([0.0, 0.0, self.config["yaw_sigma0"] ** 2,
                          self.config["bias_sigma0"] ** 2])
        self.speed = float(np.hypot(*self.initial.velocity[:2]))
        self.t = self.initial.t
        self.gz = self.columns["imu"]["gyro_z"]
        self.increments = self.imu_output == "increment"
        self.v = self.columns["odometer"]["speed"]
        if "gnss_fix" in self.columns:
            g = self.columns["gnss_fix"]
            self.fix, self.lat, self.lon = g["fix"], g["lat"], g["lon"]

    def on_imu(self, t: float, row: np.ndarray) -> None:
        dt, self.t = t - self.t, t
        if dt <= 0:
            return
        rate = row[self.gz] / dt if self.increments else row[self.gz]  # z gyro, rad/s
        if self.speed == 0.0:  # standing still: the gyro measures its own bias
            r = self.config["gyro_psd"] ** 2 / dt
            self.x, self.p, _ = update(self.x, self.p, np.array([rate - self.x[3]]),
                                       np.array([[0.0, 0.0, 0.0, 1.0]]), r)
        dpsi = (rate - self.x[3]) * dt
        yaw = self.x[2] + 0.5 * dpsi
        c, s = math.cos(yaw), math.sin(yaw)
        f = np.array([[1.0, 0.0, -self.speed * s * dt, 0.0],
                      [0.0, 1.0, self.speed * c * dt, 0.0],
                      [0.0, 0.0, 1.0, -dt],
                      [0.0, 0.0, 0.0, 1.0]])
        q = np.diag([(self.config["speed_sigma"] * dt) ** 2] * 2
                    + [self.config["gyro_psd"] ** 2 * dt, self.config["bias_psd"] ** 2 * dt])
        _, self.p = predict(self.x, self.p, f, q)
        self.x = self.x + np.array([self.speed * c * dt, self.speed * s * dt, dpsi, 0.0])

    def on_odometer(self, t: float, row: np.ndarray) -> None:
        self.speed = float(row[self.v])

    def on_gnss_fix(self, t: float, row: np.ndarray) -> None:
        if row[self.fix] <= 0:
            return
        z = (np.radians([row[self.lat], row[self.lon]]) - [self.lat0, self.lon0]) * self.m_per_rad
        h = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])
        r = np.eye(2) * self.config["gnss_sigma"] ** 2
        self.x, self.p, _ = update(self.x, self.p, z - h @ self.x, h, r)

    def solution(self, t: float) -> list[float]:
        lat, lon = np.degrees(np.array([self.lat0, self.lon0]) + self.x[:2] / self.m_per_rad)
        yaw = self.x[2]
        std = np.sqrt(np.diag(self.p))
        # a 2-D filter: no vertical velocity, roll or pitch estimate, so NaN (never a made-up 0)
        vn, ve = self.speed * math.cos(yaw), self.speed * math.sin(yaw)
        return [lat, lon, self.alt, vn, ve, math.nan, math.nan, math.nan,
                math.atan2(math.sin(yaw), math.cos(yaw)), std[0], std[1], std[2], self.x[3]]
