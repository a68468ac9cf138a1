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

With a vehicle body (``simulator.vehicle``, issue 13) the road-following point above is the
body's centre of gravity in its static position; the body then heaves, pitches, rolls, surges
and sways on its suspension and tyres and yaws by the side slip beta relative to the path
(``_with_body``), and the truth is the motion of its reference point
(``BodyMotion.reference_point``) on the body.

The truth table is ``Kinematics.columns`` (a column table of ``simulator.tables``, what the
dataset writer takes, without pandas) or ``Kinematics.table`` (the same as a DataFrame).

Public names
------------
Kinematics, kinematics_from_profile, truth_grid.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from simulator import columns as col
from simulator.earth import (
    OMEGA_E_RAD_S,
    body_to_ned_components,
    geodetic_rates,
    ned_to_body_components,
    normal_gravity_from_sin,
    radii_of_curvature,
    radii_of_curvature_from_sin,
    wrap_angle,
)
from simulator.tables import ColumnTable
from simulator.timebase import utc_to_gps
from simulator.trajectory.piecewise import PiecewisePolynomial
from simulator.trajectory.quadrature import GL_NODES, GL_WEIGHTS, cubic_interval_integrals
from simulator.trajectory.segments import RoadProfile

if TYPE_CHECKING:
    import pandas as pd

    from simulator.vehicle.body import BodyMotion

