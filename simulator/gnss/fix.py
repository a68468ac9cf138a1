"""The receiver's own navigation solution from its raw measurements: weighted least-squares
position and clock bias from pseudoranges, velocity and clock drift from pseudorange rates,
dilutions of precision, fix type (3D with four or more satellites; 2D with three, the height
held at the last 3D fix's; none otherwise), speed and course; optionally the smoothed
(filtered) output of low-cost receivers.

All epochs are solved at once: measurements are packed into (epoch, slot) arrays with a mask,
and a fixed number of Gauss-Newton iterations runs as batched 4 x 4 linear algebra.

Public functions
----------------
pack_epochs, solve_position, solve_velocity, dilution_of_precision, smooth_positions,
primary_rows, receiver_fixes.

References
----------
Groves 2013, section 9.4.1 (single-epoch least-squares position and velocity, eqs. 9.126-9.146,
Sagnac rotation in the range model) and section 9.4.3 (DOP from the NED geometry matrix);
Kaplan & Hegarty 2017, section 11.2.1 (weighted least squares).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from simulator import columns as col
from simulator.earth import ecef_to_geodetic, ned_to_ecef_matrix
from simulator.gnss.constants import C_M_S
from simulator.gnss.receiver import light_time_factor, rotate_to_reception_frame
from simulator.gnss.signals import PRIMARY_SIGNAL
from simulator.stochastic import ar1_filter

if TYPE_CHECKING:
    import pandas as pd

_GAUSS_NEWTON_ITERATIONS = 10  # from the Earth's centre: converged to < 1e-6 m after 7
_MAX_CONDITION = 1e12  # a normal matrix beyond this is singular in float64 (no fix)


def pack_epochs(epoch: np.ndarray, n_epochs: int, *values: np.ndarray
                ) -> tuple[np.ndarray, list[np.ndarray]]:
    """Scatter per-measurement values into (n_epochs, max per epoch, ...) arrays.

    Parameters
    ----------
    epoch : ndarray of int, shape (m,)
        Epoch index of each measurement, sorted ascending.
    values : ndarrays of shape (m, ...)

    Returns
    -------
    mask : ndarray of bool, shape (n_epochs, k)
    packed : list of ndarrays, shape (n_epochs, k, ...), zero where masked.
    """
    epoch = np.asarray(epoch, dtype=int)
    counts = np.bincount(epoch, minlength=n_epochs)
    k = max(int(counts.max(initial=0)), 1)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    slot = np.arange(len(epoch)) - start[epoch]
    mask = np.zeros((n_epochs, k), dtype=bool)
    mask[epoch, slot] = True
    packed = []
    for v in values:
        out = np.zeros((n_epochs, k) + v.shape[1:])
        out[epoch, slot] = v
        packed.append(out)
    return mask, packed


def _solve(normal: np.ndarray, rhs: np.ndarray, ok: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray]:
    """Batched solve of normal equations. Epochs not ``ok``, or whose system is numerically
    singular (condition number above ``_MAX_CONDITION``: satellites in a degenerate geometry,
    or an iteration gone far from the Earth), get an identity system and come back not
    solvable. Returns the solutions and the solvable flags."""
    eye = np.eye(normal.shape[-1])
    normal = np.where(ok[:, None, None], normal, eye)
    solvable = ok & (np.linalg.cond(normal) < _MAX_CONDITION)
    normal = np.where(solvable[:, None, None], normal, eye)
    return np.linalg.solve(normal, rhs[..., None])[..., 0], solvable


def _up_ecef(pos_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Ellipsoidal height and the unit up vector (ellipsoid normal) in ECEF at positions."""
    lat, lon, alt = ecef_to_geodetic(pos_m)
    up = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=-1)
    return alt, up


