"""The signal and the receiver's tracking: geometric ranges from the transmit-time iteration with
the Earth-rotation (Sagnac) correction, their exact rates, the receiver clock, C/N0, code and
frequency tracking noise, and the correlated error processes (multipath, atmospheric residuals,
signal-in-space error).

Every function works on whole arrays (satellites x epochs). The correlated (Gauss-Markov)
processes come from ``simulator.stochastic``, the one home of sensor noise processes.

Public functions
----------------
rotate_to_reception_frame, light_time_factor, signal_geometry, look_angles, clock_process,
cn0_model, dll_sigma_m, fll_sigma_hz, multipath_sigma_m.

References
----------
Groves 2013 (*Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*,
2nd ed.): eq. 8.36 (Sagnac correction by rotating the satellite position through omega_e tau),
eqs. 9.50 and 9.52 (code DLL and FLL tracking-noise standard deviations).
Kaplan & Hegarty, *Understanding GPS/GNSS*, 3rd ed., 2017, eq. 8.51 (noncoherent early-minus-late
DLL jitter) and eq. 8.37 (FLL jitter).
Brown & Hwang, *Introduction to Random Signals and Applied Kalman Filtering*, 4th ed., 2012,
section 9.3 and Table 9.1 (two-state clock model from the Allan h-parameters).
RTCA DO-229D, section J.2.4 (elevation dependence of multipath: 0.13 + 0.53 exp(-el/10 deg) m).
"""

from __future__ import annotations

import numpy as np

from simulator.datasheet import nominal_cn0_dbhz
from simulator.earth import ned_to_ecef_matrix
from simulator.gnss.constants import C_M_S, CHIP_L1CA_M, OMEGA_E_DOT_RAD_S
from simulator.gnss.ephemeris import satellite_state

_LIGHT_TIME_ITERATIONS = 4  # fixed-point steps on tau: 1e-12 s after four from 0.075 s
_FIRST_TAU_S = 0.075  # the flight time the steps start from (MEO to GEO: 0.064-0.13 s)


def rotate_to_reception_frame(vec: np.ndarray, tau_s: np.ndarray) -> np.ndarray:
    """Coordinates in the ECEF frame of reception of vectors (..., 3) given in the ECEF frame of
    transmission, tau earlier: rotation about z by -omega_e tau (Groves eq. 8.36)."""
    theta = OMEGA_E_DOT_RAD_S * np.asarray(tau_s)
    cos_t, sin_t = np.cos(theta), np.sin(theta)
    x, y = vec[..., 0], vec[..., 1]
    return np.stack([cos_t * x + sin_t * y, -sin_t * x + cos_t * y, vec[..., 2]], axis=-1)


def light_time_factor(los: np.ndarray, sat_pos_m: np.ndarray, sat_vel_rx_frame_m_s: np.ndarray,
                      tau_s: np.ndarray) -> np.ndarray:
    """The factor 1 - B / c relating the range rate to its first-order value:
    d(range)/dt = los . (R v_s - v_r) / (1 - B / c), with
    B = los . (omega_e R'(omega_e tau) r_s - R v_s), from differentiating
    |R(omega_e tau) r_s(t - tau) - r_r(t)| with d(tau)/dt = (d range/dt) / c.

    ``sat_pos_m`` is in the ECEF frame of transmission, ``sat_vel_rx_frame_m_s`` already rotated
    into the frame of reception; shapes (..., 3), result (...).
    """
    theta = OMEGA_E_DOT_RAD_S * np.asarray(tau_s)
    cos_t, sin_t = np.cos(theta), np.sin(theta)
    x, y = sat_pos_m[..., 0], sat_pos_m[..., 1]
    # d/dtheta of the rotation applied to r_s, times omega_e: the rate of the frame change
    spin = OMEGA_E_DOT_RAD_S * np.stack([-sin_t * x + cos_t * y, -cos_t * x - sin_t * y,
                                         np.zeros_like(x)], axis=-1)
    b = np.einsum("...k,...k->...", los, spin - sat_vel_rx_frame_m_s)
    return 1.0 - b / C_M_S


