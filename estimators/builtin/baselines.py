"""Baseline estimators, the floor of every comparison.

* ``gnss_only`` is the receiver's own output between its fixes, as a receiver's 10 Hz output
  would give it: the last valid fix's position extrapolated with the fix's velocity, p(t) =
  p_fix + v_fix (t - t_fix) (the curvilinear position rates of Groves 2013 eq. 2.111, with the
  radii of curvature at the fix; the height with -v_d), for at most
  ``max_extrapolation`` seconds after the fix; later (a missed epoch, an outage) it reports
  nothing, which the scores count against its coverage. It does not know the attitude: roll,
  pitch and yaw are NaN (SPEC section 7). It initialises itself and reports nothing before the
  first fix.
* ``dead_reckoning`` is two-dimensional odometer/gyro dead reckoning with no GNSS (Groves 2013,
  section 6.3 (odometry, heading-and-distance form); the 2-D DR of Cho & Choi 2006,
  eqs. 24a-b and 24e, with the odometer giving the speed): the yaw integrates the z gyro,
  compensated for the Earth rate and the transport rate (Groves eqs. 5.41, 5.44) as seen by a
  level vehicle (refreshed at each odometer sample); the distance between odometer samples
  comes from their speeds interpolated linearly in time, laid along the yaw history of the IMU
  samples. The odometer speed is signed (negative while reversing), so a reversing car moves
  back along its heading. The height is held at its initial value and the down velocity is
  zero (it moves on the level of its start); roll and pitch, which it does not know, are NaN.

Public classes
--------------
GnssOnly, DeadReckoning.
"""

from __future__ import annotations

import math

import numpy as np

from estimators.base import Estimator
from simulator.earth import (
    earth_rate_ned,
    geodetic_rates,
    radii_of_curvature,
    transport_rate_ned,
    wrap_angle,
)


class GnssOnly(Estimator):
    """The last valid fix (``fix`` > 0) of the ``gnss_fix`` stream, extrapolated with its
    velocity for up to ``max_extrapolation`` seconds."""

    name = "gnss_only"
    needs = ("gnss_fix",)
    paper = "baseline: the receiver's own fixes, extrapolated with their velocity between epochs"
    initialises_itself = True
    # s after a fix during which it is extrapolated: bridges one missed epoch of a 1 Hz receiver
    defaults = {"max_extrapolation": 2.0}

    def setup(self) -> None:
        c = self.columns["gnss_fix"]
        self._pos = [c["lat"], c["lon"], c["alt"]]
        self._vel = [c["vn"], c["ve"], c["vd"]]
        self._fix = c["fix"]
        self._t_fix: float | None = None

    def on_gnss_fix(self, t: float, row: np.ndarray) -> None:
        # a fix without a horizontal velocity is not used; one without a vertical velocity
        # (a recording that does not log it) holds its height and writes vd as NaN
        if not (row[self._fix] > 0 and all(math.isfinite(row[i]) for i in (*self._pos,
                                                                              *self._vel[:2]))):
            return
        self._t_fix = t
        lat, lon, alt = (float(row[i]) for i in self._pos)
        self._vn, self._ve, self._vd = (float(row[i]) for i in self._vel)
        self._lat, self._lon, self._alt = math.radians(lat), math.radians(lon), alt
        r_n, r_e = radii_of_curvature(self._lat)
        # rad of latitude and longitude per second of the fix's north and east velocity
        self._lat_rate = self._vn / (float(r_n) + alt)
        self._lon_rate = self._ve / ((float(r_e) + alt) * math.cos(self._lat))

    def solution(self, t: float) -> list[float] | None:
        if self._t_fix is None or t - self._t_fix > self.config["max_extrapolation"]:
            return None
        dt = t - self._t_fix
        return [math.degrees(self._lat + self._lat_rate * dt),
                math.degrees(self._lon + self._lon_rate * dt),
                self._alt - (self._vd * dt if math.isfinite(self._vd) else 0.0),
                self._vn, self._ve, self._vd, math.nan, math.nan, math.nan]


