"""GLONASS broadcast orbits: the state vector of each record integrated in the PZ-90 Earth-fixed
frame, the FDMA carrier frequencies and the slot-to-channel map.

A GLONASS navigation record gives the satellite's position, velocity and lunisolar acceleration
at t_b (PZ-90, Earth-fixed). The user integrates the equations of motion of GLONASS ICD
edition 5.1 (2008), Appendix A.3.1.2: central gravity with the J2 term, the centrifugal and
Coriolis terms of the rotating frame, and the broadcast lunisolar accelerations held constant,
with a 4th-order Runge-Kutta method.

Each record is integrated once, forward and backward from t_b over +- ``span_s`` (the age
beyond which a record is not used) at the fixed step ``STEP_S``, and the states at any time are
interpolated from those nodes with cubic Hermite polynomials (position from the nodes' position
and velocity, velocity from their velocity and acceleration). ``tests/gnss/test_gnss_glonass.py``
measures the difference to integrating each instant directly with a fine step: below a
millimetre in position (0.17 mm) and 1e-5 m/s in velocity.

PZ-90.11 and ITRF2014/IGS20 agree within a few centimetres (Zueva et al., "PZ-90.11 ...", IERS
Workshop 2014); the frames are not transformed.

Public names
------------
STEP_S, GLONASS_MAX_AGE_S, SLOT_CHANNELS, G1_BASE_HZ, G1_STEP_HZ, G2_BASE_HZ, G2_STEP_HZ,
carrier_frequencies_hz, acceleration, rk4_step, StateTable.

References
----------
GLONASS ICD, Navigational radiosignal in bands L1, L2, edition 5.1 (Russian Institute of Space
Device Engineering, 2008): 3.3.1.1 (carrier frequencies, Table 3.1), A.3.1.2 (the simplified
algorithm for re-calculation of ephemeris to the current time).
"""

from __future__ import annotations

import numpy as np

from simulator.gnss.constants import A_E_GLO_M, J2_GLO, MU_GLO_M3_S2, OMEGA_E_GLO_RAD_S

STEP_S = 30.0  # integration step of the node table, s (Hermite error ~ h^4: 0.1 mm)
GLONASS_MAX_AGE_S = 1800.0  # records come every 30 min with t_b in the middle: use within 30 min
G1_BASE_HZ, G1_STEP_HZ = 1602.0e6, 0.5625e6  # G1 = 1602 + k 0.5625 MHz (ICD 3.3.1.1)
G2_BASE_HZ, G2_STEP_HZ = 1246.0e6, 0.4375e6  # G2 = 1246 + k 0.4375 MHz
# orbital slot -> FDMA frequency number k (antipodal slots share a channel): the assignment of
# the operational constellation as published by the Information and Analysis Center for
# Positioning, Navigation and Timing (glonass-iac.ru, constellation status, 2023), the same as
# in the slot/frequency lines of real RINEX 3 headers (e.g. refdata 1f, pixel6.23o)
SLOT_CHANNELS: dict[int, int] = {
    1: 1, 2: -4, 3: 5, 4: 6, 5: 1, 6: -4, 7: 5, 8: 6,
    9: -2, 10: -7, 11: 0, 12: -1, 13: -2, 14: -7, 15: 0, 16: -1,
    17: 4, 18: -3, 19: 3, 20: 2, 21: 4, 22: -3, 23: 3, 24: 2,
}


