"""Baseline estimators, the floor of every comparison.

* ``gnss_only`` holds the last GNSS fix: position and velocity of the fix, yaw from its course
  over ground (held while the speed is below ``min_course_speed``), roll and pitch zero. It
  initialises itself and reports nothing before the first fix.
* ``dead_reckoning`` is two-dimensional odometer/gyro dead reckoning with no GNSS (Groves 2013,
  section 6.3 (odometry, heading-and-distance form); the 2-D DR of Cho & Choi 2006,
  eqs. 24a-b and 24e, with the odometer giving the speed): the yaw integrates the z gyro,
  compensated for the Earth rate and the transport rate (Groves eqs. 5.41, 5.44) as seen by a
  level vehicle; the distance between odometer samples comes from their speeds interpolated
  linearly in time, laid along the yaw history of the IMU samples. The height is held at its
  initial value, roll and pitch are reported as zero.

Public classes
--------------
GnssOnly, DeadReckoning.
"""

from __future__ import annotations

import math

import numpy as np

from estimators.base import Estimator
from simulator.earth import OMEGA_E_RAD_S, radii_of_curvature, wrap_angle


class GnssOnly(Estimator):
    """Hold the last valid fix (``fix`` > 0) of the ``gnss_fix`` stream."""

    name = "gnss_only"
    needs = ("gnss_fix",)
    paper = "baseline: the receiver's own fixes, held between epochs"
    initialises_itself = True
    defaults = {"min_course_speed": 1.0}  # m/s; below it the course is too noisy for yaw

    def setup(self) -> None:
        c = self.columns["gnss_fix"]
        self._pos = [c["lat"], c["lon"], c["alt"]]
        self._vel = [c["vn"], c["ve"], c["vd"]]
        self._fix, self._speed, self._course = c["fix"], c["speed"], c["course"]
        self._state: list[float] | None = None
        self._yaw = 0.0

    def on_gnss_fix(self, t: float, row: np.ndarray) -> None:
        if not (row[self._fix] > 0 and math.isfinite(row[self._pos[0]])):
            return
        if row[self._speed] >= self.config["min_course_speed"]:
            self._yaw = float(wrap_angle(row[self._course]))
        self._state = [*(float(row[i]) for i in self._pos), *(float(row[i]) for i in self._vel),
                       0.0, 0.0, self._yaw]

    def solution(self, t: float) -> list[float] | None:
        return self._state


class DeadReckoning(Estimator):
    """2-D odometer speed and yaw-gyro dead reckoning from the initial state, no GNSS."""

    name = "dead_reckoning"
    needs = ("imu", "odometer")
    paper = "Groves 2013 section 6.3; Cho & Choi 2006 eqs. 24a-b, 24e (2-D DR)"
    defaults = {"earth_rate": True}  # compensate the Earth and transport rates in the yaw rate

    def setup(self) -> None:
        init = self.initial
        self._lat, self._lon, self._alt = (float(x) for x in init.position)
        self._yaw = float(init.attitude[2])
        self._speed = float(math.hypot(init.velocity[0], init.velocity[1]))
        self._gz = self.columns["imu"]["gyro_z"]
        self._increments = self.units["imu"].get("gyro_z") == "rad"
        self._speed_col = self.columns["odometer"]["speed"]
        self._t_imu = init.t
        self._rate_prev: float | None = None
        self._t_odo: float | None = None
        # integrals since the last odometer sample of the unit heading vector, A = int u dt, and
        # of its time-weighted version, B = int u (t - t_odo) dt, north and east
        self._a = np.zeros(2)
        self._b = np.zeros(2)
        rn, re = radii_of_curvature(self._lat)
        self._rn, self._re = float(rn), float(re)

    def _level_frame_rate(self) -> float:
        """Down component of the NED frame's rotation rate w.r.t. inertial space, rad/s."""
        ve = self._speed * math.sin(self._yaw)
        return -OMEGA_E_RAD_S * math.sin(self._lat) - ve * math.tan(self._lat) / (
            self._re + self._alt)

    def on_imu(self, t: float, row: np.ndarray) -> None:
        dt = t - self._t_imu
        if self._increments:
            dpsi = float(row[self._gz]) if dt > 0 else 0.0
        else:
            rate = float(row[self._gz])
            prev = rate if self._rate_prev is None else self._rate_prev
            dpsi = 0.5 * (prev + rate) * dt
            self._rate_prev = rate
        if dt <= 0:
            return
        if self.config["earth_rate"]:
            dpsi -= self._level_frame_rate() * dt
        yaw_mid = self._yaw + 0.5 * dpsi
        self._yaw += dpsi
        u = np.array([math.cos(yaw_mid), math.sin(yaw_mid)])
        t_ref = self._t_odo if self._t_odo is not None else self._t_imu
        self._a += u * dt
        self._b += u * (0.5 * (self._t_imu + t) - t_ref) * dt
        self._t_imu = t

    def _move(self, d_north: float, d_east: float) -> None:
        self._lat += d_north / (self._rn + self._alt)
        self._lon += d_east / ((self._re + self._alt) * math.cos(self._lat))
        rn, re = radii_of_curvature(self._lat)
        self._rn, self._re = float(rn), float(re)

    def on_odometer(self, t: float, row: np.ndarray) -> None:
        speed = float(row[self._speed_col])
        if self._t_odo is None:  # before the first sample the initial speed was held
            self._move(*(self._speed * self._a))
        else:
            span = t - self._t_odo
            slope = (speed - self._speed) / span if span > 0 else 0.0
            self._move(*(self._speed * self._a + slope * self._b))
        self._a[:] = 0.0
        self._b[:] = 0.0
        self._speed = speed
        self._t_odo = t

    def solution(self, t: float) -> list[float]:
        d_north, d_east = self._speed * self._a  # held speed since the last odometer sample
        lat = self._lat + d_north / (self._rn + self._alt)
        lon = self._lon + d_east / ((self._re + self._alt) * math.cos(lat))
        return [math.degrees(lat), math.degrees(lon), self._alt,
                self._speed * math.cos(self._yaw), self._speed * math.sin(self._yaw), 0.0,
                0.0, 0.0, float(wrap_angle(self._yaw))]
