"""The body's motion relative to the road-following point: heave, pitch, roll, surge and sway
from the full-car ride model (``suspension``) and the side slip from a linear bicycle model,
each as a piecewise quintic of time that the exact kinematics differentiate.

* Side slip at the centre of gravity: the steady-state linear bicycle model (Rajamani, *Vehicle
  Dynamics and Control*, 2nd ed., Springer 2012, section 3.3, eq. 3.45 with the yaw rate of the
  path):  beta = kappa (l_r - m l_f v^2 / (L C_r)),  with C_r the rear axle's cornering stiffness
  (both tyres), l_f and l_r the distances of the centre of gravity from the front and rear
  axles and L = l_f + l_r. At low speed it is the kinematic model's beta = l_r kappa (the rear
  axle's velocity lies along the body, Rajamani eq. 2.29 for small angles); above the speed
  sqrt(l_r L C_r / (m l_f)) (19.5 m/s for the automotive preset) the tyres' slip turns it
  negative. Signs in FRD: kappa > 0 turns right; beta > 0 puts the velocity to the right of the
  body's x axis, so the body's yaw is the path's heading minus beta. The steady state is used
  throughout: the bicycle model's lateral and yaw modes settle within about 0.2 s, while every
  curvature change of a drive (clothoids, lane changes, fitted paths) lasts a second or more.
  Reversing (d = -1): the rear axle still rolls without sliding sideways, but the velocity at
  the centre of gravity is now -v along the path, so the same geometry gives beta = d kappa
  (l_r - m l_f v^2 / (L C_r)): the kinematic -l_r kappa at reversing speeds (the whole
  expression times d; d is constant between standstills, so its rates are d times those).
* Side slip lagging the path (``RoadProfile.slip_relaxation``, SUMO drives): the steady state
  above holds only while the curvature changes slowly. Taken at once, it moves the rear axle
  sideways by l_r dbeta/dt = l_r^2 v dkappa/ds (the body yaws by the slip's rate besides the
  path's), 0.8 m/s in a SUMO junction turned within a few metres, which no car does: its rear
  wheels roll along the body. The kinematic bicycle model's rear wheel (Rajamani 2012, section
  2.2, with delta_r = 0: the velocity of the rear axle lies along the body, so that the yaw
  rate is psi_dot = V sin beta / l_r) with the rear tyres' slip angle of the linear model
  (section 2.3: alpha_r = (l_r psi_dot - V_y) / V_x), at the quasi-static rear force m l_f
  a_y / L that gives the steady state above, is, for small angles, l_r psi_dot = v (beta +
  gain v^2 kappa); with psi_dot = v kappa - dbeta/dt (the body's yaw is the path's heading
  minus the slip) that is dbeta/ds = (beta_ss - beta) / l_r: a first-order lag in the distance
  travelled, relaxation length l_r, towards the steady state beta_ss above (``relaxed_slip``).
  It leaves a turn of constant curvature as it was, and the rear axle then moves sideways only
  by the tyres' slip (-gain v^3 kappa). Driving forward only (a SUMO drive never reverses;
  reversing, the same constraint is unstable, the pushed trailer's).
* Heave, pitch, roll, surge and sway: ``suspension.simulate`` on the grid of the truth, driven
  by the road's heights and slopes under the wheels (``road``) and by the longitudinal, lateral
  and vertical accelerations of the path. On a vertical curve (a grade change, dgamma/ds) the
  road under wheel i lies dgamma/ds x_i^2 / 2 above the tangent plane at the centre of gravity
  (the body follows the grade there), and the path accelerates by v^2 dgamma/ds normal to the
  road: the body pitches and heaves at a crest or sag. The grade inside a speed bump is level
  (``level_road``), so a bump is not counted twice.
* Engine vibration: a vertical sine of rms ``engine_accel`` at ``engine_frequency`` added to the
  heave (its phase drawn from the road's random stream).

Each channel is known on the grid with its first and second derivatives; between grid points it
is the quintic Hermite interpolant of those six values (``quintic_hermite_basis``), so the
channels are C2 and exactly differentiable, and on the grid they equal the model's values.

Public names
------------
BodyMotion, build_body, quintic_hermite_basis, side_slip, relaxed_slip, level_road.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from simulator.trajectory.piecewise import PiecewisePolynomial
from simulator.trajectory.segments import RoadProfile
from simulator.vehicle.params import ROUGHNESS_CLASSES
from simulator.vehicle.road import RoadSurface, draw_roughness
from simulator.vehicle.suspension import FullCar, axle_distances, simulate

CHANNELS = ("heave", "pitch", "roll", "slip", "surge", "sway")


def quintic_hermite_basis(u: np.ndarray) -> np.ndarray:
    """The quintic Hermite basis on [0, 1] and its first two derivatives at u (shape (m,)):
    array (m, 3, 6), [:, order, b], b = 0 ... 5 the weights of y0, y0', y0'', y1, y1', y1''
    (the derivatives scaled by the interval: h y', h^2 y''), so that on an interval of length h
    p(u) = sum_b B[:, 0, b] c_b, p'(t) = sum_b B[:, 1, b] c_b / h, p''(t) = sum_b B[:, 2, b]
    c_b / h^2 with c = (y0, h y0', h^2 y0'', y1, h y1', h^2 y1''). The polynomial matching value,
    slope and curvature at both ends: H0 = 1 - 10 u^3 + 15 u^4 - 6 u^5, H1 = u - 6 u^3 + 8 u^4
    - 3 u^5, H2 = (u^2 - 3 u^3 + 3 u^4 - u^5) / 2, H3 = 1 - H0, H4 = -4 u^3 + 7 u^4 - 3 u^5,
    H5 = (u^3 - 2 u^4 + u^5) / 2."""
    u2 = u * u
    u3 = u2 * u
    u4 = u3 * u
    u5 = u4 * u
    b = np.empty((len(u), 3, 6))
    b[:, 0, 3] = 10 * u3 - 15 * u4 + 6 * u5
    b[:, 0, 0] = 1.0 - b[:, 0, 3]
    b[:, 0, 1] = u - 6 * u3 + 8 * u4 - 3 * u5
    b[:, 0, 2] = 0.5 * (u2 - 3 * u3 + 3 * u4 - u5)
    b[:, 0, 4] = -4 * u3 + 7 * u4 - 3 * u5
    b[:, 0, 5] = 0.5 * (u3 - 2 * u4 + u5)
    b[:, 1, 3] = 30 * (u2 - 2 * u3 + u4)
    b[:, 1, 0] = -b[:, 1, 3]
    b[:, 1, 1] = 1.0 - 18 * u2 + 32 * u3 - 15 * u4
    b[:, 1, 2] = u - 4.5 * u2 + 6 * u3 - 2.5 * u4
    b[:, 1, 4] = -12 * u2 + 28 * u3 - 15 * u4
    b[:, 1, 5] = 1.5 * u2 - 4 * u3 + 2.5 * u4
    b[:, 2, 3] = 60 * (u - 3 * u2 + 2 * u3)
    b[:, 2, 0] = -b[:, 2, 3]
    b[:, 2, 1] = -36 * u + 96 * u2 - 60 * u3
    b[:, 2, 2] = 1.0 - 9 * u + 18 * u2 - 10 * u3
    b[:, 2, 4] = -24 * u + 84 * u2 - 60 * u3
    b[:, 2, 5] = 3 * u - 12 * u2 + 10 * u3
    return b


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


_RELAX_BLOCK = 50.0  # relaxation lengths of travel per closed-form block of ``relaxed_slip``


def relaxed_slip(s: np.ndarray, v: np.ndarray, a: np.ndarray,
                 steady: tuple[np.ndarray, np.ndarray, np.ndarray],
                 l_r: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The side slip lagging its steady state over the distance travelled (module doc):
    dbeta/ds = (beta_ss - beta) / l_r from beta = beta_ss at the first sample, and its first two
    time derivatives, on a grid.

    Parameters
    ----------
    s, v, a : arrays, shape (n,)
        Distance travelled (m, non-decreasing), speed (m/s, >= 0) and its rate on the grid.
    steady : three arrays, shape (n,)
        beta_ss (rad) and its first two time derivatives (``side_slip``).
    l_r : float
        Distance of the centre of gravity ahead of the rear axle, m: the relaxation length.

    The recursion is the filter's exact step for a steady state linear in s between samples
    (first-order hold: with x = ds / l_r, beta' = e^-x beta + (1 - e^-x) beta_ss + (beta_ss' -
    beta_ss) (1 - (1 - e^-x) / x)), so a clothoid at any speed is followed to rounding; it is
    solved in closed form over blocks of ``_RELAX_BLOCK`` relaxation lengths (the block's
    partial sums scaled by e^(s / l_r), as ``stochastic.ar1_filter``), the blocks one after
    another. The rates follow from the differential equation itself: dbeta/dt = v (beta_ss -
    beta) / l_r, d2beta/dt2 = (a (beta_ss - beta) + v (dbeta_ss/dt - dbeta/dt)) / l_r."""
    target, target_rate, _ = steady
    x = np.diff(s) / l_r
    fall = -np.expm1(-x)  # 1 - e^-x
    ramp = np.divide(x - fall, x, out=0.5 * x, where=x > 1e-6)  # 1 - (1 - e^-x) / x
    step_in = fall * target[:-1] + np.diff(target) * ramp
    depth = (s - s[0]) / l_r
    beta = np.empty_like(target)
    beta[0] = target[0]
    block = np.floor(depth / _RELAX_BLOCK)
    starts = np.concatenate([[0], np.flatnonzero(np.diff(block)) + 1])
    ends = np.concatenate([starts[1:], [len(s) - 1]])
    for i0, i1 in zip(starts, ends, strict=True):  # one pass per block, not per sample
        if i1 <= i0:
            continue
        grow = np.exp(depth[i0 + 1:i1 + 1] - depth[i0])  # e^(distance from the block's start)
        beta[i0 + 1:i1 + 1] = (beta[i0] + np.cumsum(step_in[i0:i1] * grow)) / grow
    lag = target - beta
    rate = v * lag / l_r
    accel = (a * lag + v * (target_rate - rate)) / l_r
    return beta, rate, accel


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
    """Heave (m, up), suspension pitch (rad, nose up), suspension roll (rad, right side down),
    side slip (rad), surge (m, forward) and sway (m, right) of the body (``CHANNELS``), each
    with its first and second time derivatives, on the truth grid ``t`` (``nodes``, shape (18,
    n): the six channels' values, then their rates, then their accelerations), and the truth's
    reference point from the centre of gravity
    (m, FRD). Between grid times the channels are the quintic Hermite curves of the nodes
    (``quintic_hermite_basis``), built interval by interval where asked."""

    t: np.ndarray
    nodes: np.ndarray
    reference_point: np.ndarray

    def evaluate(self, t: np.ndarray) -> dict[str, np.ndarray]:
        """Each channel and its first and second time derivatives at t (1-D): keys ``heave``,
        ``heave_rate``, ``heave_accel`` and so on. On grid times, the nodes themselves;
        elsewhere the quintic of the interval, built from its two ends' nodes."""
        h = self.t[1] - self.t[0]
        n = len(self.t)
        x = t / h
        at = np.clip(np.rint(x).astype(np.intp), 0, n - 1)  # the nearest grid time
        off = np.flatnonzero(t != self.t.take(at))
        rows = self.nodes.T  # (n, 18), C-ordered: a grid time's values lie together
        if not len(off) and len(at) and at[-1] - at[0] == len(at) - 1:  # a run of grid times
            values = np.ascontiguousarray(self.nodes[:, at[0]:at[-1] + 1])
        elif len(off) == len(t):
            values = np.empty((self.nodes.shape[0], len(t)))
        else:
            values = np.ascontiguousarray(rows.take(at, axis=0).T)
        if len(off):
            j = np.clip(np.floor(x[off]).astype(np.intp), 0, n - 2)  # the interval of each
            k = len(CHANNELS)
            scale = np.repeat([1.0, h, h * h], k)  # c = (y, h y', h^2 y'') at each end
            ends = np.concatenate([rows.take(j, axis=0) * scale,
                                   rows.take(j + 1, axis=0) * scale], axis=1)
            basis = quintic_hermite_basis((t[off] - self.t.take(j)) / h)
            out = basis @ ends.reshape(len(off), 6, k)  # (m, order, channel)
            out[:, 1] /= h
            out[:, 2] /= h * h
            if len(off) == len(t):
                values[:] = out.reshape(len(off), 3 * k).T
            else:
                values[:, off] = out.reshape(len(off), 3 * k).T
        return {name + suffix: values[i + len(CHANNELS) * order]
                for order, suffix in enumerate(("", "_rate", "_accel"))
                for i, name in enumerate(CHANNELS)}

    def inside(self, j: np.ndarray | slice, u: float) -> dict[str, np.ndarray]:
        """``evaluate`` at t_j + u h for the grid intervals j (an index array or a slice of
        them) at one fraction u of the interval (0 < u < 1), as a quadrature rule asks for.

        With u fixed, the quintic Hermite basis is a constant: every channel, rate and
        acceleration there is one linear map of the two ends' 18 nodes, values = N_j W_0 +
        N_j+1 W_1 with W_e[(d, c), (o, c)] = B[o, 3 e + d] h^(d - o) (d the order of the node,
        o that of the value, c the channel; ``quintic_hermite_basis``), two matrix products
        over the intervals instead of a basis and a small product per point. The same
        polynomials as ``evaluate``, so the same values to rounding."""
        h = self.t[1] - self.t[0]
        basis = quintic_hermite_basis(np.array([float(u)]))[0]  # (order, 6)
        k = len(CHANNELS)
        power = np.arange(3)[:, None] - np.arange(3)[None, :]  # d - o
        weights = [np.kron(basis[:, 3 * end:3 * end + 3].T * h ** power, np.eye(k))
                   for end in (0, 1)]
        # (18, m) products, so that each channel is a contiguous row for the arithmetic after
        if isinstance(j, slice):
            start, stop, _ = j.indices(len(self.t) - 1)
            values = weights[0].T @ self.nodes[:, start:stop]
            values += weights[1].T @ self.nodes[:, start + 1:stop + 1]
        else:  # whole samples gathered (rows of nodes.T), handed to the product transposed
            rows = self.nodes.T
            values = weights[0].T @ rows.take(j, axis=0).T
            values += weights[1].T @ rows.take(j + 1, axis=0).T
        return {name + suffix: values[i + k * order]
                for order, suffix in enumerate(("", "_rate", "_accel"))
                for i, name in enumerate(CHANNELS)}

    def breakpoints(self) -> np.ndarray:
        return self.t

    def __post_init__(self) -> None:
        # stored sample by sample (Fortran order): the 18 values of a grid time lie together,
        # so the quintics between grid times gather whole rows of nodes.T
        self.nodes = np.asfortranarray(self.nodes)


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
    u = np.empty((11, len(t)))
    u[:4], u[6:10] = surface.heights(s, car.corner_x, car.corner_y)
    np.multiply(d, a, out=u[4])
    np.multiply(d * kappa, v * v, out=u[5])
    # a vertical curve: the road under wheel i lies dgamma/ds x_i^2 / 2 above the tangent plane
    # at the centre of gravity, and the path accelerates by v^2 dgamma/ds normal to the road
    dgamma = profile.grade.evaluate(s, (1,))[0]
    u[:4] += np.multiply.outer(0.5 * car.corner_x**2, dgamma)
    np.multiply(dgamma, v * v, out=u[10])
    ride = simulate(car, u, h)  # z, theta, phi, x, y, then their rates and accelerations
    omega = 2 * np.pi * params["engine_frequency"]
    amplitude = params["engine_accel"] * np.sqrt(2.0) / omega**2
    if amplitude > 0:
        phase = omega * t + rng.uniform(0.0, 2 * np.pi)
        sin = np.sin(phase)
        ride[0] += amplitude * sin
        ride[5] += amplitude * omega * np.cos(phase)
        ride[10] -= amplitude * omega**2 * sin
    l_f, l_r = axle_distances(params)
    gain = params["mass"] * l_f / (params["wheelbase"] * params["rear_cornering"])
    steady = side_slip(kappa, dkappa, d2kappa, v, a, jerk, l_r, gain)
    if profile.slip_relaxation:
        if np.any(np.asarray(d) < 0):
            raise ValueError("the side slip's lag is modelled driving forward only")
        slip = list(relaxed_slip(s, v, a, steady, l_r))
    else:
        slip = [d * x for x in steady]
    k = len(CHANNELS)
    nodes = np.empty((3 * k, len(t)), order="F")
    for order in range(3):  # the channels; then their rates, then their accelerations
        nodes[k * order:k * order + 3] = ride[5 * order:5 * order + 3]  # heave, pitch, roll
        nodes[k * order + 3] = slip[order]
        nodes[k * order + 4:k * order + 6] = ride[5 * order + 3:5 * order + 5]  # surge, sway
    return BodyMotion(t, nodes, np.asarray(params["imu_position"], dtype=float))