class DeadReckoning(Estimator):
    """2-D odometer speed and yaw-gyro dead reckoning from the initial state, no GNSS."""

    name = "dead_reckoning"
    needs = ("imu", "odometer")
    paper = "Groves 2013 section 6.3; Cho & Choi 2006 eqs. 24a-b, 24e (2-D DR)"
    # earth_rate: compensate the Earth and transport rates in the yaw rate; standstill: while the
    # odometer reads exactly zero, hold the heading and learn the yaw-gyro bias as the mean of
    # its readings (a zero angular rate update, Groves 2013 section 15.3.3), removed once moving
    defaults = {"earth_rate": True, "standstill": True}

    def setup(self) -> None:
        init = self.initial
        self._lat, self._lon, self._alt = (float(x) for x in init.position)
        self._yaw = float(init.attitude[2])
        # signed speed along the heading (the odometer's convention: negative while reversing)
        self._speed = float(init.velocity[0] * math.cos(self._yaw)
                            + init.velocity[1] * math.sin(self._yaw))
        self._gz = self.columns["imu"]["gyro_z"]
        self._increments = self.imu_output == "increment"
        self._speed_col = self.columns["odometer"]["speed"]
        self._t_imu = init.t
        self._bias = 0.0  # yaw-gyro bias learned at standstill, rad/s
        self._still_sum = self._still_time = 0.0
        self._rate_prev: float | None = None
        self._t_odo: float | None = None
        # integrals since the last odometer sample of the unit heading vector, A = int u dt, and
        # of its time-weighted version, B = int u (t - t_odo) dt, north and east
        self._a_n = self._a_e = self._b_n = self._b_e = 0.0
        self._update_frame()

    def _update_frame(self) -> None:
        """Radii and the down component of the NED frame's rotation w.r.t. inertial space
        (Earth plus transport rate), refreshed at each odometer sample: they change slowly."""
        rn, re = radii_of_curvature(self._lat)
        self._rn, self._re = float(rn), float(re)
        v_ned = self._speed * np.array([math.cos(self._yaw), math.sin(self._yaw), 0.0])
        w_in = earth_rate_ned(self._lat) + transport_rate_ned(self._lat, self._alt, v_ned)
        self._frame_rate_d = float(w_in[0, 2]) if self.config["earth_rate"] else 0.0

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
        dpsi -= self._frame_rate_d * dt
        if self.config["standstill"] and self._t_odo is not None and self._speed == 0.0:
            self._still_sum += dpsi
            self._still_time += dt
            self._t_imu = t
            return
        dpsi -= self._bias * dt
        yaw_mid = self._yaw + 0.5 * dpsi
        self._yaw += dpsi
        c, s = math.cos(yaw_mid) * dt, math.sin(yaw_mid) * dt
        t_ref = self._t_odo if self._t_odo is not None else self._t_imu
        lag = 0.5 * (self._t_imu + t) - t_ref
        self._a_n += c
        self._a_e += s
        self._b_n += c * lag
        self._b_e += s * lag
        self._t_imu = t

    def _move(self, d_north: float, d_east: float) -> None:
        d_lat, d_lon, _ = geodetic_rates(self._lat, self._alt, (d_north, d_east, 0.0),
                                         (self._rn, self._re))
        self._lat += d_lat
        self._lon += d_lon

    def on_odometer(self, t: float, row: np.ndarray) -> None:
        speed = float(row[self._speed_col])
        if speed != 0.0 and self._still_time > 1.0:  # leaving a standstill of over a second
            self._bias = self._still_sum / self._still_time
        if speed != 0.0:
            self._still_sum = self._still_time = 0.0
        slope = 0.0  # before the first sample the initial speed was held
        if self._t_odo is not None and t > self._t_odo:
            slope = (speed - self._speed) / (t - self._t_odo)
        self._move(self._speed * self._a_n + slope * self._b_n,
                   self._speed * self._a_e + slope * self._b_e)
        self._a_n = self._a_e = self._b_n = self._b_e = 0.0
        self._speed = speed
        self._t_odo = t
        self._update_frame()

    def solution(self, t: float) -> list[float]:
        # the speed is held since the last odometer sample
        d_lat, d_lon, _ = geodetic_rates(self._lat, self._alt, (self._speed * self._a_n,
                                         self._speed * self._a_e, 0.0), (self._rn, self._re))
        lat, lon = self._lat + d_lat, self._lon + d_lon
        return [math.degrees(lat), math.degrees(lon), self._alt,
                self._speed * math.cos(self._yaw), self._speed * math.sin(self._yaw), 0.0,
                math.nan, math.nan, float(wrap_angle(self._yaw))]
