"""Pseudo-measurements of land-vehicle motion constraints, with their Jacobians with respect
to the navigation error state of ``estimators.toolbox.nav_error`` ([dr, dv, psi], estimate minus
truth), and the noise of the non-holonomic constraint from a car's physics.

* Velocity of a point of the body: the point at r (body FRD, from the IMU) moves with
  v_ref^b = C_n^b v^n + w^b x r, w^b the body rate (with respect to the Earth; the IMU's
  compensated rate differs by the Earth rate, 7.3e-5 rad/s x r, under 1e-4 m/s for r of a few
  metres). With C(estimate) = (I + [psi x]) C(true) and the gyro-bias error dbg (estimate minus
  truth, so the compensated rate is w - dbg), v_ref^b(estimate) ~ v_ref^b + C_n^b dv +
  C_n^b [v^n x] psi + [r x] dbg: H = [0, C_n^b, C_n^b [v^n x], ..., [r x] on the gyro-bias
  block] (Groves 2013, section 16.2.4, the lever arm of a wheel-speed sensor).
* Non-holonomic constraint: a wheeled vehicle does not slide sideways or leave the road, so the
  lateral (y) and vertical (z) body velocity is zero (Chan et al., "non-holonomic constraint";
  Tan et al. 2008 velocity constraint), rows y, z of the above. It holds where the wheels do not
  steer: at the rear axle of a car, not at the IMU, whose lateral velocity in a turn is the yaw
  rate times its distance ahead of the rear axle (Rajamani 2012, eq. 2.29: the kinematic bicycle
  model's rear-axle velocity lies along the body). With ``lever_arm`` None the constraint is
  applied at the IMU (a rigid point, the old form).
* ``NonholonomicNoise``: what remains of the constraint at the rear axle on a real car, as a
  1-sigma per row from quantities known before any drive (class docstring).
* Height constraint: the height is known (a flat road, a map), h(estimate) = h - dr_d, so
  H = [0, 0, -1, 0 ...] (Tan et al. 2008).

Each function returns dz = h(estimate) - z, ready for ``kalman.ErrorState.update``, and H over
``n_states`` columns with the navigation block in the first nine.

Public names
------------
body_velocity, body_velocity_points, nonholonomic, NonholonomicNoise, height.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from simulator.earth import quat_to_dcm, skew

G0 = 9.80665  # standard gravity, m/s^2
DEG = math.pi / 180.0


def body_velocity(q: np.ndarray, v_ned: np.ndarray, n_states: int = 9,
                  rate_body: np.ndarray | None = None, lever_arm: np.ndarray | None = None,
                  gyro_bias: slice | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Body-frame velocity of a point of the body, and its Jacobian (module docstring).

    Parameters
    ----------
    q : (4,) estimated body-to-NED quaternion; v_ned : (3,) estimated NED velocity of the IMU,
        m/s.
    n_states : int
        Length of the error state (>= 9).
    rate_body : (3,), optional
        Bias-compensated body rate, rad/s (needed with ``lever_arm``).
    lever_arm : (3,), optional
        The point from the IMU, body FRD, m; None: the IMU itself.
    gyro_bias : slice, optional
        Columns of the gyro-bias error (estimate minus truth) in the state; None: not carried.

    Returns
    -------
    v : (3,) the point's body-frame velocity, m/s; h : (3, n_states) its Jacobian.
    """
    c_nb = quat_to_dcm(q).T
    v_b = c_nb @ v_ned
    h = np.zeros((3, n_states))
    h[:, 3:6] = c_nb
    h[:, 6:9] = c_nb @ skew(v_ned)
    if lever_arm is not None:
        r = np.asarray(lever_arm, dtype=float)
        v_b = v_b + skew(rate_body) @ r  # w x r (np.cross costs 2 us of checks per call)
        if gyro_bias is not None:
            h[:, gyro_bias] = skew(r)
    return v_b, h


def body_velocity_points(c_bn: np.ndarray, v_ned: np.ndarray, rate_body: np.ndarray | None = None,
                         lever_arm: np.ndarray | None = None) -> np.ndarray:
    """``body_velocity``'s value for a set of states at once (the sigma points of an unscented
    filter, which needs no Jacobian): C_n^b v^n + w^b x r.

    Parameters
    ----------
    c_bn : (k, 3, 3) body-to-NED rotations; v_ned : (k, 3) NED velocities of the IMU, m/s.
    rate_body : (k, 3), optional
        Bias-compensated body rates, rad/s (needed with ``lever_arm``).
    lever_arm : (3,), optional
        The point from the IMU, body FRD, m; None: the IMU itself.

    Returns
    -------
    v : (k, 3) the point's body-frame velocity of each state, m/s.
    """
    v_b = np.einsum("kji,kj->ki", c_bn, v_ned)
    if lever_arm is not None:
        v_b = v_b + np.cross(rate_body, np.asarray(lever_arm, dtype=float))
    return v_b


