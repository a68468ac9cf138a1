"""The GNSS measurement model of every tightly coupled estimator, written once: predicted
pseudorange and pseudorange rate of the satellites of an epoch, vectorised over satellites and over
any leading axes of the receiver state (sigma points, for instance).

The raw stream (SPEC section 5) gives each satellite's position and velocity at transmission in
the ECEF frame of transmission, and the broadcast corrections in metres, so that

    corrected pseudorange   rho_c = pseudorange + sat_clock - iono - tropo
                                  = |R(omega_e tau) r_s - r_a| + cb + noise
    corrected range rate    rho_dot_c = pseudorange_rate + sat_clock_drift
                                      = d|...|/dt + d + noise

with r_a the antenna position, cb the receiver clock bias (m), d its drift (m/s),
tau = |...| / c the signal's flight time and R(omega_e tau) the rotation of the ECEF frame during
the flight (the Sagnac correction; Groves 2013, eq. 8.36; IS-GPS-200 20.3.3.4.3.4). The satellite
clock columns already hold the relativistic term, as Android's SvClockBiasMeters does (refdata 3b).
This is Chan et al. eq. 7 written out: the paper's eq. 7 lacks the receiver position (the antenna
is r_ins + C_b^n l_b, not C_b^n l_b alone) and prints "+" for the inner product; it is
||r_i - r_ins - C_b^n l_b|| here.

The range rate (Chan et al. eq. 8) is the exact time derivative of the range above:
los . (R v_s - v_a) / (1 - B / c), B = los . (omega_e R' r_s - R v_s) the rate of the frame
rotation and of the flight time; the factor differs from one by about 1e-5 (the simulator's own
model, ``simulator.gnss.receiver.signal_geometry``, is the same derivative). The antenna velocity is
v + C_b^n (w_eb^b x l_b) (Chan et al. eq. 8; Groves eq. 14.110 for the lever arm).

Line-of-sight Jacobians (Groves eqs. 14.127-14.128): d rho / d r_a = -los^T,
d rho_dot / d v_a = -los^T, and one for cb and for d. The receiver clock is the two-state model
x = [cb, d], Phi = [[1, dt], [0, 1]], Q from the oscillator's Allan h-parameters (Brown & Hwang,
*Introduction to Random Signals and Applied Kalman Filtering*, 4th ed., section 9.3; flicker
noise h_-1 left out): S_f = h0 / 2, S_g = 2 pi^2 h_-2, times c^2 for metres.

Innovation gating is not here: neither tightly coupled seed paper describes one, and the opt-in
chi-square gate is the toolbox's ``gating`` block.

The constants (speed of light, the GPS Earth rotation rate) are imported from their one home,
``simulator.gnss.constants``, a leaf module of numbers only.

Public names
------------
RawEpoch, single_frequency, raw_epoch, select, predict, los_jacobians, antenna_offset,
clock_transition, clock_noise, correlated_noise_inflation, nlos_sigma, nlos_delay, NLOS_SIGMA_M,
TCXO_H0,
TCXO_H_MINUS2.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields

import numpy as np

from simulator.datasheet import Cn0Template, nlos_delay_moments, nlos_probability
from simulator.gnss.constants import C_M_S, OMEGA_E_DOT_RAD_S

SAGNAC_ITERATIONS = 2  # flight-time iterations: the second changes the range by < 1e-6 m
# a temperature-compensated crystal, Brown & Hwang Table 9.1 (the automotive receiver's clock)
TCXO_H0 = 2e-19  # white-frequency Allan coefficient h_0, s
TCXO_H_MINUS2 = 2e-20  # random-walk-frequency Allan coefficient h_-2, 1/s


@dataclass(frozen=True)
class RawEpoch:
    """The measurements of one epoch, corrected with the broadcast models, shape (m,) each.

    Attributes
    ----------
    sv : satellite numbers; sat_pos, sat_vel : (m, 3) satellite ECEF state at transmission
    (frame of transmission), m and m/s; pseudorange : corrected pseudorange rho_c, m;
    range_rate : corrected pseudorange rate rho_dot_c, m/s; pseudorange_std, range_rate_std : the
    receiver's reported 1-sigma (NaN when the stream has none); iono : the broadcast
    ionosphere delay removed from the pseudorange, m; elevation : rad; cn0 : dB-Hz; azimuth :
    rad, from north through east (each NaN when the stream lacks the column).
    """

    sv: np.ndarray
    sat_pos: np.ndarray
    sat_vel: np.ndarray
    pseudorange: np.ndarray
    range_rate: np.ndarray
    pseudorange_std: np.ndarray
    range_rate_std: np.ndarray
    iono: np.ndarray | None = None
    elevation: np.ndarray | None = None
    cn0: np.ndarray | None = None
    azimuth: np.ndarray | None = None


L1_BAND_HZ = (1559e6, 1592e6)  # the L1/E1/B1 band (B1I 1561.098, L1/E1 1575.42 MHz)


def single_frequency(block: np.ndarray, columns: Mapping[str, int]) -> np.ndarray:
    """The rows of a ``gnss_raw`` epoch block in the L1/E1/B1 band (all rows of a stream
    without ``frequency``): what a single-frequency filter takes from a receiver that tracks
    several signals per satellite (each row's ``iono`` is that of its own frequency)."""
    if "frequency" not in columns:
        return block
    f = block[:, columns["frequency"]]
    return block[(f > L1_BAND_HZ[0]) & (f < L1_BAND_HZ[1])]


def raw_epoch(block: np.ndarray, columns: Mapping[str, int]) -> RawEpoch:
    """Corrected measurements of a ``gnss_raw`` epoch block (rows = satellites) whose column
    positions are ``columns`` (the replay's ``self.columns["gnss_raw"]``). Rows of unhealthy
    satellites (``health`` not 0, where the stream has the column) are left out."""
    if "health" in columns:
        block = block[block[:, columns["health"]] == 0]
    def c(name: str) -> np.ndarray:
        return block[:, columns[name]]

    def optional(name: str) -> np.ndarray:
        return c(name) if name in columns else np.full(len(block), np.nan)

    return RawEpoch(
        sv=c("sv"),
        sat_pos=block[:, [columns["sat_x"], columns["sat_y"], columns["sat_z"]]],
        sat_vel=block[:, [columns["sat_vx"], columns["sat_vy"], columns["sat_vz"]]],
        pseudorange=c("pseudorange") + c("sat_clock") - c("iono") - c("tropo"),
        range_rate=c("pseudorange_rate") + c("sat_clock_drift"),
        pseudorange_std=optional("pseudorange_std"),
        range_rate_std=optional("pseudorange_rate_std"),
        iono=optional("iono"), elevation=optional("elevation"), cn0=optional("cn0"),
        azimuth=optional("azimuth"))


def select(epoch: RawEpoch, keep: np.ndarray) -> RawEpoch:
    """The epoch's satellites where the boolean mask ``keep`` (m,) is true (an innovation
    gate's survivors, for instance)."""
    return RawEpoch(*(None if v is None else v[keep]
                      for v in (getattr(epoch, f.name) for f in fields(RawEpoch))))


def _rotate_z(vec: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Coordinates after the frame turns by theta about z: R(theta) v (Groves eq. 8.36)."""
    cos_t, sin_t = np.cos(theta), np.sin(theta)
    x, y, z = np.broadcast_arrays(vec[..., 0], vec[..., 1], vec[..., 2], cos_t)[:3]
    return np.stack([cos_t * x + sin_t * y, -sin_t * x + cos_t * y, z], axis=-1)


def predict(sat_pos: np.ndarray, sat_vel: np.ndarray, rx_pos: np.ndarray, rx_vel: np.ndarray,
            clock_bias_m: np.ndarray | float = 0.0, clock_drift_m_s: np.ndarray | float = 0.0
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Predicted corrected pseudoranges and range rates.

    Parameters
    ----------
    sat_pos, sat_vel : (m, 3)
        Satellite ECEF position (m) and velocity (m/s) at transmission, frame of transmission.
    rx_pos, rx_vel : (..., 3)
        Antenna ECEF position (m) and velocity (m/s) at reception; any leading axes (k sigma
        points, ...) broadcast against the m satellites.
    clock_bias_m, clock_drift_m_s : float or (...)
        Receiver clock bias c dt_r (m) and drift (m/s).

    Returns
    -------
    pseudorange : (..., m), m; range_rate : (..., m), m/s; los : (..., m, 3) unit vectors from
    the antenna to the satellites, ECEF of reception.
    """
    rx_pos = np.asarray(rx_pos, dtype=float)[..., None, :]
    rx_vel = np.asarray(rx_vel, dtype=float)[..., None, :]
    rel = sat_pos - rx_pos
    rng = np.sqrt(np.einsum("...k,...k->...", rel, rel))
    for _ in range(SAGNAC_ITERATIONS):
        theta = OMEGA_E_DOT_RAD_S * rng / C_M_S
        rel = _rotate_z(sat_pos, theta) - rx_pos
        rng = np.sqrt(np.einsum("...k,...k->...", rel, rel))
    los = rel / rng[..., None]
    vel_rx_frame = _rotate_z(sat_vel, theta)
    cos_t, sin_t = np.cos(theta), np.sin(theta)
    x, y = sat_pos[..., 0], sat_pos[..., 1]
    spin_x, spin_y = -sin_t * x + cos_t * y, -cos_t * x - sin_t * y
    spin = OMEGA_E_DOT_RAD_S * np.stack([spin_x, spin_y, np.zeros_like(spin_x)], axis=-1)
    light_time = 1.0 - np.einsum("...k,...k->...", los, spin - vel_rx_frame) / C_M_S
    rate = np.einsum("...k,...k->...", los, vel_rx_frame - rx_vel) / light_time
    clock_bias_m = np.asarray(clock_bias_m, dtype=float)[..., None]
    clock_drift_m_s = np.asarray(clock_drift_m_s, dtype=float)[..., None]
    return rng + clock_bias_m, rate + clock_drift_m_s, los


def los_jacobians(los: np.ndarray) -> np.ndarray:
    """Rows [d/d r_a (3), d/d cb] of the pseudoranges, the same as [d/d v_a (3), d/d d] of the
    range rates (the line of sight's own change with position, |v| / range ~ 1e-6, left out).

    Parameters
    ----------
    los : (m, 3) unit lines of sight, ECEF.

    Returns
    -------
    (m, 4) [-los, 1].
    """
    return np.concatenate([-los, np.ones((len(los), 1))], axis=1)


def antenna_offset(c_bn: np.ndarray, lever_b: np.ndarray, w_eb_b: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The antenna's offset from the IMU in NED and its velocity relative to the IMU
    (Chan et al. eqs. 7-8: C_b^n l_b and C_b^n (w_eb^b x l_b)).

    Parameters
    ----------
    c_bn : (..., 3, 3) body-to-NED rotation; lever_b : (3,) IMU-to-antenna lever arm, FRD, m;
    w_eb_b : (..., 3) body rate with respect to the Earth, FRD, rad/s.

    Returns
    -------
    offset_ned : (..., 3), m; velocity_ned : (..., 3), m/s.
    """
    lever_b = np.asarray(lever_b, dtype=float)
    offset = c_bn @ lever_b
    vel = np.einsum("...ij,...j->...i", c_bn, np.cross(w_eb_b, lever_b))
    return offset, vel


def clock_transition(dt_s: float) -> np.ndarray:
    """Transition matrix of [cb, d] over ``dt_s``: [[1, dt], [0, 1]]."""
    return np.array([[1.0, dt_s], [0.0, 1.0]])


def clock_noise(dt_s: float, h0: float = TCXO_H0, h_minus2: float = TCXO_H_MINUS2
                ) -> np.ndarray:
    """Discrete process noise of [cb (m), d (m/s)] over ``dt_s`` from the Allan h-parameters:
    c^2 [[S_f dt + S_g dt^3 / 3, S_g dt^2 / 2], [S_g dt^2 / 2, S_g dt]], S_f = h0 / 2,
    S_g = 2 pi^2 h_-2 (Brown & Hwang section 9.3)."""
    s_f, s_g = h0 / 2.0, 2.0 * np.pi**2 * h_minus2
    return C_M_S**2 * np.array([[s_f * dt_s + s_g * dt_s**3 / 3.0, s_g * dt_s**2 / 2.0],
                                [s_g * dt_s**2 / 2.0, s_g * dt_s]])


def correlated_noise_inflation(correlation_time_s: float, interval_s: float) -> float:
    """Factor on a measurement's 1-sigma that makes a filter treating it as white count a
    first-order Gauss-Markov error of correlation time T, sampled every dt, at its real worth.

    The mean of N samples of such an error (an AR(1) sequence, phi = exp(-dt / T)) has, for
    N dt >> T, the variance sigma^2 (1 + phi) / ((1 - phi) N): the sum of its autocorrelations
    sigma^2 phi^|k| over all lags, i.e. its long-run variance, (1 + phi) / (1 - phi) times what
    N white samples give; the sigma is scaled by the square root of that (sqrt(2 T / dt) for
    T >> dt). T = 0 (a white error) gives 1. It makes the long-run weight right and the
    epoch-to-epoch weight too small: the price of not carrying the errors as states.
    """
    if correlation_time_s <= 0.0:
        return 1.0
    phi = np.exp(-interval_s / correlation_time_s)
    return float(np.sqrt((1.0 + phi) / (1.0 - phi)))


NLOS_SIGMA_M = 20.0  # a reflected signal's extra path, 1-sigma (gnss_wls's module docstring)


def nlos_sigma(sigma: np.ndarray, cn0: np.ndarray, elevation: np.ndarray,
               template: Cn0Template, nlos_sigma_m: float) -> np.ndarray:
    """Each pseudorange's 1-sigma with the reflected-signal (NLOS) error its C/N0 announces:
    sigma^2 + p nlos_sigma_m^2, p = ``nlos_probability`` of its deficit below the template at
    its elevation (``estimators/builtin/gnss_wls.py``'s module docstring: the extra
    path's spread, 20 m there)."""
    p = nlos_probability(template.expected_dbhz(elevation) - cn0, template.scatter_db)
    return np.sqrt(sigma**2 + p * nlos_sigma_m**2)


def nlos_delay(cn0: np.ndarray, elevation: np.ndarray, template: Cn0Template
               ) -> tuple[np.ndarray, np.ndarray]:
    """Each pseudorange's expected reflected-signal (NLOS) delay and its variance (m, m^2), from
    the probability p that its C/N0 deficit below the template at its elevation announces
    (``nlos_probability``) and the receiver's model of a reflection's extra path
    (``simulator.datasheet.nlos_delay_moments``, the model of the receiver's own fix
    accuracy): p mu and p (mu^2 + s^2) - (p mu)^2. A signal without C/N0 (NaN) is taken as
    direct."""
    deficit = template.expected_dbhz(elevation) - np.where(np.isfinite(cn0), cn0, np.inf)
    p = nlos_probability(deficit, template.scatter_db)
    mean, mean_square = nlos_delay_moments(p)
    return mean, mean_square - mean**2
