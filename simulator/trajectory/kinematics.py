"""Exact kinematics: from road geometry and speed profile to the truth table.

Everything is computed from the analytic road profile (piecewise polynomials), vectorised, never
by differencing samples:

* attitude: yaw = road heading psi(s), pitch = road grade angle gamma(s), roll = road bank minus a
  body roll proportional to the lateral acceleration (``limits.roll_gradient``);
* NED velocity d v (cos g cos psi, cos g sin psi, -sin g), along the body x axis (no side slip),
  and its exact time derivative; v = ds/dt >= 0 is the speed along the path and d = +1 forward,
  -1 reversing (``RoadProfile.direction``, constant between standstills), so a reversing car
  moves along -x body while its attitude, a function of s, stays continuous. The yaw rate is
  kappa v (psi is a function of s, whichever way the car rolls), the lateral acceleration
  d kappa v^2; the truth ``speed`` is the signed speed d v along body x;
* geodetic position by integrating the NED velocity (Groves eq. 5.56) with the cubic rule on the
  base grid's samples (``quadrature``), then cubic Hermite interpolation (with the exact
  derivatives) between grid points;
* specific force f^n = dv/dt - g^n + (w_en + 2 w_ie) x v (Groves eq. 5.54 rearranged) with WGS-84
  normal gravity, and body rate w_ib^b = w_nb^b + C_n^b (w_ie^n + w_en^n), where w_nb^b comes
  from the exact Euler-angle rates (Groves eq. 2.56 inverted).

The truth table is ``Kinematics.columns`` (a column table of ``simulator.tables``, what the
dataset writer takes, without pandas) or ``Kinematics.table`` (the same as a DataFrame).

Public names
------------
Kinematics, kinematics_from_profile.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from simulator import columns as col
from simulator.earth import (
    OMEGA_E_RAD_S,
    normal_gravity,
    radii_of_curvature,
    wrap_angle,
)
from simulator.earth import ned_to_body_trig as ned_to_body
from simulator.tables import ColumnTable
from simulator.timebase import utc_to_gps
from simulator.trajectory.piecewise import PiecewisePolynomial
from simulator.trajectory.quadrature import GL_NODES, GL_WEIGHTS, cubic_interval_integrals
from simulator.trajectory.segments import RoadProfile

if TYPE_CHECKING:
    import pandas as pd


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
        self.profile = _as_fast(profile)
        curves = (self.profile.curvature, self.profile.grade, self.profile.bank,
                  self.profile.heading)
        self._shared_breaks = all(np.array_equal(c.x, curves[0].x) for c in curves)
        self.origin = origin
        self.rate_hz = float(rate_hz)
        self.roll_gradient = float(roll_gradient)
        self.duration_s = profile.duration_s
        n = int(np.floor(self.duration_s * self.rate_hz + 1e-9)) + 1
        self.t_grid = np.arange(n) / self.rate_hz
        self._breaks: np.ndarray | None = None
        self._cache: dict[str, dict] = {}
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
        s, v, a = p.distance_of_time.evaluate(t, (0, 1, 2))
        v = np.maximum(v, 0.0)
        d = p.direction_at(t)  # +1 forward, -1 reversing: switches only where v = a = 0
        # the road curves of a parametric drive share their breakpoints: one search serves all
        idx = p.curvature.piece_index(s) if self._shared_breaks else None
        kappa, dkappa = p.curvature.evaluate(s, (0, 1), idx)
        gamma, dgamma = p.grade.evaluate(s, (0, 1), idx)
        bank, dbank = p.bank.evaluate(s, (0, 1), idx)
        psi = np.radians(self.origin.heading_deg) + p.heading.evaluate(s, (0,), idx)[0]
        cg, sg, cp, sp = np.cos(gamma), np.sin(gamma), np.cos(psi), np.sin(psi)
        yaw_rate = kappa * v
        pitch_rate = dgamma * v
        # body roll against the lateral acceleration d kappa v^2 (and its exact rate, d constant)
        roll = bank - self.roll_gradient * d * v**2 * kappa
        roll_rate = dbank * v - self.roll_gradient * d * (2 * v * a * kappa + v**3 * dkappa)
        dv, da = d * v, d * a  # signed speed and acceleration along body x
        v_ned = np.empty(t.shape + (3,))
        v_ned[:, 0] = dv * cg * cp
        v_ned[:, 1] = dv * cg * sp
        v_ned[:, 2] = -dv * sg
        # d/dt of d v u(psi, gamma): d (a u + v (du/dpsi psi' + du/dgamma gamma'))
        a_ned = np.empty_like(v_ned)
        a_ned[:, 0] = da * cg * cp - dv * (cg * sp * yaw_rate + sg * cp * pitch_rate)
        a_ned[:, 1] = da * cg * sp + dv * (cg * cp * yaw_rate - sg * sp * pitch_rate)
        a_ned[:, 2] = -da * sg - dv * cg * pitch_rate
        # + 0.0: a reversing car at rest reads 0.0, not -0.0
        return dict(s=s, v=dv + 0.0, roll=roll, pitch=gamma, yaw=psi, roll_rate=roll_rate,
                    pitch_rate=pitch_rate, yaw_rate=yaw_rate, v_ned=v_ned, a_ned=a_ned,
                    cos_pitch=cg, sin_pitch=sg, cos_yaw=cp, sin_yaw=sp)

    # -- position ---------------------------------------------------------------------------
    def _integrate_position(self) -> None:
        """Geodetic position on the grid: dlat/dt, dlon/dt, dh/dt (Groves eq. 5.56) integrated
        interval by interval with the cubic rule on the grid samples (``quadrature``), and with
        three-point Gauss-Legendre on the analytic velocity where the grid is too short for it
        and over the last, partial interval up to the drive's end.
        """
        t = self.t_grid
        h = 1.0 / self.rate_hz
        motion = self._motion(t)
        self._motion_cache = {"grid": motion}  # reused by ``grid_inertial``
        v = motion["v_ned"]
        if t[-1] < self.duration_s - 1e-9:  # the drive ends between two grid points
            t = np.append(t, self.duration_s)
            v = np.vstack([v, self._motion(t[-1:])["v_ned"]])
        lat0, lon0 = np.radians(self.origin.lat_deg), np.radians(self.origin.lon_deg)

        def integrate(rate_of) -> np.ndarray:
            """Cumulative integral of rate_of(times, v_ned, index) over the nodes."""
            values = rate_of(t, v, np.arange(len(t)))
            n_uniform = len(self.t_grid)
            steps = np.empty(len(t) - 1)
            if n_uniform >= 4:
                steps[:n_uniform - 1] = cubic_interval_integrals(values[:n_uniform], h)
                first_gauss = n_uniform - 1
            else:
                first_gauss = 0
            if first_gauss < len(t) - 1:
                a, b = t[first_gauss:-1], t[first_gauss + 1:]
                nodes = (a[:, None] + (b - a)[:, None] * GL_NODES[None, :]).ravel()
                owner = np.repeat(np.arange(first_gauss, len(t) - 1), len(GL_NODES))
                at_nodes = rate_of(nodes, self._motion(nodes)["v_ned"], owner)
                steps[first_gauss:] = (b - a) * (at_nodes.reshape(-1, len(GL_NODES))
                                                 @ GL_WEIGHTS)
            return np.concatenate([[0.0], np.cumsum(steps)])

        alt = self.origin.alt_m + integrate(lambda tt, vv, i: -vv[:, 2])
        lat = np.full_like(t, lat0)

        def between(nodes_value: np.ndarray, tt: np.ndarray, i: np.ndarray) -> np.ndarray:
            # node values at the nodes; linear between them (the radii vary slowly)
            j = np.minimum(i, len(t) - 2)
            u = (tt - t[j]) / (t[j + 1] - t[j])
            return nodes_value[j] + u * (nodes_value[j + 1] - nodes_value[j])

        for _ in range(2):  # fixed point on the weak dependence of the radii on latitude
            lat_prev = lat
            lat = lat0 + integrate(lambda tt, vv, i, lat_prev=lat_prev: vv[:, 0] / (
                radii_of_curvature(between(lat_prev, tt, i))[0] + between(alt, tt, i)))
        lon = lon0 + integrate(lambda tt, vv, i: vv[:, 1] / (
            (radii_of_curvature(between(lat, tt, i))[1] + between(alt, tt, i))
            * np.cos(between(lat, tt, i))))
        rn, re = radii_of_curvature(lat)
        rates = np.stack([v[:, 0] / (rn + alt), v[:, 1] / ((re + alt) * np.cos(lat)), -v[:, 2]],
                         axis=-1)
        self._t_int = t
        self._pos_values = np.stack([lat, lon, alt], axis=-1)
        self._pos_rates = rates

    def position(self, t: np.ndarray) -> np.ndarray:
        """Latitude (rad), longitude (rad), altitude (m) at times t, shape (n, 3).

        Cubic Hermite interpolation between integration nodes with the exact rates, so the
        interpolation error is O(dt^4) (far below a millimetre at the base rate).
        """
        t = np.clip(np.atleast_1d(np.asarray(t, float)), 0.0, self._t_int[-1])
        if len(self._t_int) == 1:
            return np.repeat(self._pos_values, len(t), axis=0)
        i = np.clip(np.searchsorted(self._t_int, t, side="right") - 1, 0, len(self._t_int) - 2)
        h = (self._t_int[i + 1] - self._t_int[i])[:, None]
        u = ((t - self._t_int[i]) / h[:, 0])[:, None]
        u2, u3 = u * u, u * u * u
        return ((2 * u3 - 3 * u2 + 1) * self._pos_values[i]
                + (u3 - 2 * u2 + u) * h * self._pos_rates[i]
                + (-2 * u3 + 3 * u2) * self._pos_values[i + 1]
                + (u3 - u2) * h * self._pos_rates[i + 1])

    # -- the truth columns ------------------------------------------------------------------
    def inertial(self, t: np.ndarray, motion: dict | None = None,
                 position: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """Everything at times t: position, velocity, attitude, w_ib^b and f_ib^b (FRD).

        f^n = dv/dt - g^n + (w_en + 2 w_ie) x v (Groves eq. 5.54) and
        w_ib^b = w_nb^b + C_n^b (w_ie + w_en), written component-wise for speed.
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        m = self._motion(t) if motion is None else motion
        pos = self.position(t) if position is None else position
        lat, alt = pos[:, 0], pos[:, 2]
        v = m["v_ned"]
        rn, re = radii_of_curvature(lat)
        cos_lat, sin_lat = np.cos(lat), np.sin(lat)
        # Earth rate (Groves eq. 5.41) and transport rate (eq. 5.44) in NED
        rate_n = v[:, 1] / (re + alt)
        rate_e = -v[:, 0] / (rn + alt)
        rate_d = -rate_n * sin_lat / cos_lat
        ie_n, ie_d = OMEGA_E_RAD_S * cos_lat, -OMEGA_E_RAD_S * sin_lat
        w_in = np.stack([ie_n + rate_n, rate_e, ie_d + rate_d], axis=-1)
        cn, ce, cd = 2 * ie_n + rate_n, rate_e, 2 * ie_d + rate_d  # w_en + 2 w_ie
        f_ned = m["a_ned"].copy()
        f_ned[:, 0] += ce * v[:, 2] - cd * v[:, 1]
        f_ned[:, 1] += cd * v[:, 0] - cn * v[:, 2]
        f_ned[:, 2] += cn * v[:, 1] - ce * v[:, 0] - normal_gravity(lat, alt)
        roll = m["roll"]
        sr, cr = np.sin(roll), np.cos(roll)
        sp, cp = m["sin_pitch"], m["cos_pitch"]
        trig = (cr, sr, cp, sp, m["cos_yaw"], m["sin_yaw"])
        f_body = ned_to_body(*trig, f_ned)
        w_body = ned_to_body(*trig, w_in)
        w_body[:, 0] += m["roll_rate"] - m["yaw_rate"] * sp
        w_body[:, 1] += m["pitch_rate"] * cr + m["yaw_rate"] * cp * sr
        w_body[:, 2] += -m["pitch_rate"] * sr + m["yaw_rate"] * cp * cr
        return dict(t=t, lat=lat, lon=pos[:, 1], alt=alt, v_ned=v, roll=roll,
                    pitch=m["pitch"], yaw=m["yaw"], w_body=w_body, f_body=f_body, speed=m["v"],
                    distance=m["s"])

    def grid_inertial(self) -> dict[str, np.ndarray]:
        """``inertial`` on the base grid, cached: the truth table and the sensors sampling at
        the base rate share one evaluation."""
        if "grid" not in self._cache:
            n = len(self.t_grid)  # the grid's positions are the integration's own nodes
            self._cache["grid"] = self.inertial(self.t_grid, self._motion_cache.pop("grid"),
                                                self._pos_values[:n])
        return self._cache["grid"]

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
        """Zone name at times t ('' outside every zone), a string array; later zones win where
        they overlap.

        Zones are [start, end), except that a zone reaching the end of the drive also holds
        its last instant (a drive that ends in a garage ends without sky). Each time gets the
        number of its zone (0: none), and the names are looked up once from those numbers.
        """
        t = np.atleast_1d(t)
        zones = self.profile.zones
        zone_number = np.zeros(t.shape, dtype=np.intp)
        for number, (start, end, _) in enumerate(zones, start=1):
            last = end >= self.duration_s - 1e-9
            zone_number[(t >= start) & ((t < end) | (last & (t <= end)))] = number
        return np.array(["", *(name for _, _, name in zones)]).take(zone_number)

    def table(self, t: np.ndarray | None = None) -> pd.DataFrame:
        """The truth table (SPEC section 5 ``truth.parquet`` columns) at times t (default: grid),
        as a DataFrame (imports pandas)."""
        import pandas as pd

        return pd.DataFrame(self.columns(t), columns=list(col.TRUTH))

    def columns(self, t: np.ndarray | None = None) -> ColumnTable:
        """The truth table as a column table (``simulator.tables``): ``table`` without pandas."""
        k = self.grid_inertial() if t is None else self.inertial(t)
        return {
            "t": k["t"],
            "lat": np.degrees(k["lat"]),
            "lon": np.degrees(k["lon"]),
            "alt": k["alt"],
            "vn": k["v_ned"][:, 0], "ve": k["v_ned"][:, 1], "vd": k["v_ned"][:, 2],
            "roll": wrap_angle(k["roll"]), "pitch": k["pitch"], "yaw": wrap_angle(k["yaw"]),
            "wx": k["w_body"][:, 0], "wy": k["w_body"][:, 1], "wz": k["w_body"][:, 2],
            "fx": k["f_body"][:, 0], "fy": k["f_body"][:, 1], "fz": k["f_body"][:, 2],
            "speed": k["speed"], "distance": k["distance"],
            "zone": self.zone_at(k["t"]),
        }


def _as_fast(profile: RoadProfile) -> RoadProfile:
    """The profile with every curve a ``PiecewisePolynomial`` (sources may give scipy PPoly)."""
    fields = ("distance_of_time", "curvature", "heading", "grade", "bank")
    converted = {f: PiecewisePolynomial.from_ppoly(getattr(profile, f)) for f in fields}
    direction = (None if profile.direction is None
                 else PiecewisePolynomial.from_ppoly(profile.direction))
    return RoadProfile(**converted, duration_s=profile.duration_s, zones=profile.zones,
                       direction=direction)


def kinematics_from_profile(profile: RoadProfile, start: dict, rate_hz: float,
                            roll_gradient: float) -> Kinematics:
    """Build the ``Kinematics`` of a road profile from a resolved scenario ``start`` block."""
    origin = Origin(start["lat"], start["lon"], start["alt"], start["heading"])
    return Kinematics(profile, origin, rate_hz, roll_gradient)
