"""The linear full-car ride model: body heave, pitch and roll on four suspension corners and four
wheels on their tyres, and the body's fore-aft and sideways motion on the horizontal compliance
of tyres and suspension (nine degrees of freedom), driven by the road height and slope under
each wheel and by the inertial forces and moments of longitudinal and lateral acceleration.

The vertical part is the classical full-vehicle ride model (Gillespie, *Fundamentals of Vehicle
Dynamics*, SAE 1992, ch. 5; Jazar, *Vehicle Dynamics: Theory and Application*, 3rd ed., Springer
2017, section 15.4 "full car vibrating model", eq. 15.91 ff.):

    M q'' + C q' + K q = F u,   q = [z, theta, phi, x, y, w_fl, w_fr, w_rl, w_rr]

with z the body's heave (m, up), theta its pitch (rad, nose up), phi its roll (rad, right side
down, as in FRD), x and y its surge and sway (m, forward and right, FRD) from the road-following
point, w_i the wheels' heights (m, up) and u = [r_fl, r_fr, r_rl, r_rr, a_x, a_y, r'_fl, r'_fr,
r'_rl, r'_rr, a_v] the road heights under the wheels (m), the longitudinal and lateral
accelerations of the path (m/s^2, FRD), the road's forward slopes under the wheels (dr/ds) and
the path's acceleration normal to the road (m/s^2, up: v^2 dgamma/ds on a vertical curve).
The corner i at (x_i, y_i) of the body moves by z + x_i theta - y_i phi; its spring and damper
act on that minus w_i, the anti-roll bars on the difference of the left and right deflections
(a roll stiffness split over the axles as the springs are), the tyre on w_i - r_i. The moments
of the accelerations act on the sprung mass at ``cg_height`` above the axes: m h a_x nose up
(the body squats when accelerating and dives when braking) and -m h a_y (it leans out of a
turn). Corner springs follow from the ride frequencies on each axle's sprung load (Gillespie
eq. 5-5), dampers from the damping ratio; the tyre is a spring (its damping is small).

Fore-aft and sideways: the sprung mass sits on the horizontal stiffness of its four corners
(``tyre_longitudinal_stiffness``, ``tyre_lateral_stiffness``: the tyre carcass in series with
the suspension's fore-aft and lateral compliance), damped with the ride modes' ratio (the
rolling tyres' slip damping, C / v per tyre, gives a ratio of that order at 10-20 m/s), and
is pushed by the road: a tyre rolling over unevenness feels its contact force along the local
road normal, so the road's forward slope under wheel i adds -N_i r'_i fore-aft and the road's
cross-slope under an axle, (r_right - r_left) / track, adds -N_axle times it sideways (N the
static wheel loads; the "effective road plane" of Pacejka, *Tire and Vehicle Dynamics*, 3rd ed.,
Butterworth-Heinemann 2012, section 10.2, here without the tyre's enveloping filter). The
path's accelerations add their inertial forces -m_s a_x, -m_s a_y (the tyres deflect under
braking and cornering) and -m a_v on the body and the wheels (the body sinks in a sag and
rises over a crest).

Integration: the state equation x' = A x + B u is diagonalised, A = V diag(lambda) V^-1; each
mode is propagated exactly for an input linear between samples ("first-order hold"; the road
heights at the wheels are sampled on the truth grid), y_k+1 = e^(lambda h) y_k + b (p u_k +
q u_k+1). The recursion runs in blocks with numpy (``stochastic.ar1_filter`` with the modes'
complex factors), never sample by sample.

Public names
------------
FullCar, axle_distances, corner_ride_rates, simulate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simulator.earth import G0_M_S2
from simulator.stochastic import ar1_filter

N_BODY = 5  # heave, pitch, roll, surge, sway
N_DOF = 9
N_INPUT = 11  # four road heights, a_x, a_y, four road slopes, the path's vertical acceleration


def axle_distances(p: dict) -> tuple[float, float]:
    """Distances l_f, l_r (m) of the centre of gravity from the front and rear axles: the
    front axle carries ``front_weight`` of the weight, so l_r = front_weight x wheelbase."""
    l_r = p["wheelbase"] * p["front_weight"]
    return p["wheelbase"] - l_r, l_r


def corner_ride_rates(p: dict) -> tuple[np.ndarray, np.ndarray]:
    """Sprung mass on each corner (kg; front-left, front-right, rear-left, rear-right) and the
    ride rate that gives its axle's ride frequency there, m (2 pi f)^2 (N/m; Gillespie eq.
    5-5): the suspension spring in series with the tyre."""
    sprung = p["mass"] - 4 * p["unsprung_mass"]
    front = p["front_weight"]
    corner_mass = np.array([front, front, 1 - front, 1 - front]) * sprung / 2
    freq = np.array([p["front_frequency"]] * 2 + [p["rear_frequency"]] * 2)
    return corner_mass, corner_mass * (2 * np.pi * freq) ** 2


@dataclass
class FullCar:
    """The matrices of the full-car model (see the module doc) built from vehicle parameters.

    ``corner_x`` and ``corner_y`` (m, FRD, from the centre of gravity) are the four corners in
    the order front-left, front-right, rear-left, rear-right.
    """

    mass: np.ndarray  # (9, 9)
    damping: np.ndarray  # (9, 9)
    stiffness: np.ndarray  # (9, 9)
    forcing: np.ndarray  # (9, 11)
    corner_x: np.ndarray
    corner_y: np.ndarray

    @classmethod
    def from_parameters(cls, p: dict) -> FullCar:
        """Build the model from a resolved ``vehicle`` parameter mapping."""
        m = p["mass"]
        m_u = p["unsprung_mass"]
        m_s = m - 4 * m_u
        lf, lr = axle_distances(p)
        half = p["track"] / 2
        x = np.array([lf, lf, -lr, -lr])
        y = np.array([-half, half, -half, half])
        corner_mass, k_ride = corner_ride_rates(p)
        # the ride rate is the spring in series with the tyre: k_s = k_ride k_t / (k_t - k_ride)
        k_t = p["tyre_stiffness"]
        k_s = k_ride * k_t / (k_t - k_ride)
        c_s = 2 * p["damping"] * np.sqrt(k_ride * corner_mass)
        # corners: deflection d = T q_body - w, T_i = [1, x_i, -y_i, 0, 0]
        t_body = np.stack([np.ones(4), x, -y, np.zeros(4), np.zeros(4)], axis=1)
        g = np.hstack([t_body, -np.eye(4)])
        k_defl = np.diag(k_s)
        # anti-roll bars: (k_bar / t^2) (d_right - d_left)^2 / 2 per axle, the roll stiffness
        # split over the axles in proportion to their springs' roll stiffness
        axle_share = np.array([k_s[0], k_s[2]]) / (k_s[0] + k_s[2])
        for axle, (left, right) in enumerate(((0, 1), (2, 3))):
            k_bar = p["roll_stiffness"] * axle_share[axle] / (2 * half) ** 2
            pair = np.array([left, right])
            k_defl[np.ix_(pair, pair)] += k_bar * np.array([[1.0, -1.0], [-1.0, 1.0]])
        stiffness = g.T @ k_defl @ g
        stiffness[N_BODY:, N_BODY:] += k_t * np.eye(4)
        damping = g.T @ np.diag(c_s) @ g
        # fore-aft and sideways on the four corners' horizontal stiffness, damped as the ride
        for dof, key in ((3, "tyre_longitudinal_stiffness"), (4, "tyre_lateral_stiffness")):
            stiffness[dof, dof] = 4 * p[key]
            damping[dof, dof] = 2 * p["damping"] * np.sqrt(4 * p[key] * m_s)
        mass = np.diag([m_s, p["pitch_inertia"], p["roll_inertia"], m_s, m_s,
                        m_u, m_u, m_u, m_u])
        forcing = np.zeros((N_DOF, N_INPUT))
        forcing[N_BODY:, :4] = k_t * np.eye(4)
        forcing[1, 4] = m_s * p["cg_height"]  # accelerating pitches the nose up
        forcing[2, 5] = -m_s * p["cg_height"]  # a turn to the right rolls the body left
        # the inertial forces of the path's accelerations, along the road and across it, and
        # normal to it (a vertical curve: v^2 times the curvature of the road's profile)
        forcing[3, 4] = forcing[4, 5] = forcing[0, 10] = -m_s
        forcing[N_BODY:, 10] = -m_u
        # the contact forces along the road's normal: -N_i r'_i fore-aft, -N (r_right -
        # r_left) / track sideways per axle
        load = (corner_mass + m_u) * G0_M_S2
        forcing[3, 6:10] = -load
        for left, right in ((0, 1), (2, 3)):
            axle_load = load[left] + load[right]
            forcing[4, left] += axle_load / (2 * half)
            forcing[4, right] -= axle_load / (2 * half)
        return cls(mass, damping, stiffness, forcing, x, y)

    def state_space(self) -> tuple[np.ndarray, np.ndarray]:
        """A (18, 18) and B (18, 11) of x' = A x + B u, x = [q, q']."""
        m_inv = np.linalg.inv(self.mass)
        a = np.zeros((2 * N_DOF, 2 * N_DOF))
        a[:N_DOF, N_DOF:] = np.eye(N_DOF)
        a[N_DOF:, :N_DOF] = -m_inv @ self.stiffness
        a[N_DOF:, N_DOF:] = -m_inv @ self.damping
        b = np.zeros((2 * N_DOF, N_INPUT))
        b[N_DOF:] = m_inv @ self.forcing
        return a, b


def simulate(model: FullCar, u: np.ndarray, h: float) -> np.ndarray:
    """Body heave, pitch, roll, surge and sway and their first and second derivatives on a
    uniform grid.

    Parameters
    ----------
    model : FullCar
    u : array, shape (11, n)
        Inputs at the grid times (see the module doc), one row per input, linear between
        the grid times.
    h : float
        Grid spacing, s.

    Returns
    -------
    array, shape (15, n)
        z, theta, phi, x, y, then their first and then their second derivatives (m, rad, per
        s, per s^2). The model starts at rest in the static equilibrium of the first input.

    Every product with the (n,)-long series is a real matrix product of a few rows (the modal
    matrices split into real and imaginary parts): complex products of that shape cost several
    times more.
    """
    a, b = model.state_space()
    lam, vec = np.linalg.eig(a)
    vec_inv = np.linalg.inv(vec)
    # one of each complex-conjugate pair (its partner adds the conjugate: twice the real part)
    keep = lam.imag >= -1e-12 * np.abs(lam)
    weight = np.where(np.abs(lam.imag) > 1e-12 * np.abs(lam), 2.0, 1.0)[keep]
    lam, vec, vec_inv = lam[keep], vec[:, keep], vec_inv[keep]
    modal_b = vec_inv @ b  # (modes, 6): y' = lam y + modal_b u
    # exact propagation over h of y' = lam y + beta u(t), u linear: integrals of e^(lam (h-s))
    # times 1 and s over [0, h]
    e = np.exp(lam * h)
    i0 = (e - 1) / lam
    i1 = h * i0 - (h * e / lam - (e - 1) / lam**2)
    now, after = (i0 - i1 / h)[:, None] * modal_b, (i1 / h)[:, None] * modal_b
    # the modes sample by sample, (n, modes) complex, seen as (n, 2 modes) real (real and
    # imaginary parts interleaved): each product with the series is one real matrix product
    forced = np.empty((u.shape[1], len(lam)), dtype=complex)
    forced[0] = -(modal_b @ u[:, 0]) / lam  # the static equilibrium of u_0
    pairs = forced[1:].view(float)
    np.matmul(u[:, :-1].T, _interleaved(now.T), out=pairs)
    pairs += u[:, 1:].T @ _interleaved(after.T)
    y = ar1_filter(forced, e, overwrite=True)  # y_k = e y_k-1 + forced_k, in place
    # positions and rates of the body are states; accelerations are rows of A x + B u
    rows = np.r_[0:N_BODY, N_DOF:N_DOF + N_BODY]
    accel = slice(N_DOF, N_DOF + N_BODY)
    gain = np.vstack([vec[rows], vec[accel] * lam]) * weight
    out = _interleaved(np.conj(gain)) @ y.view(float).T  # Re(gain y), (15, n)
    out[2 * N_BODY:] += b[accel] @ u
    return out


def _interleaved(m: np.ndarray) -> np.ndarray:
    """A complex matrix (k, modes) as a real one (k, 2 modes), the real and imaginary parts of
    each mode side by side: for a real x (n, k), x @ result is the complex x @ m seen as
    interleaved parts; for complex y (n, modes) seen so, result @ y.T is Re(m y^T) when m is
    given conjugated."""
    return np.ascontiguousarray(m).view(float)