def solve_position(pr_m: np.ndarray, sat_pos_m: np.ndarray, weight: np.ndarray,
                   mask: np.ndarray, height_m: np.ndarray | None = None,
                   start_m: np.ndarray | None = None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weighted least-squares antenna position and receiver clock from corrected pseudoranges.

    Model (Groves eq. 9.126 with 8.36): pr = |R(omega_e tau) r_s - r| + c dt_r, tau = range / c,
    with r_s at transmission in the ECEF frame of transmission. Where ``height_m`` is given
    (finite) the ellipsoidal height is held at that value by one more equation, so three
    satellites give a 2D fix (Kaplan & Hegarty section 11.2.2, altitude hold).

    Parameters
    ----------
    pr_m : ndarray, shape (n, k)
        Pseudorange + satellite clock - broadcast iono - broadcast tropo, m.
    sat_pos_m : ndarray, shape (n, k, 3)
    weight : ndarray, shape (n, k)
        1 / sigma^2 of each pseudorange (0 where masked).
    mask : ndarray of bool, shape (n, k)
    height_m : ndarray, shape (n,), optional
        Height to hold (NaN: none), m.
    start_m : ndarray, shape (n, 3), optional
        Starting positions (default: the Earth's centre; needed where a height is held).

    Returns
    -------
    pos_m : ndarray, shape (n, 3) (NaN where not solvable)
    clock_m : ndarray, shape (n,), c dt_r
    ok : ndarray of bool, shape (n,): at least 4 equations
    """
    n = pr_m.shape[0]
    held = np.zeros(n, dtype=bool) if height_m is None else np.isfinite(height_m)
    ok = mask.sum(axis=1) + held >= 4
    w = np.where(mask, weight, 0.0)
    x = np.zeros((n, 4))
    if start_m is not None:
        x[:, :3] = np.where(np.isfinite(start_m), start_m, 0.0)
    for _ in range(_GAUSS_NEWTON_ITERATIONS):
        rng, los = _geometry(sat_pos_m, x[:, :3])
        h = np.concatenate([-los, np.ones(rng.shape + (1,))], axis=-1)
        resid = np.where(mask, pr_m - rng - x[:, 3:4], 0.0)
        hw = h * w[..., None]
        normal = np.einsum("nki,nkj->nij", hw, h)
        rhs = np.einsum("nki,nk->ni", hw, resid)
        if held.any():
            alt, up = _up_ecef(x[held, :3])
            row = np.concatenate([up, np.zeros((len(up), 1))], axis=1)
            normal[held] += row[:, :, None] * row[:, None, :]
            rhs[held] += row * (height_m[held] - alt)[:, None]
        dx, ok = _solve(normal, rhs, ok)
        x = x + np.where(ok[:, None], dx, 0.0)
    pos = np.where(ok[:, None], x[:, :3], np.nan)
    return pos, np.where(ok, x[:, 3], np.nan), ok


def _geometry(sat_pos_m: np.ndarray, rx_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Range (with the Sagnac rotation) and unit line of sight from receiver to satellite."""
    rel = sat_pos_m - rx_m[:, None, :]
    tau = np.linalg.norm(rel, axis=-1) / C_M_S
    rel = rotate_to_reception_frame(sat_pos_m, tau) - rx_m[:, None, :]
    rng = np.linalg.norm(rel, axis=-1)
    return rng, rel / np.where(rng > 0, rng, 1.0)[..., None]


def solve_velocity(rate_m_s: np.ndarray, sat_pos_m: np.ndarray, sat_vel_m_s: np.ndarray,
                   pos_m: np.ndarray, weight: np.ndarray, mask: np.ndarray,
                   held: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Weighted least-squares ECEF velocity and clock drift (c d(dt_r)/dt, m/s) from pseudorange
    rates corrected for the satellite clock drift (Groves eq. 9.141):
    rate = los . (v_s - v) / f + c d(dt_r)/dt, with v_s rotated into the frame of reception and
    f = ``light_time_factor`` (the exact light-time derivative; 1 - f is about 1e-5).
    Epochs flagged ``held`` (2D fixes) add the equation "no vertical velocity"."""
    held = np.zeros(len(pos_m), dtype=bool) if held is None else held
    ok = (mask.sum(axis=1) + held >= 4) & np.isfinite(pos_m).all(axis=1)
    rx = np.where(ok[:, None], pos_m, 0.0)
    rng, los = _geometry(sat_pos_m, rx)
    vs = rotate_to_reception_frame(sat_vel_m_s, rng / C_M_S)
    factor = light_time_factor(los, sat_pos_m, vs, rng / C_M_S)
    y = np.where(mask, rate_m_s * factor - np.einsum("nki,nki->nk", los, vs), 0.0)
    h = np.concatenate([-los, factor[..., None]], axis=-1)
    hw = h * np.where(mask, weight, 0.0)[..., None]
    normal = np.einsum("nki,nkj->nij", hw, h)
    held = held & ok
    if held.any():
        _, up = _up_ecef(rx[held])
        row = np.concatenate([up, np.zeros((len(up), 1))], axis=1)
        normal[held] += row[:, :, None] * row[:, None, :]
    x, ok = _solve(normal, np.einsum("nki,nk->ni", hw, y), ok)
    x = np.where(ok[:, None], x, np.nan)
    return x[:, :3], x[:, 3]


def dilution_of_precision(sat_pos_m: np.ndarray, pos_m: np.ndarray, mask: np.ndarray,
                          held: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """HDOP and VDOP from the unweighted geometry matrix in local NED (Groves eq. 9.91).

    For 2D fixes (``held``) the held height enters as one more unit row on the down axis, and
    VDOP is NaN (there is no vertical solution)."""
    held = np.zeros(len(pos_m), dtype=bool) if held is None else held
    ok = (mask.sum(axis=1) + held >= 4) & np.isfinite(pos_m).all(axis=1)
    rx = np.where(ok[:, None], pos_m, np.array([1.0, 0.0, 0.0]) * 6.4e6)
    _, los = _geometry(sat_pos_m, rx)
    lat, lon, _ = ecef_to_geodetic(rx)
    c_ne = ned_to_ecef_matrix(lat, lon)
    los_ned = np.einsum("nji,nkj->nki", c_ne, los)
    h = np.concatenate([-los_ned, np.ones(mask.shape + (1,))], axis=-1) * mask[..., None]
    normal = np.einsum("nki,nkj->nij", h, h)
    normal[:, 2, 2] += held
    normal = np.where(ok[:, None, None], normal, np.eye(4))
    g = np.linalg.inv(normal)
    hdop = np.sqrt(g[:, 0, 0] + g[:, 1, 1])
    vdop = np.sqrt(g[:, 2, 2])
    return np.where(ok, hdop, np.nan), np.where(ok & ~held, vdop, np.nan)


def smooth_positions(pos_m: np.ndarray, vel_m_s: np.ndarray, dt_s: float,
                     time_constant_s: float) -> np.ndarray:
    """Velocity-aided first-order smoothing of fixes, as low-cost receivers filter their output:
    p_k = q_k + alpha (z_k - q_k) with the prediction q_k = p_{k-1} + (v_{k-1} + v_k) dt / 2
    (trapezoidal, so a turn or an acceleration does not make the output lag) and
    alpha = dt / (time_constant + dt); the filter restarts after every epoch without a fix."""
    alpha = dt_s / (time_constant_s + dt_s)
    out = np.full_like(pos_m, np.nan)
    valid = np.isfinite(pos_m).all(axis=1) & np.isfinite(vel_m_s).all(axis=1)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], valid.astype(int), [0]])))
    for start, stop in zip(edges[::2], edges[1::2], strict=True):  # one pass per fix stretch
        z = pos_m[start:stop]
        v = vel_m_s[start:stop]
        step = np.concatenate([np.zeros((1, 3)), 0.5 * (v[1:] + v[:-1]) * dt_s])
        # p_k - (1 - alpha) p_{k-1} = alpha z_k + (1 - alpha) step_k, started at the first fix
        drive = alpha * z + (1.0 - alpha) * step
        drive[0] = z[0]
        out[start:stop] = ar1_filter(drive, 1.0 - alpha)
    return out


def primary_rows(raw: pd.DataFrame) -> pd.DataFrame:
    """The rows of each system's primary signal (all rows of a stream without ``signal``)."""
    if "signal" not in raw or "system" not in raw:
        return raw
    primary = raw["system"].map(PRIMARY_SIGNAL)
    return raw[(raw["signal"] == primary).to_numpy()]


def receiver_fixes(t: np.ndarray, raw: pd.DataFrame, smoothing_time_constant_s: float = 0.0,
                   dop_mask: float = np.inf) -> pd.DataFrame:
    """The fix stream (``simulator.columns.GNSS_FIX``) at epochs t from the raw measurements.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Fix epochs, s; every raw row's ``t`` must be one of them.
    raw : pandas.DataFrame
        Rows of ``gnss_raw`` (with ``pseudorange_std`` and ``pseudorange_rate_std``); rows whose
        ``health`` is not 0 are left out, and with several signals only each system's primary
        one (``simulator.gnss.signals.PRIMARY_SIGNAL``: a single-frequency fix) is used.
    smoothing_time_constant_s : float
        0 for raw single-epoch fixes, else the time constant of ``smooth_positions``.
    dop_mask : float
        Largest HDOP a fix is given with, as receivers' DOP masks do (a receiver with three
        satellites near the zenith reports no fix rather than one hundreds of metres off).
    """
    import pandas as pd

    n = len(t)
    if "health" in raw:  # an unhealthy satellite is tracked and reported, never used
        raw = raw[raw["health"].to_numpy() == 0]
    raw = primary_rows(raw)
    raw = raw.sort_values(["t", "sv"], kind="stable")
    epoch = np.searchsorted(t, raw["t"].to_numpy())
    sat_pos = raw[["sat_x", "sat_y", "sat_z"]].to_numpy()
    sat_vel = raw[["sat_vx", "sat_vy", "sat_vz"]].to_numpy()
    pr = (raw["pseudorange"] + raw["sat_clock"] - raw["iono"] - raw["tropo"]).to_numpy()
    rate = (raw["pseudorange_rate"] + raw["sat_clock_drift"]).to_numpy()
    w_pr = 1.0 / raw["pseudorange_std"].to_numpy() ** 2
    w_rate = 1.0 / raw["pseudorange_rate_std"].to_numpy() ** 2
    mask, (pr_p, pos_p, vel_p, rate_p, w_pr_p, w_rate_p) = pack_epochs(
        epoch, n, pr, sat_pos, sat_vel, rate, w_pr, w_rate)
    pos, clock, ok = solve_position(pr_p, pos_p, w_pr_p, mask)
    # 2D fixes: three satellites, the height held at the last 3D fix's (causal)
    last = pd.DataFrame(np.where(ok[:, None], pos, np.nan)).ffill().to_numpy()
    last_alt = np.full(n, np.nan)
    known = np.isfinite(last).all(axis=1)
    last_alt[known] = ecef_to_geodetic(last[known])[2]
    held = (mask.sum(axis=1) == 3) & known
    if held.any():
        pos2, clock2, ok2 = solve_position(pr_p[held], pos_p[held], w_pr_p[held], mask[held],
                                           last_alt[held], last[held])
        pos[held], clock[held] = pos2, clock2
        held[held] = ok2
    vel, drift = solve_velocity(rate_p, pos_p, vel_p, pos, w_rate_p, mask, held)
    hdop, vdop = dilution_of_precision(pos_p, pos, mask, held)
    fix_type = np.where(ok, 2, np.where(held, 1, 0))
    fix_type[~(hdop <= dop_mask)] = 0
    ok = fix_type > 0
    if smoothing_time_constant_s > 0 and n > 1:
        pos = smooth_positions(pos, vel, float(t[1] - t[0]), smoothing_time_constant_s)
    lat, lon, alt = ecef_to_geodetic(np.where(ok[:, None], pos, [6.4e6, 0.0, 0.0]))
    v_ned = np.einsum("nji,nj->ni", ned_to_ecef_matrix(lat, lon), np.nan_to_num(vel))
    nan = np.where(ok, 1.0, np.nan)
    v_ned = v_ned * nan[:, None]
    return pd.DataFrame({
        "t": t, "lat": np.degrees(lat) * nan, "lon": np.degrees(lon) * nan, "alt": alt * nan,
        "vn": v_ned[:, 0], "ve": v_ned[:, 1], "vd": v_ned[:, 2],
        "speed": np.hypot(v_ned[:, 0], v_ned[:, 1]),
        "course": np.mod(np.arctan2(v_ned[:, 1], v_ned[:, 0]), 2.0 * np.pi),
        "num_sats": mask.sum(axis=1), "hdop": hdop, "vdop": vdop,
        "fix": fix_type, "clock_bias": clock, "clock_drift": drift,
    }, columns=list(col.GNSS_FIX))