def nonholonomic(q: np.ndarray, v_ned: np.ndarray, n_states: int = 9,
                 rate_body: np.ndarray | None = None, lever_arm: np.ndarray | None = None,
                 gyro_bias: slice | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Zero lateral and vertical body velocity at a point of the body (``body_velocity``'s
    arguments; for a car the rear axle, ``lever_arm`` from the IMU).

    Returns
    -------
    dz : (2,) estimated lateral and vertical velocity of the point (the constraint says 0),
        m/s; h : (2, n_states) Jacobian with respect to [dr, dv, psi, ...].
    """
    v_b, h = body_velocity(q, v_ned, n_states, rate_body, lever_arm, gyro_bias)
    return v_b[1:3], h[1:3]


@dataclass(frozen=True)
class NonholonomicNoise:
    """1-sigma of the non-holonomic constraint at a car's rear axle, from the car's physics as
    a user knows it before any drive (never fitted to a drive's errors).

    * Lateral: the rear tyres slip by the angle alpha_r = F_yr / C_r = (m_r / C_r) a_y in a
      steady turn (the linear bicycle model, Rajamani 2012, eqs. 3.9-3.12 and 3.45; m_r the mass
      on the rear axle, C_r its cornering stiffness), so the rear axle moves sideways at
      v alpha_r = D_r v a_y, a_y = v w_z. The cornering compliance D_r = m_r / C_r = 1 / (CC g)
      with CC the tyre's cornering coefficient (cornering stiffness per unit load): radial
      passenger-car tyres about 0.15 per degree, range 0.11-0.19 (Gillespie, *Fundamentals of
      Vehicle Dynamics*, SAE 1992, pp. 347-355), so D_r = 6.7 deg/g. The slip has a known sign
      (outward), but its size is the tyre's, so it is taken as noise of that size.
    * Vertical: the body pitches on its springs under a longitudinal acceleration a_x, by
      theta = m h a_x / K_pitch with K_pitch = m w^2 l_f l_r (both axles at the ride frequency
      w; Gillespie ch. 5, eq. 5-5), so the rear axle's velocity leaves the body's x axis by
      v theta = v a_x h / (w^2 l_f l_r). Chosen: a typical saloon's centre-of-gravity height
      0.55 m, the lower end of Gillespie's ride frequencies, 1.0 Hz, and l_f = l_r = L / 2 from
      the wheelbase L. And the suspension's travel over the road's roughness: the road's
      vertical velocity seen at speed v has a white spectrum 4 pi^2 G_d(n0) n0^2 v (ISO
      8608:2016, waviness 2; class B, G_d(0.1) = 64e-6 m^3, a good road assumed), which the
      suspension passes up to the wheel-hop frequency, 10 Hz (Gillespie ch. 5), so
      sigma^2 = 4 pi^2 G_d(n0) n0^2 |v| x 10 Hz.
    * ``floor``: every other motion the constraint does not model (roll about the roll axis,
      the IMU's own installation), 0.1 m/s: the value Park's filter used for a rigid body.

    Parameters
    ----------
    wheelbase : float
        Front to rear axle, m (the user's car).
    """

    wheelbase: float
    cornering_coefficient: float = 0.15 / DEG  # per rad (Gillespie: 0.15 per degree)
    cg_height: float = 0.55  # m
    ride_frequency: float = 1.0  # Hz
    roughness: float = 64e-6  # ISO 8608 G_d(n0), m^3 (class B)
    wheel_hop: float = 10.0  # Hz
    floor: float = 0.1  # m/s

    @property
    def cornering_compliance(self) -> float:
        """D_r, rad of rear slip per m/s^2 of lateral acceleration."""
        return 1.0 / (self.cornering_coefficient * G0)

    @property
    def pitch_compliance(self) -> float:
        """Suspension pitch per longitudinal acceleration, rad per m/s^2."""
        half = 0.5 * self.wheelbase
        return self.cg_height / ((2 * math.pi * self.ride_frequency) ** 2 * half * half)

    def sigma_of_state(self, q: np.ndarray, v_ned: np.ndarray, rate_body: np.ndarray,
                       force_body: np.ndarray) -> tuple[float, float]:
        """``sigma`` from a navigation state: the forward speed C_b^n[:, 0] . v^n, the body's
        yaw rate, and the forward acceleration f_x + g C_b^n[2, 0] (the specific force plus
        gravity's body-x part, -g sin(pitch); standard gravity is close enough for a sigma)."""
        c_bn = quat_to_dcm(q)
        return self.sigma(float(c_bn[:, 0] @ v_ned), float(rate_body[2]),
                          float(force_body[0] + G0 * c_bn[2, 0]))

    def sigma(self, speed: float, yaw_rate: float, forward_accel: float) -> tuple[float, float]:
        """Lateral and vertical 1-sigma (m/s) at speed (m/s), yaw rate (rad/s) and forward
        acceleration (m/s^2)."""
        v = abs(speed)
        lateral = self.cornering_compliance * v * v * abs(yaw_rate)
        pitch = self.pitch_compliance * v * abs(forward_accel)
        travel2 = 4 * math.pi**2 * self.roughness * 0.01 * v * self.wheel_hop  # n0 = 0.1 /m
        f2 = self.floor * self.floor
        return math.sqrt(f2 + lateral * lateral), math.sqrt(f2 + pitch * pitch + travel2)


def height(h_estimate: float, h_reference: float, n_states: int = 9
           ) -> tuple[np.ndarray, np.ndarray]:
    """Known height.

    Parameters
    ----------
    h_estimate : estimated ellipsoidal height, m; h_reference : the known height, m.

    Returns
    -------
    dz : (1,) h_estimate - h_reference, m; h : (1, n_states) Jacobian, -1 on dr_d.
    """
    h = np.zeros((1, n_states))
    h[0, 2] = -1.0
    return np.array([h_estimate - h_reference]), h
