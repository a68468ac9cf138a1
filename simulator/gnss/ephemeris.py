"""Broadcast ephemeris evaluation: satellite ECEF position, velocity and clock offset from the
Keplerian parameters of a navigation table, vectorised over any array shape (satellites x epochs).

Times are seconds relative to the start of a reference GPS week chosen by the caller
(``ephemeris_arrays(nav, week0)``), so that differences such as t - toe stay small and exact in
float64 and week crossovers need no special case.

A broadcast ephemeris is a curve fit over its fit interval (IS-GPS-200 20.3.4.4: four hours,
fit interval flag 0, with toe in its middle), so a record is used only within half that interval
of its toe (``EPHEMERIS_MAX_AGE_S``, 2 h): beyond it the orbit error grows quickly, and a receiver
would not use it. Unhealthy records are selected like healthy ones when asked (a receiver tracks
an unhealthy satellite and reports it, it only leaves it out of its solution); a record without a
usable orbit (square root of the semi-major axis below ``MIN_SQRT_A``, as some files write for
satellites that are not transmitting) never is.

Public names
------------
EPHEMERIS_FIT_INTERVAL_S, EPHEMERIS_MAX_AGE_S, MIN_SQRT_A, ephemeris_arrays, select_ephemeris,
gather, satellite_state.

References
----------
IS-GPS-200N, Table 20-IV (user algorithm for ephemeris determination) and section
20.3.3.3.3.1 (user algorithm for the SV clock correction, relativistic term and T_GD).
Velocity: the time derivative of Table 20-IV, as given in IS-GPS-200N Table 20-IV (addendum
"SV velocity") and in Remondi, *Computing satellite velocity using the broadcast ephemeris*,
GPS Solutions 8(3), 2004.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from simulator.gnss.constants import (
    F_REL_S_SQRTM,
    MU_GPS_M3_S2,
    OMEGA_E_DOT_RAD_S,
    SECONDS_PER_WEEK,
)

if TYPE_CHECKING:
    import pandas as pd

EPHEMERIS_FIT_INTERVAL_S = 4 * 3600.0  # IS-GPS-200 20.3.4.4, fit interval flag 0
EPHEMERIS_MAX_AGE_S = 0.5 * EPHEMERIS_FIT_INTERVAL_S  # toe is in the middle of the fit interval
MIN_SQRT_A = 4000.0  # m^0.5; GPS orbits have about 5153.6 (a = 26 560 km)
_KEPLER_ITERATIONS = 8  # Newton steps on Kepler's equation: below 1e-15 rad for e < 0.1


def ephemeris_arrays(nav: pd.DataFrame, week0: int) -> dict[str, np.ndarray]:
    """Navigation-table columns as float arrays, with ``toe_s`` and ``toc_s`` in seconds since
    the start of GPS week ``week0``."""
    out = {k: nav[k].to_numpy(dtype=float) for k in nav.columns if k != "sv"}
    out["sv"] = nav["sv"].to_numpy(dtype=int)
    shift = (nav["week"].to_numpy(dtype=float) - week0) * SECONDS_PER_WEEK
    out["toe_s"] = out["toe"] + shift
    out["toc_s"] = out["toc"] + shift
    return out


def select_ephemeris(eph: dict[str, np.ndarray], sv: np.ndarray, t_s: np.ndarray,
                     max_age_s: float = EPHEMERIS_MAX_AGE_S,
                     healthy_only: bool = True) -> np.ndarray:
    """Index of the ephemeris of satellite ``sv`` whose toe is nearest to ``t_s``: among the
    healthy records, or (``healthy_only=False``) among all records with a usable orbit.

    Parameters
    ----------
    eph : dict
        From ``ephemeris_arrays``.
    sv, t_s : array_like, broadcast together
        Satellite numbers and times (s since the start of the reference week).
    max_age_s : float
        Records with |t - toe| above this are not used (default: half the 4 h fit interval).
    healthy_only : bool
        Leave out records whose health is not 0.

    Returns
    -------
    ndarray of int, the broadcast shape of sv and t_s; -1 where no record qualifies.
    """
    sv, t_s = np.broadcast_arrays(np.asarray(sv, dtype=int), np.asarray(t_s, dtype=float))
    usable = eph["sqrt_a"] > MIN_SQRT_A
    good = np.flatnonzero(usable & (eph["health"] == 0) if healthy_only else usable)
    span = 4.0 * SECONDS_PER_WEEK  # keys of different satellites never interleave
    key = eph["sv"][good] * span + eph["toe_s"][good]
    order = np.argsort(key, kind="stable")
    key, good = key[order], good[order]
    if len(key) == 0:
        return np.full(sv.shape, -1)
    query = sv * span + t_s
    right = np.clip(np.searchsorted(key, query), 0, len(key) - 1)
    left = np.clip(right - 1, 0, len(key) - 1)
    pick = np.where(np.abs(key[left] - query) <= np.abs(key[right] - query), left, right)
    idx = good[pick]
    ok = (eph["sv"][idx] == sv) & (np.abs(eph["toe_s"][idx] - t_s) <= max_age_s)
    return np.where(ok, idx, -1)


def gather(eph: dict[str, np.ndarray], idx: np.ndarray) -> dict[str, np.ndarray]:
    """The ephemeris parameters of records ``idx`` (any shape; -1 entries give record 0)."""
    safe = np.where(idx < 0, 0, idx)
    return {k: v[safe] for k, v in eph.items()}


def satellite_state(eph: dict[str, np.ndarray], t_s: np.ndarray) -> dict[str, np.ndarray]:
    """Satellite position, velocity and clock at GPS times t (IS-GPS-200 Table 20-IV).

    Parameters
    ----------
    eph : dict of ndarray
        Broadcast parameters (``gather`` output or ``ephemeris_arrays``), each broadcastable
        to the shape of ``t_s``, with ``toe_s`` and ``toc_s`` on the same time axis as ``t_s``.
    t_s : ndarray, shape S
        GPS system time of signal transmission, s on the reference-week axis.

    Returns
    -------
    dict with
        ``pos`` (S + (3,), m) and ``vel`` (S + (3,), m/s): ECEF (WGS-84) at time t, in the ECEF
        frame of time t;
        ``clock_s``: SV clock offset dt_sv = af0 + af1 (t - toc) + af2 (t - toc)^2 + dt_r - T_GD
        (s; IS-GPS-200 20.3.3.3.3.1 and 20.3.3.3.3.2, L1 C/A single-frequency user);
        ``clock_drift_s_s``: its time derivative (s/s);
        ``relativistic_s``: dt_r = F e sqrt(A) sin E_k (s).
    """
    t = np.asarray(t_s, dtype=float)
    a = eph["sqrt_a"] ** 2
    n = np.sqrt(MU_GPS_M3_S2 / a**3) + eph["delta_n"]  # corrected mean motion
    tk = t - eph["toe_s"]
    e = eph["e"]
    mk = eph["m0"] + n * tk
    ek = mk.copy()
    for _ in range(_KEPLER_ITERATIONS):  # Newton on E - e sin E = M
        ek = ek - (ek - e * np.sin(ek) - mk) / (1.0 - e * np.cos(ek))
    sin_e, cos_e = np.sin(ek), np.cos(ek)
    one_minus = 1.0 - e * cos_e
    nu = np.arctan2(np.sqrt(1.0 - e**2) * sin_e, cos_e - e)  # true anomaly
    phi = nu + eph["omega"]  # argument of latitude
    s2, c2 = np.sin(2 * phi), np.cos(2 * phi)
    du = eph["cus"] * s2 + eph["cuc"] * c2
    dr = eph["crs"] * s2 + eph["crc"] * c2
    di = eph["cis"] * s2 + eph["cic"] * c2
    u = phi + du
    r = a * one_minus + dr
    inc = eph["i0"] + di + eph["idot"] * tk
    omega_rate = eph["omega_dot"] - OMEGA_E_DOT_RAD_S
    # corrected longitude of the ascending node; toe here is in seconds of its own week
    om = eph["omega0"] + omega_rate * tk - OMEGA_E_DOT_RAD_S * eph["toe"]
    cu, su = np.cos(u), np.sin(u)
    xp, yp = r * cu, r * su
    co, so = np.cos(om), np.sin(om)
    ci, si = np.cos(inc), np.sin(inc)
    pos = np.stack([xp * co - yp * ci * so, xp * so + yp * ci * co, yp * si], axis=-1)

    e_dot = n / one_minus
    nu_dot = e_dot * np.sqrt(1.0 - e**2) / one_minus
    u_dot = nu_dot * (1.0 + 2.0 * (eph["cus"] * c2 - eph["cuc"] * s2))
    r_dot = a * e * sin_e * e_dot + 2.0 * nu_dot * (eph["crs"] * c2 - eph["crc"] * s2)
    i_dot = eph["idot"] + 2.0 * nu_dot * (eph["cis"] * c2 - eph["cic"] * s2)
    xp_dot = r_dot * cu - r * u_dot * su
    yp_dot = r_dot * su + r * u_dot * cu
    vel = np.stack([
        xp_dot * co - yp_dot * ci * so + yp * si * i_dot * so - pos[..., 1] * omega_rate,
        xp_dot * so + yp_dot * ci * co - yp * si * i_dot * co + pos[..., 0] * omega_rate,
        yp_dot * si + yp * ci * i_dot,
    ], axis=-1)

    dtc = t - eph["toc_s"]
    rel = F_REL_S_SQRTM * e * eph["sqrt_a"] * sin_e
    rel_dot = F_REL_S_SQRTM * e * eph["sqrt_a"] * cos_e * e_dot
    clock = eph["af0"] + eph["af1"] * dtc + eph["af2"] * dtc**2 + rel - eph["tgd"]
    drift = eph["af1"] + 2.0 * eph["af2"] * dtc + rel_dot
    return {"pos": pos, "vel": vel, "clock_s": clock, "clock_drift_s_s": drift,
            "relativistic_s": rel}
