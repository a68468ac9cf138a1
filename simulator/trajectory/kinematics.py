"""Exact kinematics: from road geometry and speed profile to the truth table.

Everything is computed from the analytic road profile (piecewise polynomials), vectorised, never
by differencing samples:

* attitude: yaw = road heading psi(s), pitch = road grade angle gamma(s), roll = road bank minus a
  body roll proportional to the lateral acceleration (``limits.roll_gradient``);
* NED velocity v (cos g cos psi, cos g sin psi, -sin g), along the body x axis (no side slip), and
  its exact time derivative;
* geodetic position by integrating the NED velocity (Groves eq. 5.56) with Simpson's rule on the
  base grid, then cubic Hermite interpolation (with the exact derivatives) between grid points;
* specific force f^n = dv/dt - g^n + (w_en + 2 w_ie) x v (Groves eq. 5.54 rearranged) with WGS-84
  normal gravity, and body rate w_ib^b = w_nb^b + C_n^b (w_ie^n + w_en^n), where w_nb^b comes
  from the exact Euler-angle rates (Groves eq. 2.56 inverted).

Public names
------------
Kinematics, kinematics_from_profile.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.interpolate import CubicHermiteSpline

from simulator import columns as col
from simulator.earth import (
    earth_rate_ned,
    euler_to_dcm,
    gravity_ned,
    radii_of_curvature,
    transport_rate_ned,
    wrap_angle,
)
from simulator.timebase import utc_to_gps
from simulator.trajectory.segments import RoadProfile


@dataclass
class Origin:
    lat_deg: float
    lon_deg: float
    alt_m: float
    heading_deg: float


class Kinematics:
    """The exact truth trajectory of one drive; evaluates the truth columns at any times.

    Parameters
    ----------
    profile : RoadProfile
        Road geometry and speed profile.
    origin : Origin
        Start position and heading.
    rate_hz : float
        Base rate of the truth table (the grid used for the position integration).
    roll_gradient : float
        Body roll per lateral acceleration, rad per m/s^2.
    """

    def __init__(self, profile: RoadProfile, origin: Origin, rate_hz: float,
                 roll_gradient: float):
        self.profile = profile
        self.origin = origin
        self.rate_hz = float(rate_hz)
        self.roll_gradient = float(roll_gradient)
        self.duration_s = profile.duration_s
        n = int(np.floor(self.duration_s * self.rate_hz + 1e-9)) + 1
        self.t_grid = np.arange(n) / self.rate_hz
        self._breaks: np.ndarray | None = None
        # set by the dataset generator from the scenario: when the drive starts, and the
        # resolved ``environment`` block (zones and their sky, canyon and magnetic settings)
        self.utc_start: dt.datetime = dt.datetime(2020, 1, 1)
        self.gps_week, self.gps_tow = utc_to_gps(self.utc_start)
        self.environment: dict = {"zones": {}}
        self._integrate_position()

    # -- along-road quantities --------------------------------------------------------------
    def _motion(self, t: np.ndarray) -> dict[str, np.ndarray]:
        p = self.profile
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration_s)
        s = p.distance_of_time(t)
        v = np.maximum(p.distance_of_time(t, 1), 0.0)
        a = p.distance_of_time(t, 2)
        kappa, dkappa = p.curvature(s), p.curvature(s, 1)
        gamma, dgamma = p.grade(s), p.grade(s, 1)
        psi = np.radians(self.origin.heading_deg) + p.heading(s)
        bank, dbank = p.bank(s), p.bank(s, 1)
        cg, sg, cp, sp = np.cos(gamma), np.sin(gamma), np.cos(psi), np.sin(psi)
        u = np.stack([cg * cp, cg * sp, -sg], axis=-1)
        du_dpsi = np.stack([-cg * sp, cg * cp, np.zeros_like(cg)], axis=-1)
        du_dgamma = np.stack([-sg * cp, -sg * sp, -cg], axis=-1)
        yaw_rate = kappa * v
        pitch_rate = dgamma * v
        roll = bank - self.roll_gradient * v**2 * kappa
        roll_rate = dbank * v - self.roll_gradient * (2 * v * a * kappa + v**3 * dkappa)
        v_ned = v[:, None] * u
        a_ned = a[:, None] * u + v[:, None] * (du_dpsi * yaw_rate[:, None]
                                               + du_dgamma * pitch_rate[:, None])
        return dict(s=s, v=v, roll=roll, pitch=gamma, yaw=psi, roll_rate=roll_rate,
                    pitch_rate=pitch_rate, yaw_rate=yaw_rate, v_ned=v_ned, a_ned=a_ned)

    # -- position ---------------------------------------------------------------------------
    def _integrate_position(self) -> None:
        """Geodetic position on the grid: Simpson's rule on dlat/dt, dlon/dt, dh/dt.

        The integration grid is the base grid plus the drive's end time, so positions are
        exact up to the last instant of the drive.
        """
        t = self.t_grid
        if t[-1] < self.duration_s - 1e-9:
            t = np.append(t, self.duration_s)
        dt = np.diff(t)
        node = self._motion(t)["v_ned"]
        mid = self._motion(t[:-1] + dt / 2)["v_ned"]
        lat0, lon0 = np.radians(self.origin.lat_deg), np.radians(self.origin.lon_deg)

        def simpson(f_node: np.ndarray, f_mid: np.ndarray) -> np.ndarray:
            steps = dt / 6 * (f_node[:-1] + 4 * f_mid + f_node[1:])
            return np.concatenate([[0.0], np.cumsum(steps)])

        alt = self.origin.alt_m + simpson(-node[:, 2], -mid[:, 2])
        alt_mid = 0.5 * (alt[:-1] + alt[1:]) + dt / 8 * (node[1:, 2] - node[:-1, 2])
        lat = np.full_like(t, lat0)
        for _ in range(3):  # fixed point on the weak dependence of the radii on latitude
            lat_mid = 0.5 * (lat[:-1] + lat[1:])
            rn_node, _ = radii_of_curvature(lat)
            rn_mid, _ = radii_of_curvature(lat_mid)
            lat = lat0 + simpson(node[:, 0] / (rn_node + alt), mid[:, 0] / (rn_mid + alt_mid))
        lat_mid = 0.5 * (lat[:-1] + lat[1:])
        _, re_node = radii_of_curvature(lat)
        _, re_mid = radii_of_curvature(lat_mid)
        lon = lon0 + simpson(node[:, 1] / ((re_node + alt) * np.cos(lat)),
                             mid[:, 1] / ((re_mid + alt_mid) * np.cos(lat_mid)))
        rn, re = radii_of_curvature(lat)
        rates = np.stack([node[:, 0] / (rn + alt), node[:, 1] / ((re + alt) * np.cos(lat)),
                          -node[:, 2]], axis=-1)
        values = np.stack([lat, lon, alt], axis=-1)
        self._t_end = t[-1]
        if len(t) > 1:
            self._position = CubicHermiteSpline(t, values, rates, axis=0)
        else:
            self._position = lambda tt: np.repeat(values, np.size(tt), axis=0)

    def position(self, t: np.ndarray) -> np.ndarray:
        """Latitude (rad), longitude (rad), altitude (m) at times t, shape (n, 3)."""
        return np.atleast_2d(self._position(np.clip(np.asarray(t, float), 0.0, self._t_end)))

    # -- the truth columns ------------------------------------------------------------------
    def inertial(self, t: np.ndarray) -> dict[str, np.ndarray]:
        """Everything at times t: position, velocity, attitude, w_ib^b and f_ib^b (FRD)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        m = self._motion(t)
        pos = self.position(t)
        lat, alt = pos[:, 0], pos[:, 2]
        v_ned = m["v_ned"]
        w_ie = earth_rate_ned(lat)
        w_en = transport_rate_ned(lat, alt, v_ned)
        f_ned = m["a_ned"] - gravity_ned(lat, alt) + np.cross(w_en + 2 * w_ie, v_ned)
        c_bn = euler_to_dcm(m["roll"], m["pitch"], m["yaw"])
        f_body = np.einsum("nji,nj->ni", c_bn, f_ned)
        sr, cr = np.sin(m["roll"]), np.cos(m["roll"])
        sp, cp = np.sin(m["pitch"]), np.cos(m["pitch"])
        w_nb = np.stack([
            m["roll_rate"] - m["yaw_rate"] * sp,
            m["pitch_rate"] * cr + m["yaw_rate"] * cp * sr,
            -m["pitch_rate"] * sr + m["yaw_rate"] * cp * cr,
        ], axis=-1)
        w_body = w_nb + np.einsum("nji,nj->ni", c_bn, w_ie + w_en)
        return dict(t=t, lat=pos[:, 0], lon=pos[:, 1], alt=alt, v_ned=v_ned,
                    roll=m["roll"], pitch=m["pitch"], yaw=m["yaw"], w_body=w_body,
                    f_body=f_body, speed=m["v"], distance=m["s"])

    def breakpoints(self) -> np.ndarray:
        """Times where the piecewise kinematics switch polynomial pieces (rates may kink there).

        The speed profile's breaks, and the road profile's breaks in distance mapped to time.
        """
        if self._breaks is None:
            p = self.profile
            s_grid = p.distance_of_time(self.t_grid)
            s_breaks = np.unique(np.concatenate([p.curvature.x, p.grade.x, p.bank.x]))
            s_breaks = s_breaks[(s_breaks > 0) & (s_breaks < s_grid[-1])]
            t_breaks = np.interp(s_breaks, s_grid, self.t_grid)
            for _ in range(4):  # Newton on s(t) = s_b; the vehicle moves at every road break
                v = np.maximum(p.distance_of_time(t_breaks, 1), 1e-6)
                t_breaks = t_breaks - (p.distance_of_time(t_breaks) - s_breaks) / v
            self._breaks = np.unique(np.concatenate([p.distance_of_time.x, t_breaks]))
        return self._breaks

    def zone_at(self, t: np.ndarray) -> np.ndarray:
        """Zone name at times t ('' outside every zone); later zones win where they overlap."""
        t = np.atleast_1d(t)
        out = np.full(t.shape, "", dtype=object)
        for start, end, name in self.profile.zones:
            out[(t >= start) & (t < end)] = name
        return out

    def table(self, t: np.ndarray | None = None) -> pd.DataFrame:
        """The truth table (SPEC section 5 ``truth.parquet`` columns) at times t (default: grid)."""
        k = self.inertial(self.t_grid if t is None else t)
        return pd.DataFrame({
            "t": k["t"],
            "lat": np.degrees(k["lat"]),
            "lon": np.degrees(k["lon"]),
            "alt": k["alt"],
            "vn": k["v_ned"][:, 0], "ve": k["v_ned"][:, 1], "vd": k["v_ned"][:, 2],
            "roll": wrap_angle(k["roll"]), "pitch": k["pitch"], "yaw": wrap_angle(k["yaw"]),
            "wx": k["w_body"][:, 0], "wy": k["w_body"][:, 1], "wz": k["w_body"][:, 2],
            "fx": k["f_body"][:, 0], "fy": k["f_body"][:, 1], "fz": k["f_body"][:, 2],
            "speed": k["speed"], "distance": k["distance"],
            "zone": self.zone_at(k["t"]).astype(str),
        }, columns=list(col.TRUTH))


def kinematics_from_profile(profile: RoadProfile, start: dict, rate_hz: float,
                            roll_gradient: float) -> Kinematics:
    """Build the ``Kinematics`` of a road profile from a resolved scenario ``start`` block."""
    origin = Origin(start["lat"], start["lon"], start["alt"], start["heading"])
    return Kinematics(profile, origin, rate_hz, roll_gradient)