def signal_geometry(eph: dict[str, np.ndarray], t_rx_s: np.ndarray, rx_pos_m: np.ndarray,
                    rx_vel_m_s: np.ndarray) -> dict[str, np.ndarray]:
    """Transmit time, satellite state and geometric range of each signal received at t_rx.

    Parameters
    ----------
    eph : dict of ndarray, each of shape S = (n_sat, n_epoch)
        Gathered broadcast parameters (``ephemeris.gather``).
    t_rx_s : ndarray, shape (n_epoch,)
        True GPS time of reception, s on the ephemeris time axis.
    rx_pos_m, rx_vel_m_s : ndarray, shape (n_epoch, 3)
        Antenna ECEF position and velocity at reception.

    Returns
    -------
    dict with
        ``tau`` (S, s): signal flight time, solving c tau = |R(omega_e tau) r_s(t - tau) - r_r|;
        ``pos``, ``vel`` (S + (3,)): satellite state at transmission in the ECEF frame of
        transmission; ``clock_s``, ``clock_drift_s_s`` (S): broadcast satellite clock;
        ``system_time_offset_s`` (S): its system's time minus GPS time (``ephemeris``);
        ``range`` (S, m): c tau, the geometric range including the Sagnac term;
        ``range_rate`` (S, m/s): its exact time derivative (with d tau/dt and the rotation's
        own rate); ``tau_rate`` (S): d tau / dt; ``los`` (S + (3,)): unit vector from antenna
        to satellite, ECEF of reception; ``los_rate`` (S + (3,), 1/s): its time derivative.
    """
    t_rx = np.broadcast_to(np.asarray(t_rx_s, dtype=float), eph["toe_s"].shape)
    tau = np.full(t_rx.shape, _FIRST_TAU_S)
    # the fixed-point steps move the satellite along its velocity at t - 0.075 s: within
    # |a| dtau^2 / 2 of its orbit (0.1 mm for a MEO, 0.3 mm for a GEO 0.055 s further), so tau
    # converges within 1e-12 s, and the orbit is evaluated once more, exactly, at t - tau
    first = satellite_state(eph, t_rx - tau)
    for _ in range(_LIGHT_TIME_ITERATIONS):
        moved = first["pos"] + first["vel"] * (_FIRST_TAU_S - tau)[..., None]
        rel = rotate_to_reception_frame(moved, tau) - rx_pos_m[None, :, :]
        tau = np.linalg.norm(rel, axis=-1) / C_M_S
    state = satellite_state(eph, t_rx - tau)
    rel = rotate_to_reception_frame(state["pos"], tau) - rx_pos_m[None, :, :]
    rng = np.linalg.norm(rel, axis=-1)
    los = rel / rng[..., None]
    vel_rx_frame = rotate_to_reception_frame(state["vel"], tau)
    a = np.einsum("...k,...k->...", los, vel_rx_frame - rx_vel_m_s[None, :, :])
    rate = a / light_time_factor(los, state["pos"], vel_rx_frame, tau)
    v_rel = vel_rx_frame - rx_vel_m_s[None, :, :]
    los_rate = (v_rel - np.einsum("...k,...k->...", los, v_rel)[..., None] * los) / rng[..., None]
    return {"tau": rng / C_M_S, "pos": state["pos"], "vel": state["vel"], "los_rate": los_rate,
            "clock_s": state["clock_s"], "clock_drift_s_s": state["clock_drift_s_s"],
            "system_time_offset_s": state["system_time_offset_s"], "range": rng,
            "range_rate": rate, "los": los, "tau_rate": rate / C_M_S}


def look_angles(los: np.ndarray, los_rate: np.ndarray, lat_rad: np.ndarray, lon_rad: np.ndarray
                ) -> dict[str, np.ndarray]:
    """Elevation and azimuth (from north, clockwise; in [0, 2 pi)) of unit lines of sight, and
    their rates.

    Parameters
    ----------
    los, los_rate : ndarray, shape (n_sat, n_epoch, 3)
        Unit line of sight (ECEF) and its time derivative (1/s).
    lat_rad, lon_rad : ndarray, shape (n_epoch,)
        Receiver position.

    Returns
    -------
    dict with ``elevation``, ``azimuth`` (rad) and ``elevation_rate``, ``azimuth_rate``
    (rad/s), each (n_sat, n_epoch).
    """
    c_ne = ned_to_ecef_matrix(lat_rad, lon_rad)
    u = np.einsum("eji,sej->sei", c_ne, los)
    du = np.einsum("eji,sej->sei", c_ne, los_rate)
    el = np.arcsin(np.clip(-u[..., 2], -1.0, 1.0))
    horizontal = np.maximum(u[..., 0] ** 2 + u[..., 1] ** 2, 1e-18)
    return {
        "elevation": el,
        "azimuth": np.mod(np.arctan2(u[..., 1], u[..., 0]), 2.0 * np.pi),
        "elevation_rate": -du[..., 2] / np.maximum(np.cos(el), 1e-9),
        "azimuth_rate": (u[..., 0] * du[..., 1] - u[..., 1] * du[..., 0]) / horizontal,
    }