# samples per piece of a long evaluation (``_by_pieces``): its intermediate arrays, 128 kB each
_PIECE = 16384


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
        Body roll per lateral acceleration, rad per m/s^2 (without a ``body`` only).
    body : BodyMotion, optional
        The body's motion on its suspension and its side slip (``simulator.vehicle``); None:
        a rigid point following the road.
    """

    def __init__(self, profile: RoadProfile, origin: Origin, rate_hz: float,
                 roll_gradient: float, utc_start: dt.datetime = dt.datetime(2020, 1, 1),
                 environment: Mapping | None = None, body: BodyMotion | None = None):
        self.profile = _as_fast(profile)
        self.body = body
        curves = (self.profile.curvature, self.profile.grade, self.profile.bank,
                  self.profile.heading)
        self._shared_breaks = all(np.array_equal(c.x, curves[0].x) for c in curves)
        self.origin = origin
        self.rate_hz = float(rate_hz)
        self.roll_gradient = float(roll_gradient)
        self.duration_s = profile.duration_s
        self.t_grid = truth_grid(self.duration_s, self.rate_hz)
        self._breaks: np.ndarray | None = None
        self._cache: dict[str, dict] = {}
        # when the drive starts, and the resolved ``environment`` block (zones and their sky,
        # canyon and magnetic settings)
        self.utc_start = utc_start
        self.gps_week, self.gps_tow = utc_to_gps(utc_start)
        self.environment = environment if environment is not None else {"zones": {}}
        self._integrate_position()

    # -- along-road quantities --------------------------------------------------------------
    def _motion(self, t: np.ndarray) -> dict[str, np.ndarray]:
        """Along-road quantities at times t: distance, signed speed, attitude and Euler-angle
        rates, the NED velocity and its exact time derivative, and the cosines and sines of
        pitch and yaw (which ``inertial`` reuses).

        A long t is evaluated piece by piece (``_by_pieces``)."""
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration_s)
        if t.ndim != 1:
            return self._motion_piece(t)
        return _by_pieces(lambda rows: self._motion_piece(t[rows]), len(t))

    def _motion_piece(self, t: np.ndarray,
                      body: dict[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
        """``_motion`` of one piece; ``body``: the body's channels at t when already known
        (``BodyMotion.inside``), else evaluated here."""
        p = self.profile
        s, v, a = p.distance_of_time.evaluate(t, (0, 1, 2))
        np.maximum(v, 0.0, out=v)
        d = p.direction_at(t)  # +1 forward, -1 reversing: switches only where v = a = 0
        # the road curves of a parametric drive share their breakpoints: one search serves all
        idx = p.curvature.piece_index(s) if self._shared_breaks else None
        orders = (0, 1) if self.body is None else (0, 1, 2)
        kappa, dkappa, *d2kappa = p.curvature.evaluate(s, orders, idx)
        gamma, dgamma, *d2gamma = p.grade.evaluate(s, orders, idx)
        bank, dbank, *d2bank = p.bank.evaluate(s, orders, idx)
        psi = p.heading.evaluate(s, (0,), idx)[0]
        psi += np.radians(self.origin.heading_deg)
        yaw = wrap_angle(psi)  # the same angle, whose cosine and sine are cheaper
        cg, sg, cp, sp = np.cos(gamma), np.sin(gamma), np.cos(yaw), np.sin(yaw)
        yaw_rate = kappa * v
        pitch_rate = dgamma * v
        # body roll against the lateral acceleration d kappa v^2 (and its exact rate, d constant)
        roll_per_accel = self.roll_gradient * d
        v2 = v * v
        roll = bank - roll_per_accel * v2 * kappa
        roll_rate = dbank * v - roll_per_accel * (2 * v * a * kappa + v2 * v * dkappa)
        dv, da = d * v, d * a  # signed speed and acceleration along body x
        # the velocity is d v u with the unit vector u = (cg cp, cg sp, -sg) along the road;
        # stored component by component (shape (3, n)), handed out transposed as (n, 3)
        u_n, u_e = cg * cp, cg * sp
        v_ned = np.empty((3,) + t.shape)
        np.multiply(dv, u_n, out=v_ned[0])
        np.multiply(dv, u_e, out=v_ned[1])
        np.multiply(dv, sg, out=v_ned[2])
        np.negative(v_ned[2], out=v_ned[2])
        # d/dt of d v u(psi, gamma): d (a u + v (du/dpsi psi' + du/dgamma gamma'))
        sg_pitch_rate = sg * pitch_rate
        a_ned = np.empty_like(v_ned)
        a_ned[0] = da * u_n - dv * (u_e * yaw_rate + cp * sg_pitch_rate)
        a_ned[1] = da * u_e + dv * (u_n * yaw_rate - sp * sg_pitch_rate)
        a_ned[2] = -da * sg - dv * cg * pitch_rate
        if self.body is not None:
            road = dict(s=s, v=v, a=a, psi=psi, kappa=kappa, dkappa=dkappa, gamma=gamma,
                        dgamma=dgamma, d2gamma=d2gamma[0], bank=bank, dbank=dbank,
                        d2bank=d2bank[0], v_ned=v_ned, a_ned=a_ned)
            return self._with_body(road, dv + 0.0,
                                   self.body.evaluate(t) if body is None else body)
        # + 0.0: a reversing car at rest reads 0.0, not -0.0
        return dict(s=s, v=dv + 0.0, roll=roll, pitch=gamma, yaw=psi, roll_rate=roll_rate,
                    pitch_rate=pitch_rate, yaw_rate=yaw_rate, v_ned=v_ned.T, a_ned=a_ned.T,
                    cos_pitch=cg, sin_pitch=sg, cos_yaw=cp, sin_yaw=sp)

    def _with_body(self, road: dict[str, np.ndarray], speed: np.ndarray,
                   b: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """``_motion_piece`` with the body (its channels ``b``, ``BodyMotion.evaluate``):
        attitude, rates and the reference point's motion.

        Attitude: roll = bank + body roll, pitch = grade + body pitch, yaw = path heading - side
        slip, each with its exact first and second time derivatives (the road curves' s
        derivatives times v and a). The body's centre of gravity is displaced by
        e = (x, y, -z) from the road-following point (FRD; surge x, sway y, heave z up) and the
        reference point sits at r' = r + e from it (r the reference point), so relative to the
        road-following point its velocity is C_b^n (w x r' + e') and its acceleration
        C_b^n (alpha x r' + w x (w x r') + 2 w x e' + e''), with w = w_nb^b from the Euler-angle
        rates
        (Groves eq. 2.56 inverted) and alpha its derivative. The rotation of the NED frame
        itself (the transport rate, below 1e-5 rad/s) is left out of these lever-arm terms: it
        moves the point by less than 1e-5 m/s x r. The road-following point's velocity is
        kept as ``v_road`` for the position integration, the displacement as ``offset``.
        """
        v, a = road["v"], road["a"]
        v2 = v * v
        roll = road["bank"] + b["roll"]
        pitch = road["gamma"] + b["pitch"]
        yaw = road["psi"] - b["slip"]
        roll_rate = road["dbank"] * v + b["roll_rate"]
        pitch_rate = road["dgamma"] * v + b["pitch_rate"]
        yaw_rate = road["kappa"] * v - b["slip_rate"]
        roll_acc = road["d2bank"] * v2 + road["dbank"] * a + b["roll_accel"]
        pitch_acc = road["d2gamma"] * v2 + road["dgamma"] * a + b["pitch_accel"]
        yaw_acc = road["dkappa"] * v2 + road["kappa"] * a - b["slip_accel"]
        cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
        yaw_wrapped = wrap_angle(yaw)
        cy, sy = np.cos(yaw_wrapped), np.sin(yaw_wrapped)
        wx = roll_rate - yaw_rate * sp
        wy = pitch_rate * cr + yaw_rate * cp * sr
        wz = -pitch_rate * sr + yaw_rate * cp * cr
        ax = roll_acc - yaw_acc * sp - yaw_rate * pitch_rate * cp
        ay = (pitch_acc * cr - pitch_rate * roll_rate * sr + yaw_acc * cp * sr
              - yaw_rate * pitch_rate * sp * sr + yaw_rate * roll_rate * cp * cr)
        az = (-pitch_acc * sr - pitch_rate * roll_rate * cr + yaw_acc * cp * cr
              - yaw_rate * pitch_rate * sp * cr - yaw_rate * roll_rate * cp * sr)
        r0x, r0y, r0z = self.body.reference_point
        rx, ry, rz = r0x + b["surge"], r0y + b["sway"], r0z - b["heave"]
        ex, ey, ez = b["surge_rate"], b["sway_rate"], -b["heave_rate"]  # e'
        # w x r' + e', then alpha x r' + w x (w x r') + 2 w x e' + e''
        ux = wy * rz - wz * ry
        uy = wz * rx - wx * rz
        uz = wx * ry - wy * rx
        acc_x = (ay * rz - az * ry + (wy * uz - wz * uy) + 2 * (wy * ez - wz * ey)
                 + b["surge_accel"])
        acc_y = (az * rx - ax * rz + (wz * ux - wx * uz) + 2 * (wz * ex - wx * ez)
                 + b["sway_accel"])
        acc_z = (ax * ry - ay * rx + (wx * uy - wy * ux) + 2 * (wx * ey - wy * ex)
                 - b["heave_accel"])
        trig = (cr, sr, cp, sp, cy, sy)
        v_ned = road["v_ned"].T + body_to_ned_components(*trig, ux + ex, uy + ey, uz + ez)
        a_ned = road["a_ned"].T + body_to_ned_components(*trig, acc_x, acc_y, acc_z)
        offset = body_to_ned_components(*trig, rx, ry, rz)
        return dict(s=road["s"], v=speed, roll=roll, pitch=pitch, yaw=yaw, roll_rate=roll_rate,
                    pitch_rate=pitch_rate, yaw_rate=yaw_rate, v_ned=v_ned, a_ned=a_ned,
                    cos_pitch=cp, sin_pitch=sp, cos_yaw=cy, sin_yaw=sy, cos_roll=cr, sin_roll=sr,
                    v_road=road["v_ned"].T, offset=offset)

    # -- position ---------------------------------------------------------------------------
    def _integrate_position(self) -> None:
        """Geodetic position on the grid: dlat/dt, dlon/dt, dh/dt (Groves eq. 5.56) integrated
        interval by interval with the cubic rule on the grid samples (``quadrature``), and with
        three-point Gauss-Legendre on the analytic velocity where the grid is too short for it
        and over the last, partial interval up to the drive's end.

        Altitude first, then latitude by two fixed-point passes on the weak dependence of R_N on
        latitude (R_N at the start latitude, then at the first pass's latitude), then longitude.
        At the Gauss-Legendre nodes, latitude and altitude are interpolated linearly between the
        integration nodes (the radii vary slowly). The motion on the grid, and the sine, cosine
        and radii of the grid latitudes, are kept for ``grid_inertial``.
        """
        h = 1.0 / self.rate_hz
        n_grid = len(self.t_grid)
        t = self.t_grid  # the integration nodes: the grid, and the drive's end if off the grid
        if t[-1] < self.duration_s - 1e-9:
            t = np.append(t, self.duration_s)
        motion = self._motion(t)
        v = _road_velocity(motion)
        # intervals [t_k, t_k+1] for k >= first_gauss: Gauss-Legendre on the analytic velocity
        first_gauss = n_grid - 1 if n_grid >= 4 else 0
        owner = np.repeat(np.arange(first_gauss, len(t) - 1), len(GL_NODES))
        gauss_t = t[owner] + (t[owner + 1] - t[owner]) * np.tile(GL_NODES, len(t) - 1
                                                                  - first_gauss)
        gauss_v = _road_velocity(self._motion(gauss_t)) if len(gauss_t) else np.empty((0, 3))
        gauss_u = (gauss_t - t[owner]) / (t[owner + 1] - t[owner])

        def at_gauss(node_values: np.ndarray) -> np.ndarray:
            """Values at the nodes interpolated linearly to the Gauss-Legendre nodes."""
            left = node_values[owner]
            return left + gauss_u * (node_values[owner + 1] - left)

        def integrate(rate_at_nodes: np.ndarray, rate_at_gauss: np.ndarray) -> np.ndarray:
            """Cumulative integral over the nodes (0 at the first) of a rate given at the
            nodes and at the Gauss-Legendre nodes."""
            steps = np.empty(len(t) - 1)
            if first_gauss:
                steps[:first_gauss] = cubic_interval_integrals(rate_at_nodes[:n_grid], h)
            if len(gauss_t):
                widths = t[first_gauss + 1:] - t[first_gauss:-1]
                steps[first_gauss:] = widths * (rate_at_gauss.reshape(-1, len(GL_NODES))
                                                @ GL_WEIGHTS)
            total = np.empty(len(t))
            total[0] = 0.0
            np.cumsum(steps, out=total[1:])
            return total

        lat0, lon0 = np.radians(self.origin.lat_deg), np.radians(self.origin.lon_deg)
        alt = integrate(-v[:, 2], -gauss_v[:, 2])
        alt += self.origin.alt_m
        alt_gauss = at_gauss(alt)
        rn_start = radii_of_curvature(lat0)[0]
        lat = integrate(v[:, 0] / (rn_start + alt), gauss_v[:, 0] / (rn_start + alt_gauss))
        lat += lat0
        rn_gauss = radii_of_curvature(at_gauss(lat))[0]
        lat = integrate(v[:, 0] / (radii_of_curvature(lat)[0] + alt),
                        gauss_v[:, 0] / (rn_gauss + alt_gauss))
        lat += lat0
        sin_lat, cos_lat = np.sin(lat), np.cos(lat)
        rn, re = radii_of_curvature_from_sin(sin_lat)
        lat_gauss = at_gauss(lat)
        rates = geodetic_rates(lat, alt, v, (rn, re))
        lon = integrate(rates[1], geodetic_rates(lat_gauss, alt_gauss, gauss_v)[1])
        lon += lon0
        self._t_int = t
        self._lla = (lat, lon, alt)
        self._lla_rates = rates
        # for ``grid_inertial``: the grid's positions are the integration's own nodes
        self._grid_motion = {key: values[:n_grid] for key, values in motion.items()}
        if self.body is None:
            self._grid_place = dict(lat=lat[:n_grid], lon=lon[:n_grid], alt=alt[:n_grid],
                                    sin_lat=sin_lat[:n_grid], cos_lat=cos_lat[:n_grid],
                                    rn=rn[:n_grid], re=re[:n_grid])
        else:
            pos = np.stack([lat[:n_grid], lon[:n_grid], alt[:n_grid]], axis=1)
            self._grid_place = _place(_displaced(pos, self._grid_motion["offset"]))

    def position(self, t: np.ndarray) -> np.ndarray:
        """Latitude (rad), longitude (rad), altitude (m) at times t, shape (n, 3).

        Cubic Hermite interpolation between integration nodes with the exact rates, so the
        interpolation error is O(dt^4) (far below a millimetre at the base rate); with a body,
        displaced from the road-following point to the reference point.
        """
        pos = self._road_position(t)
        if self.body is None:
            return pos
        return _displaced(pos, self._motion(np.clip(t, 0.0, self.duration_s))["offset"])

    def _road_position(self, t: np.ndarray,
                       i: np.ndarray | slice | None = None) -> np.ndarray:
        """``position`` of the road-following point; ``i``: the integration interval of each
        time when known (an index array, or a slice for a run of intervals; else searched)."""
        nodes = self._t_int
        t = np.clip(np.atleast_1d(np.asarray(t, float)), 0.0, nodes[-1])
        out = np.empty((3,) + t.shape)  # component by component, handed out as (n, 3)
        if len(nodes) == 1:
            out[:] = [[values[0]] for values in self._lla]
            return out.T
        if i is None:
            i = np.clip(np.searchsorted(nodes, t, side="right") - 1, 0, len(nodes) - 2)
        this, after = _at_and_after(i)
        start = nodes[this]
        h = nodes[after] - start
        u = (t - start) / h
        u2 = u * u
        u3 = u2 * u
        # the cubic Hermite basis: values at the ends, and rates at the ends (times h)
        value_start, value_end = 2 * u3 - 3 * u2 + 1, -2 * u3 + 3 * u2
        rate_start, rate_end = (u3 - 2 * u2 + u) * h, (u3 - u2) * h
        for column, (values, rates) in enumerate(zip(self._lla, self._lla_rates, strict=True)):
            out[column] = (value_start * values[this] + rate_start * rates[this]
                           + value_end * values[after] + rate_end * rates[after])
        return out.T

    # -- the truth columns ------------------------------------------------------------------
    def inertial(self, t: np.ndarray) -> dict[str, np.ndarray]:
        """Everything at times t: position, velocity, attitude, w_ib^b and f_ib^b (FRD)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        motion = self._motion(t)
        pos = self._road_position(t)
        if self.body is not None:
            pos = _displaced(pos, motion["offset"])
        return self._inertial(t, motion, _place(pos))

    def _inertial(self, t: np.ndarray, m: dict[str, np.ndarray],
                  place: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """``inertial`` from the motion at t and the place: latitude, longitude, altitude, the
        sine and cosine of latitude and the radii of curvature R_N, R_E there (the body
        vectors evaluated piece by piece, ``_by_pieces``)."""
        body = _by_pieces(lambda rows: self._body_vectors(
            {key: values[rows] for key, values in m.items()},
            {key: values[rows] for key, values in place.items()}), len(t))
        return dict(t=t, lat=place["lat"], lon=place["lon"], alt=place["alt"], v_ned=m["v_ned"],
                    roll=m["roll"], pitch=m["pitch"], yaw=m["yaw"], w_body=body["w_body"],
                    f_body=body["f_body"], speed=m["v"], distance=m["s"])

    @staticmethod
    def _body_vectors(m: dict[str, np.ndarray],
                      place: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """w_ib^b and f_ib^b from the motion and the place (see ``_inertial``):
        f^n = dv/dt - g^n + (w_en + 2 w_ie) x v (Groves eq. 5.54) and
        w_ib^b = w_nb^b + C_n^b (w_ie + w_en), written component-wise for speed."""
        v = m["v_ned"]
        vn, ve, vd = v[:, 0], v[:, 1], v[:, 2]
        alt, sin_lat, cos_lat = place["alt"], place["sin_lat"], place["cos_lat"]
        # Earth rate (Groves eq. 5.41) and transport rate (eq. 5.44) in NED
        rate_n = ve / (place["re"] + alt)
        rate_e = -vn / (place["rn"] + alt)
        rate_d = -rate_n * sin_lat / cos_lat
        ie_n, ie_d = OMEGA_E_RAD_S * cos_lat, -OMEGA_E_RAD_S * sin_lat
        cn, ce, cd = 2 * ie_n + rate_n, rate_e, 2 * ie_d + rate_d  # w_en + 2 w_ie
        a = m["a_ned"]
        f_n = a[:, 0] + (ce * vd - cd * ve)
        f_e = a[:, 1] + (cd * vn - cn * vd)
        f_d = a[:, 2] + (cn * ve - ce * vn - normal_gravity_from_sin(sin_lat, alt))
        if "cos_roll" in m:  # the body's roll, whose sine and cosine ``_with_body`` took
            sr, cr = m["sin_roll"], m["cos_roll"]
        else:
            sr, cr = np.sin(m["roll"]), np.cos(m["roll"])
        sp, cp = m["sin_pitch"], m["cos_pitch"]
        trig = (cr, sr, cp, sp, m["cos_yaw"], m["sin_yaw"])
        f_body = ned_to_body_components(*trig, f_n, f_e, f_d)
        w_body = ned_to_body_components(*trig, ie_n + rate_n, rate_e, ie_d + rate_d)  # w_in
        w_body[:, 0] += m["roll_rate"] - m["yaw_rate"] * sp
        w_body[:, 1] += m["pitch_rate"] * cr + m["yaw_rate"] * cp * sr
        w_body[:, 2] += -m["pitch_rate"] * sr + m["yaw_rate"] * cp * cr
        return {"w_body": w_body, "f_body": f_body}

    def rates_inside(self, j: np.ndarray, u: float) -> dict[str, np.ndarray]:
        """w_ib^b and f_ib^b (``inertial``'s ``w_body``, ``f_body``, shape (m, 3)) at
        t_j + u h for the base grid's intervals j (indices, shape (m,)) at one fraction u of
        the interval: the inner nodes of a quadrature rule over grid intervals.

        The same truth as ``inertial``, computed piece by piece straight to the two vectors
        (the motion, the place and the body vectors of a piece are never assembled for the
        whole series), with the body's channels from ``BodyMotion.inside`` (one linear map of
        the interval's end nodes for all points) and the position from the interval's own
        integration nodes (no search)."""
        j = np.asarray(j, dtype=np.intp)
        h = 1.0 / self.rate_hz
        run = len(j) > 0 and j[-1] - j[0] == len(j) - 1 and bool((np.diff(j) == 1).all())

        def piece(rows: slice) -> dict[str, np.ndarray]:
            # a run of intervals (every sample of a vibrating drive) as slices: views, no gathers
            jj = slice(j[0] + rows.start, j[0] + min(rows.stop, len(j))) if run else j[rows]
            t = np.minimum(self.t_grid[jj] + u * h, self.duration_s)
            body = None if self.body is None else self.body.inside(jj, u)
            motion = self._motion_piece(t, body)
            pos = self._road_position(t, jj)
            if self.body is not None:
                pos = _displaced(pos, motion["offset"])
            return self._body_vectors(motion, _place(pos))

        return _by_pieces(piece, len(j))

    def grid_inertial(self) -> dict[str, np.ndarray]:
        """``inertial`` on the base grid, cached: the truth table and the sensors sampling at
        the base rate share one evaluation, which reuses the motion and the latitude terms the
        position integration computed on the grid."""
        if "grid" not in self._cache:
            self._cache["grid"] = self._inertial(self.t_grid, self._grid_motion,
                                                 self._grid_place)
            del self._grid_motion, self._grid_place
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
            body = [] if self.body is None else [self.body.breakpoints()]
            self._breaks = np.unique(np.concatenate([p.distance_of_time.x, t_breaks, *body]))
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
            "lon": np.degrees(wrap_angle(k["lon"])),  # across the antimeridian too
            "alt": k["alt"],
            "vn": k["v_ned"][:, 0], "ve": k["v_ned"][:, 1], "vd": k["v_ned"][:, 2],
            "roll": wrap_angle(k["roll"]), "pitch": k["pitch"], "yaw": wrap_angle(k["yaw"]),
            "wx": k["w_body"][:, 0], "wy": k["w_body"][:, 1], "wz": k["w_body"][:, 2],
            "fx": k["f_body"][:, 0], "fy": k["f_body"][:, 1], "fz": k["f_body"][:, 2],
            "speed": k["speed"], "distance": k["distance"],
            "zone": self.zone_at(k["t"]),
        }


def _by_pieces(evaluate: Callable[[slice], dict[str, np.ndarray]],
               n: int) -> dict[str, np.ndarray]:
    """``evaluate(rows)`` over rows 0 to n, assembled piece by piece into full arrays when n is
    long: the dozens of intermediate arrays of a piece stay small and are reused by the next
    one, where a whole hour's would first touch some 90 MB (page faults were two thirds of the
    time). ``evaluate`` returns arrays of len(rows) or (len(rows), k); the latter are
    assembled in (k, n) storage and handed out as (n, k), like the vectors of one piece."""
    if n <= 2 * _PIECE:
        return evaluate(slice(0, n))
    out: dict[str, np.ndarray] = {}
    for start in range(0, n, _PIECE):
        rows = slice(start, start + _PIECE)
        piece = evaluate(rows)
        if not out:
            out = {key: np.empty((value.shape[1], n)).T if value.ndim == 2 else np.empty(n)
                   for key, value in piece.items()}
        for key, value in piece.items():
            out[key][rows] = value
    return out


def _at_and_after(i: np.ndarray | slice) -> tuple[np.ndarray | slice, np.ndarray | slice]:
    """Indices i and i + 1, as slices for a slice (views) and as arrays for an index array."""
    if isinstance(i, slice):
        return i, slice(i.start + 1, i.stop + 1)
    return i, i + 1


def _road_velocity(motion: dict[str, np.ndarray]) -> np.ndarray:
    """NED velocity of the road-following point (that of the truth without a body)."""
    return motion["v_road"] if "v_road" in motion else motion["v_ned"]


def _place(pos: np.ndarray) -> dict[str, np.ndarray]:
    """Latitude, longitude, altitude (rad, rad, m; (n, 3)) with the sine and cosine of latitude
    and the radii of curvature there: the place ``_inertial`` takes."""
    lat = pos[:, 0]
    sin_lat, cos_lat = np.sin(lat), np.cos(lat)
    rn, re = radii_of_curvature_from_sin(sin_lat)
    return dict(lat=lat, lon=pos[:, 1], alt=pos[:, 2], sin_lat=sin_lat, cos_lat=cos_lat,
                rn=rn, re=re)


def _displaced(pos: np.ndarray, offset_ned: np.ndarray) -> np.ndarray:
    """Geodetic positions (n, 3) moved by small NED offsets (n, 3), m (``geodetic_rates`` of the
    offsets: first order, the offsets are about a metre, so the neglected terms are below a
    micrometre)."""
    out = np.empty_like(pos)
    for column, change in enumerate(geodetic_rates(pos[:, 0], pos[:, 2], offset_ned)):
        np.add(pos[:, column], change, out=out[:, column])
    return out


def _as_fast(profile: RoadProfile) -> RoadProfile:
    """The profile with every curve a ``PiecewisePolynomial`` (sources may give scipy PPoly)."""
    fields = ("distance_of_time", "curvature", "heading", "grade", "bank")
    converted = {f: PiecewisePolynomial.from_ppoly(getattr(profile, f)) for f in fields}
    direction = (None if profile.direction is None
                 else PiecewisePolynomial.from_ppoly(profile.direction))
    return RoadProfile(**converted, duration_s=profile.duration_s, zones=profile.zones,
                       direction=direction, bumps=profile.bumps)


def truth_grid(duration_s: float, rate_hz: float) -> np.ndarray:
    """The base grid of the truth: every 1 / rate_hz from 0 up to the drive's duration."""
    n = int(np.floor(duration_s * rate_hz + 1e-9)) + 1
    return np.arange(n) / rate_hz


def kinematics_from_profile(profile: RoadProfile, start: Mapping, rate_hz: float,
                            roll_gradient: float,
                            utc_start: dt.datetime = dt.datetime(2020, 1, 1),
                            environment: Mapping | None = None,
                            body: BodyMotion | None = None) -> Kinematics:
    """Build the ``Kinematics`` of a road profile from a resolved scenario ``start`` block (and
    the drive's UTC epoch and resolved ``environment`` block, which the sensors read, and the
    vehicle's body on the road, ``simulator.vehicle``)."""
    origin = Origin(start["lat"], start["lon"], start["alt"], start["heading"])
    return Kinematics(profile, origin, rate_hz, roll_gradient, utc_start, environment, body)
