"""The body's motion relative to the road-following point: heave, pitch and roll from the
full-car ride model (``suspension``) and the side slip from a linear bicycle model, each as a
piecewise quintic of time that the exact kinematics differentiate.

* Side slip at the centre of gravity: the steady-state linear bicycle model (Rajamani, *Vehicle
  Dynamics and Control*, 2nd ed., Springer 2012, section 3.3, eq. 3.45 with the yaw rate of the
  path):  beta = kappa (l_r - m l_f v^2 / (L C_r)),  with C_r the rear axle's cornering stiffness
  (both tyres), l_f and l_r the distances of the centre of gravity from the front and rear
  axles and L = l_f + l_r. At low speed it is the kinematic model's beta = l_r kappa (the rear
  axle's velocity lies along the body, Rajamani eq. 2.29 for small angles); above the speed
  sqrt(l_r L C_r / (m l_f)) (about 16 m/s for the automotive preset) the tyres' slip turns it
  negative. Signs in FRD: kappa > 0 turns right; beta > 0 puts the velocity to the right of the
  body's x axis, so the body's yaw is the path's heading minus beta. The steady state is used
  throughout: the bicycle model's lateral and yaw modes settle within about 0.2 s, while every
  curvature change of a drive (clothoids, lane changes, fitted paths) lasts a second or more.
  Choice: beta is the same when reversing (at reversing speeds it is the kinematic l_r kappa).
* Heave, pitch and roll: ``suspension.simulate`` on the grid of the truth, driven by the road
  under the wheels (``road``) and by the longitudinal and lateral accelerations of the path.
* Engine vibration: a vertical sine of rms ``engine_accel`` at ``engine_frequency`` added to the
  heave (its phase drawn from the road's random stream).

Each channel is known on the grid with its first and second derivatives; between grid points it
is the quintic Hermite interpolant of those six values (``hermite_quintic``), so the channels are
C2 and exactly differentiable, and on the grid they equal the model's values.

Public names
------------
BodyMotion, build_body, hermite_quintic, side_slip, level_road.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from simulator.trajectory.piecewise import PiecewisePolynomial
from simulator.trajectory.segments import RoadProfile
from simulator.vehicle.params import ROUGHNESS_CLASSES
from simulator.vehicle.road import RoadSurface, draw_roughness
from simulator.vehicle.suspension import FullCar, simulate

CHANNELS = ("heave", "pitch", "roll", "slip")


def hermite_quintic(t: np.ndarray, y: np.ndarray, dy: np.ndarray,
                    d2y: np.ndarray) -> PiecewisePolynomial:
    """The C2 piecewise quintic through values, first and second derivatives at the nodes t.

    On [t_k, t_k+1] with dx = t - t_k, p = y_k + y'_k dx + y''_k dx^2 / 2 + a3 dx^3 + a4 dx^4 +
    a5 dx^5, with a3..a5 from the conditions at t_k+1 (the residuals D0, D1, D2 of value, slope
    and curvature of the quadratic part there):
    a3 = (10 D0 - 4 D1 h + D2 h^2 / 2) / h^3, a4 = (-15 D0 + 7 D1 h - D2 h^2) / h^4,
    a5 = (6 D0 - 3 D1 h + D2 h^2 / 2) / h^5.
    """
    h = np.diff(t)
    a0, a1, a2 = y[:-1], dy[:-1], 0.5 * d2y[:-1]
    d0 = y[1:] - (a0 + h * (a1 + h * a2))
    d1 = (dy[1:] - (a1 + 2 * a2 * h)) * h
    d2 = (d2y[1:] - 2 * a2) * h * h
    h3 = h**3
    a3 = (10 * d0 - 4 * d1 + 0.5 * d2) / h3
    a4 = (-15 * d0 + 7 * d1 - d2) / (h3 * h)
    a5 = (6 * d0 - 3 * d1 + 0.5 * d2) / (h3 * h * h)
    return PiecewisePolynomial(np.stack([a5, a4, a3, a2, a1, a0]), t)


def side_slip(kappa: np.ndarray, dkappa: np.ndarray, d2kappa: np.ndarray, v: np.ndarray,
              a: np.ndarray, jerk: np.ndarray, l_r: float,
              gain: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """beta = kappa(s) (l_r - gain v^2) and its first two time derivatives (see the module doc;
    gain = m l_f / (L C_r), s^2/m). kappa and its derivatives are along s (1/m, 1/m^2, 1/m^3);
    v, a, jerk the path speed (>= 0) and its time derivatives."""
    k_t = dkappa * v
    k_tt = d2kappa * v * v + dkappa * a
    g = l_r - gain * v * v
    g_t = -2 * gain * v * a
    g_tt = -2 * gain * (a * a + v * jerk)
    return kappa * g, k_t * g + kappa * g_t, k_tt * g + 2 * k_t * g_t + kappa * g_tt


def level_road(profile: RoadProfile) -> RoadProfile:
    """The profile with its speed bumps taken out of the grade (the wheels ride over them
    instead): the grade of every piece inside a bump is zero (a bump's road is level)."""
    if not profile.bumps:
        return profile
    grade = profile.grade
    mid = 0.5 * (grade.x[:-1] + grade.x[1:])
    inside = np.zeros(len(mid), dtype=bool)
    for start, length, _ in profile.bumps:
        inside |= (mid > start) & (mid < start + length)
    c = grade.c.copy()
    c[:, inside] = 0.0
    return replace(profile, grade=PiecewisePolynomial(c, grade.x))


@dataclass
class BodyMotion:
    """Heave (m, up), suspension pitch (rad, nose up), suspension roll (rad, right side down)
    and side slip (rad) of the body as C2 piecewise quintics of time sharing the grid as
    breakpoints, and the truth's reference point from the centre of gravity (m, FRD)."""

    curves: dict[str, PiecewisePolynomial]
    reference_point: np.ndarray

    def evaluate(self, t: np.ndarray) -> dict[str, np.ndarray]:
        """Each channel and its first and second time derivatives at t: keys ``heave``,
        ``heave_rate``, ``heave_accel`` and so on."""
        first = self.curves[CHANNELS[0]]
        idx = first.piece_index(t)
        out = {}
        for name in CHANNELS:
            out[name], out[name + "_rate"], out[name + "_accel"] = \
                self.curves[name].evaluate(t, (0, 1, 2), idx)
        return out

    def breakpoints(self) -> np.ndarray:
        return self.curves[CHANNELS[0]].x


def build_body(profile: RoadProfile, params: dict, t_grid: np.ndarray,
               rng: np.random.Generator) -> BodyMotion:
    """The body motion of a drive on its truth grid (see the module doc).

    Parameters
    ----------
    profile : RoadProfile
        The road and speed profile, bumps included (``profile.bumps``).
    params : dict
        Resolved vehicle parameters (``params.vehicle_parameters``).
    t_grid : array, shape (n,)
        The truth grid, uniform, from 0.
    rng : numpy.random.Generator
        The road's random stream (roughness, engine phase).
    """
    car = FullCar.from_parameters(params)
    t = t_grid if len(t_grid) > 1 else np.array([0.0, profile.duration_s or 1.0])
    h = t[1] - t[0]
    s, v, a, jerk = profile.distance_of_time.evaluate(t, (0, 1, 2, 3))
    np.maximum(v, 0.0, out=v)
    d = profile.direction_at(t)
    kappa, dkappa, d2kappa = profile.curvature.evaluate(s, (0, 1, 2))
    # the road: roughness over the whole drive and a wheelbase either side
    span = float(s[-1]) + 2 * params["wheelbase"] + 1.0
    if params["roughness"] == "none":
        tracks = None
    else:
        tracks = draw_roughness(span, ROUGHNESS_CLASSES[params["roughness"]], rng)
    surface = RoadSurface(profile.bumps, tracks, -params["wheelbase"] - 0.5, params["camber"])
    u = np.empty((len(t), 6))
    u[:, :4] = surface.heights(s, car.corner_x, car.corner_y)
    u[:, 4] = d * a
    u[:, 5] = d * kappa * v * v
    body = simulate(car, u, h)
    # engine vibration on the heave
    omega = 2 * np.pi * params["engine_frequency"]
    amplitude = params["engine_accel"] * np.sqrt(2.0) / omega**2
    if amplitude > 0:
        phase = omega * t + rng.uniform(0.0, 2 * np.pi)
        sin, cos = np.sin(phase), np.cos(phase)
        body[:, 0] += amplitude * sin
        body[:, 3] += amplitude * omega * cos
        body[:, 6] -= amplitude * omega**2 * sin
    l_f = params["wheelbase"] * (1 - params["front_weight"])
    l_r = params["wheelbase"] - l_f
    gain = params["mass"] * l_f / (params["wheelbase"] * params["rear_cornering"])
    slip = side_slip(kappa, dkappa, d2kappa, v, a, jerk, l_r, gain)
    curves = {name: hermite_quintic(t, body[:, i], body[:, 3 + i], body[:, 6 + i])
              for i, name in enumerate(CHANNELS[:3])}
    curves["slip"] = hermite_quintic(t, *slip)
    return BodyMotion(curves, np.asarray(params["imu_position"], dtype=float))