def clock_process(n: int, dt_s: float, h0: float, h_minus2: float, bias0_s: float,
                  drift0_s_s: float, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Receiver clock bias (s) and drift (s/s) at n epochs dt apart: the two-state model
    x_{k+1} = [[1, dt], [0, 1]] x_k + w_k with
    Q = [[S_f dt + S_g dt^3 / 3, S_g dt^2 / 2], [S_g dt^2 / 2, S_g dt]], S_f = h0 / 2,
    S_g = 2 pi^2 h_-2 (Brown & Hwang section 9.3; flicker noise h_-1 is not modelled)."""
    s_f, s_g = h0 / 2.0, 2.0 * np.pi**2 * h_minus2
    q = np.array([[s_f * dt_s + s_g * dt_s**3 / 3.0, s_g * dt_s**2 / 2.0],
                  [s_g * dt_s**2 / 2.0, s_g * dt_s]])
    if q[0, 0] > 0:
        w = rng.standard_normal((max(n - 1, 0), 2)) @ np.linalg.cholesky(q).T
    else:
        w = np.zeros((max(n - 1, 0), 2))
    drift = drift0_s_s + np.concatenate([[0.0], np.cumsum(w[:, 1])])
    bias = bias0_s + np.concatenate([[0.0], np.cumsum(drift[:-1] * dt_s + w[:, 0])])
    return bias, drift




def cn0_model(elevation_rad: np.ndarray, zenith_dbhz: float, horizon_dbhz: float) -> np.ndarray:
    """Carrier-to-noise density, dB-Hz, from the antenna gain pattern and the path through the
    atmosphere: zenith - (zenith - horizon) exp(-el / 17 deg).

    The shape was fitted to the L1 C/N0 of the ARL1 station receiver on 2015-07-19 (refdata
    ``arlm200a.15o``, S1 against elevation: 34.8, 40.1, 44.3, 45.8 and 46.1 dB-Hz in the 10-20,
    20-30, 30-45, 45-60 and 60-90 deg bands), which it follows within 1 dB with the defaults
    zenith 46.5 and horizon 18 dB-Hz.
    """
    return nominal_cn0_dbhz(elevation_rad, zenith_dbhz, horizon_dbhz)


def dll_sigma_m(cn0_dbhz: np.ndarray, bandwidth_hz: float, spacing_chip: float,
                integration_s: float) -> np.ndarray:
    """Code tracking (DLL thermal noise) standard deviation, m, of a noncoherent early-minus-late
    power discriminator: sigma = chip sqrt(B d / (2 c/n0) (1 + 2 / (T (2 - d) c/n0)))
    (Kaplan & Hegarty eq. 8.51; Groves eq. 9.50)."""
    cn0 = 10.0 ** (np.asarray(cn0_dbhz) / 10.0)
    var = bandwidth_hz * spacing_chip / (2.0 * cn0) * (
        1.0 + 2.0 / (integration_s * (2.0 - spacing_chip) * cn0))
    return CHIP_L1CA_M * np.sqrt(var)


def fll_sigma_hz(cn0_dbhz: np.ndarray, bandwidth_hz: float, integration_s: float) -> np.ndarray:
    """Frequency tracking (FLL thermal noise) standard deviation, Hz:
    sigma = 1 / (2 pi T) sqrt(4 F B / c/n0 (1 + 1 / (T c/n0))), F = 1 above 35 dB-Hz, 2 below
    (Kaplan & Hegarty eq. 8.37; Groves eq. 9.52)."""
    cn0_db = np.asarray(cn0_dbhz)
    cn0 = 10.0 ** (cn0_db / 10.0)
    f = np.where(cn0_db >= 35.0, 1.0, 2.0)
    return np.sqrt(4.0 * f * bandwidth_hz / cn0 * (1.0 + 1.0 / (integration_s * cn0))) / (
        2.0 * np.pi * integration_s)


def multipath_sigma_m(elevation_rad: np.ndarray, zenith_m: float) -> np.ndarray:
    """Multipath standard deviation, m: the DO-229D J.2.4 elevation shape
    0.13 + 0.53 exp(-el / 10 deg), scaled so that the zenith value is ``zenith_m``."""
    el_deg = np.degrees(np.clip(elevation_rad, 0, None))
    return zenith_m * (0.13 + 0.53 * np.exp(-el_deg / 10.0)) / 0.13