def carrier_frequencies_hz(channel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """G1 and G2 carrier frequencies (Hz) of FDMA frequency numbers k (ICD Table 3.1)."""
    k = np.asarray(channel, dtype=float)
    return G1_BASE_HZ + k * G1_STEP_HZ, G2_BASE_HZ + k * G2_STEP_HZ


def acceleration(state: np.ndarray, lunisolar: np.ndarray) -> np.ndarray:
    """Acceleration (m/s^2) in the rotating PZ-90 frame (ICD 2008 A.3.1.2).

    Parameters
    ----------
    state : ndarray, shape (..., 6)
        Position (m) and velocity (m/s), Earth-fixed.
    lunisolar : ndarray, shape (..., 3)
        The broadcast lunisolar acceleration (m/s^2), held constant.
    """
    x, y, z = state[..., 0], state[..., 1], state[..., 2]
    vx, vy = state[..., 3], state[..., 4]
    r2 = x * x + y * y + z * z
    r = np.sqrt(r2)
    mu_r3 = MU_GLO_M3_S2 / (r2 * r)
    j2 = 1.5 * J2_GLO * MU_GLO_M3_S2 * A_E_GLO_M**2 / (r2 * r2 * r)
    z2 = 5.0 * z * z / r2
    w2 = OMEGA_E_GLO_RAD_S**2
    ax = -mu_r3 * x - j2 * x * (1.0 - z2) + w2 * x + 2.0 * OMEGA_E_GLO_RAD_S * vy
    ay = -mu_r3 * y - j2 * y * (1.0 - z2) + w2 * y - 2.0 * OMEGA_E_GLO_RAD_S * vx
    az = -mu_r3 * z - j2 * z * (3.0 - z2)
    return np.stack([ax, ay, az], axis=-1) + lunisolar


def _derivative(state: np.ndarray, lunisolar: np.ndarray) -> np.ndarray:
    return np.concatenate([state[..., 3:], acceleration(state, lunisolar)], axis=-1)


def rk4_step(state: np.ndarray, lunisolar: np.ndarray, h: np.ndarray | float) -> np.ndarray:
    """One classical 4th-order Runge-Kutta step of length ``h`` (s; negative: backward)."""
    h = np.asarray(h, dtype=float)[..., None]
    k1 = _derivative(state, lunisolar)
    k2 = _derivative(state + 0.5 * h * k1, lunisolar)
    k3 = _derivative(state + 0.5 * h * k2, lunisolar)
    k4 = _derivative(state + h * k3, lunisolar)
    return state + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


class StateTable:
    """Every record's orbit integrated once over t_b +- ``span_s`` at ``STEP_S``, interpolated.

    Parameters
    ----------
    state0 : ndarray, shape (n, 6)
        Position (m) and velocity (m/s) of each record at its t_b, PZ-90.
    lunisolar : ndarray, shape (n, 3)
        The records' lunisolar accelerations (m/s^2).
    span_s : float
        Half-width of the integrated interval around t_b (s).
    """

    def __init__(self, state0: np.ndarray, lunisolar: np.ndarray,
                 span_s: float = GLONASS_MAX_AGE_S):
        state0 = np.asarray(state0, dtype=float).reshape(-1, 6)
        self.lunisolar = np.asarray(lunisolar, dtype=float).reshape(-1, 3)
        self.n_side = int(np.ceil(span_s / STEP_S))
        n_nodes = 2 * self.n_side + 1
        nodes = np.empty((len(state0), n_nodes, 6))
        nodes[:, self.n_side] = state0
        forward, backward = state0, state0
        for k in range(1, self.n_side + 1):  # the physics is recursive in time
            forward = rk4_step(forward, self.lunisolar, STEP_S)
            backward = rk4_step(backward, self.lunisolar, -STEP_S)
            nodes[:, self.n_side + k] = forward
            nodes[:, self.n_side - k] = backward
        self.nodes = nodes
        self.accel = acceleration(nodes, self.lunisolar[:, None, :])

    def state(self, record: np.ndarray, dt_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Position and velocity (m, m/s; shape ``dt_s.shape + (3,)``) of records ``record``
        at ``dt_s`` seconds from their t_b (clipped to the integrated span)."""
        record = np.asarray(record, dtype=int)
        s = np.clip(np.asarray(dt_s, dtype=float) / STEP_S + self.n_side, 0.0,
                    2 * self.n_side - 1e-9)
        j = np.minimum(np.floor(s).astype(int), 2 * self.n_side - 1)
        u = (s - j)[..., None]
        a, b = self.nodes[record, j], self.nodes[record, j + 1]
        acc_a, acc_b = self.accel[record, j], self.accel[record, j + 1]
        pos = _hermite(a[..., :3], a[..., 3:], b[..., :3], b[..., 3:], u)
        vel = _hermite(a[..., 3:], acc_a, b[..., 3:], acc_b, u)
        return pos, vel


def _hermite(p0: np.ndarray, d0: np.ndarray, p1: np.ndarray, d1: np.ndarray,
             u: np.ndarray) -> np.ndarray:
    """Cubic Hermite interpolation on [0, 1] of a value with derivatives (per second) at both
    ends of one ``STEP_S`` interval."""
    u2, u3 = u * u, u * u * u
    return ((2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * STEP_S * d0
            + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * STEP_S * d1)


__all__ = ["STEP_S", "GLONASS_MAX_AGE_S", "SLOT_CHANNELS", "G1_BASE_HZ", "G1_STEP_HZ",
           "G2_BASE_HZ", "G2_STEP_HZ", "carrier_frequencies_hz", "acceleration", "rk4_step",
           "StateTable"]
