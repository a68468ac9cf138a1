"""Broadcast ephemeris evaluation: satellite ECEF position, velocity and clock offset of every
system (GPS, QZSS, Galileo, BeiDou, GLONASS) from the records of a navigation table,
vectorised over any array shape (satellites x epochs) and over mixed systems.

Times are GPS time in seconds relative to the start of a reference GPS week chosen by the
caller (``ephemeris_arrays(nav, week0)``), so that differences such as t - toe stay small and
exact in float64 and week crossovers need no special case. Each system's broadcast times are
moved onto that axis (``simulator.gnss.timesystems``: BDT = GPST - 14 s, BDT week 0 = GPS week
1356; GLONASS t_b from UTC); an orbit is evaluated at t - toe, the same in either time scale.

The receiver's one call (arrays broadcast to a shape S, e.g. satellites x epochs):

    eph = ephemeris_arrays(nav, week0)                   # once per navigation table
    state = satellites_at(eph, system, sv, t_tx)         # every satellite at its transmit time

or, in steps (to keep the records fixed over the light-time iterations):

    idx = select_ephemeris(eph, sv, t, system=system)    # record of each (system, sv) at t
    state = satellite_state(gather(eph, idx, STATE_KEYS), t_tx)

``satellite_state`` returns per element ``pos``, ``vel`` (ECEF of the transmit time: WGS-84 /
CGCS2000 / PZ-90, all within centimetres of ITRF), ``clock_s`` (the satellite clock offset from
its own system time for the system's primary single-frequency signal: GPS/QZSS L1 C/A, Galileo
E1 (I/NAV: E1,E5b clock minus BGD(E1,E5b)), BeiDou B1I (minus TGD1), GLONASS G1), with
``clock_drift_s_s``, ``group_delay_s`` (the term subtracted: add it back for the iono-free
clock and subtract another signal's instead; ``eph["tgd"]``/``eph["tgd2"]`` hold both), and
``system_time_offset_s`` (the system's time minus GPST beyond whole seconds, from the file's
``TIME SYSTEM CORR``: a receiver without an inter-system bias in its clock model corrects the
satellite clock by it). The system letter and number of each element are ``eph["system"]``
and ``eph["sv"]`` of the gathered records, returned again as ``system`` and ``sv``.

Algorithms: GPS IS-GPS-200 Table 20-IV; QZSS IS-QZSS-PNT the same; Galileo OS SIS ICD 5.1.1
(its own mu); BeiDou BDS SIS ICD B1I 5.2.4.12 (CGCS2000 mu and Omega_e; MEO and IGSO as GPS;
GEO, PRN 1-5 and 59-63, computed in an inertial-like frame and rotated by -5 deg about X and by
Omega_e t_k about Z); GLONASS ICD 2008 A.3.1.2 (``simulator.gnss.glonass``). Relativistic
clock term F e sqrt(A) sin E for the Keplerian systems with each system's F (GLONASS clocks
include it). Clocks: a0 + a1 (t - toc) + a2 (t - toc)^2; GLONASS -tau_n + gamma_n (t - t_b).

A broadcast ephemeris is a curve fit over its fit interval, so a record is used only within
``MAX_AGE_S`` of its toe (GPS: half the 4 h fit interval, IS-GPS-200 20.3.4.4; QZSS: records
hourly with a 2 h fit; Galileo: records every 10 min, used up to 2 h like GPS; BeiDou: hourly,
used within 1 h; GLONASS: every 30 min, used within 30 min): beyond it the orbit error grows
quickly, and a receiver would not use it. Unhealthy records are selected like healthy ones when
asked (a receiver tracks an unhealthy satellite and reports it, it only leaves it out of its
solution); a record without a usable orbit (square root of the semi-major axis below
``MIN_SQRT_A``, or a GLONASS position nearer than ``MIN_RADIUS_M``) never is.

Public names
------------
EPHEMERIS_FIT_INTERVAL_S, EPHEMERIS_MAX_AGE_S, MAX_AGE_S, MIN_SQRT_A, MIN_RADIUS_M,
BEIDOU_GEO_PRNS, SYSTEM_CODES, STATE_KEYS, system_codes, primary_frequency_hz,
ephemeris_arrays, select_ephemeris, gather, satellite_state, satellites_at.

References
----------
IS-GPS-200N, Table 20-IV (user algorithm for ephemeris determination) and section
20.3.3.3.3.1 (user algorithm for the SV clock correction, relativistic term and T_GD).
Velocity: the time derivative of Table 20-IV, as given in IS-GPS-200N Table 20-IV (addendum
"SV velocity") and in Remondi, *Computing satellite velocity using the broadcast ephemeris*,
GPS Solutions 8(3), 2004. Galileo OS SIS ICD issue 2.1 (2023), 5.1.1-5.1.5 (orbit, clock,
BGD). BDS SIS ICD B1I version 3.0 (2019), 5.2.4.10-5.2.4.12 (clock, TGD, user algorithm for
GEO/MEO/IGSO ephemeris). IS-QZSS-PNT-005 (2022), 4.1.2.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from simulator.gnss.constants import (
    F_B1I_HZ,
    F_L1_HZ,
    KEPLER_CONSTANTS,
    SECONDS_PER_WEEK,
    relativistic_constant,
)
from simulator.gnss.glonass import GLONASS_MAX_AGE_S, StateTable, carrier_frequencies_hz
from simulator.gnss.timesystems import BDS_WEEK_OFFSET, BDT_MINUS_GPST_S, offset_polynomials

if TYPE_CHECKING:
    import pandas as pd

EPHEMERIS_FIT_INTERVAL_S = 4 * 3600.0  # IS-GPS-200 20.3.4.4, fit interval flag 0
EPHEMERIS_MAX_AGE_S = 0.5 * EPHEMERIS_FIT_INTERVAL_S  # toe is in the middle of the fit interval
MAX_AGE_S = {"G": EPHEMERIS_MAX_AGE_S, "J": 3600.0, "E": EPHEMERIS_MAX_AGE_S, "C": 3600.0,
             "R": GLONASS_MAX_AGE_S}
MIN_SQRT_A = 4000.0  # m^0.5; GPS orbits have about 5153.6 (a = 26 560 km)
MIN_RADIUS_M = 2.0e7  # GLONASS orbits have r = 25 510 km
BEIDOU_GEO_PRNS = (1, 2, 3, 4, 5, 59, 60, 61, 62, 63)  # BDS SIS ICD 5.2.4.12, RINEX 3.04 A14
SYSTEM_CODES = "GJECR"  # integer code of each system in the arrays (its index here)
_KEPLER_ITERATIONS = 8  # Newton steps on Kepler's equation: below 1e-15 rad for e < 0.1
_GEO_TILT_RAD = np.radians(-5.0)  # BDS SIS ICD 5.2.4.12: R_X(-5 deg)
_R = SYSTEM_CODES.index("R")
_BLOCK = 16384  # elements evaluated together by satellite_state


def primary_frequency_hz(system: np.ndarray, channel: np.ndarray) -> np.ndarray:
    """Carrier frequency (Hz) of each satellite's primary signal, the one ``clock_s`` is for:
    GPS/QZSS L1 and Galileo E1 1575.42 MHz, BeiDou B1I 1561.098 MHz, GLONASS G1 on its FDMA
    channel (``glonass.carrier_frequencies_hz``)."""
    system = np.asarray(system)
    g1, _ = carrier_frequencies_hz(channel)
    return np.where(system == "R", g1, np.where(system == "C", F_B1I_HZ, F_L1_HZ))


def system_codes(system: np.ndarray) -> np.ndarray:
    """Index in ``SYSTEM_CODES`` of each RINEX system letter (-1 for any other text)."""
    letters, inverse = np.unique(np.asarray(system), return_inverse=True)
    table = np.array([SYSTEM_CODES.find(x) if len(x) == 1 else -1 for x in letters.tolist()],
                     dtype=int)
    return table[inverse].reshape(np.shape(system))


def ephemeris_arrays(nav: pd.DataFrame, week0: int) -> dict[str, np.ndarray]:
    """Navigation-table columns as arrays, on the GPS time axis of week ``week0``.

    Adds ``toe_s`` and ``toc_s`` (GPS seconds since the start of week ``week0``), ``system``
    (letters; ``G`` when the table has no ``system`` column), ``system_code`` (index in
    ``SYSTEM_CODES``), each record's constants ``mu``, ``omega_e``, ``f_rel``, ``geo``
    (BeiDou GEO), ``group_delay`` (of the primary signal: module docstring), the time-system
    offset polynomial ``tsys_a0``, ``tsys_a1``, ``tsys_ref_s`` (``timesystems``), ``record``
    (row number), ``glonass_row`` (row in the GLONASS state table, -1 for other systems) and
    ``glonass`` (that ``glonass.StateTable``, not indexed by record)."""
    n = len(nav)
    system = (nav["system"].to_numpy(dtype=str) if "system" in nav.columns
              else np.full(n, "G"))
    out = {k: nav[k].to_numpy(dtype=float) for k in nav.columns if k not in ("sv", "system")}
    out["sv"] = nav["sv"].to_numpy(dtype=int)
    out["system"] = system
    out["system_code"] = system_codes(system)
    for key in ("tgd2", "data_source"):
        out.setdefault(key, np.zeros(n))
    beidou = system == "C"
    week = out["week"] + np.where(beidou, BDS_WEEK_OFFSET, 0)
    shift = (week - week0) * SECONDS_PER_WEEK - np.where(beidou, BDT_MINUS_GPST_S, 0.0)
    out["toe_s"] = out["toe"] + shift
    out["toc_s"] = out["toc"] + shift
    mu = np.array([KEPLER_CONSTANTS.get(s, KEPLER_CONSTANTS["G"])[0] for s in system])
    out["mu"] = mu
    out["omega_e"] = np.array([KEPLER_CONSTANTS.get(s, KEPLER_CONSTANTS["G"])[1]
                               for s in system])
    out["f_rel"] = np.where(system == "R", 0.0, relativistic_constant(1.0) * np.sqrt(mu))
    out["geo"] = beidou & np.isin(out["sv"], BEIDOU_GEO_PRNS)
    fnav = (out["data_source"].astype(int) & 2) != 0
    out["group_delay"] = np.select(
        [system == "R", (system == "E") & ~fnav], [0.0, out["tgd2"]], out["tgd"])
    out["tsys_a0"], out["tsys_a1"], out["tsys_ref_s"] = offset_polynomials(
        system, nav.attrs.get("time_corrections", {}), week0)
    out["record"] = np.arange(n)
    glonass = np.flatnonzero(system == "R")
    out["glonass_row"] = np.full(n, -1)
    out["glonass_row"][glonass] = np.arange(len(glonass))
    if len(glonass):
        state0 = np.stack([out[k][glonass] for k in ("glo_x", "glo_y", "glo_z", "glo_vx",
                                                     "glo_vy", "glo_vz")], axis=-1)
        lunisolar = np.stack([out[k][glonass] for k in ("glo_ax", "glo_ay", "glo_az")], axis=-1)
        out["glonass"] = StateTable(state0, lunisolar, MAX_AGE_S["R"])
    return out


def _usable(eph: dict[str, np.ndarray]) -> np.ndarray:
    if "glo_x" not in eph:
        return eph["sqrt_a"] > MIN_SQRT_A
    radius = np.sqrt(eph["glo_x"] ** 2 + eph["glo_y"] ** 2 + eph["glo_z"] ** 2)
    return np.where(eph["system_code"] == _R, radius > MIN_RADIUS_M, eph["sqrt_a"] > MIN_SQRT_A)


def select_ephemeris(eph: dict[str, np.ndarray], sv: np.ndarray, t_s: np.ndarray,
                     max_age_s: float | None = None, healthy_only: bool = True,
                     system: np.ndarray | str = "G") -> np.ndarray:
    """Index of the record of satellite (``system``, ``sv``) whose toe is nearest to ``t_s``:
    among the healthy records, or (``healthy_only=False``) among all records with a usable
    orbit.

    Parameters
    ----------
    eph : dict
        From ``ephemeris_arrays``.
    sv, t_s, system : array_like, broadcast together
        Satellite numbers, times (GPS s since the start of the reference week) and RINEX
        system letters (default ``G``).
    max_age_s : float or None
        Records with |t - toe| above this are not used (default: ``MAX_AGE_S`` of each system;
        GLONASS records never beyond theirs, the span their orbit is integrated over).
    healthy_only : bool
        Leave out records whose health is not 0.

    Returns
    -------
    ndarray of int, the broadcast shape of sv, t_s and system; -1 where no record qualifies.
    """
    sv, t_s, code = np.broadcast_arrays(np.asarray(sv, dtype=int),
                                        np.asarray(t_s, dtype=float), system_codes(system))
    usable = _usable(eph)
    good = np.flatnonzero(usable & (eph["health"] == 0) if healthy_only else usable)
    span = 4.0 * SECONDS_PER_WEEK  # keys of different satellites never interleave
    satellite = eph["system_code"][good] * 1000 + eph["sv"][good]
    key = satellite * span + eph["toe_s"][good]
    order = np.argsort(key, kind="stable")
    key, good = key[order], good[order]
    if len(key) == 0:
        return np.full(sv.shape, -1)
    query = (code * 1000 + sv) * span + t_s
    right = np.clip(np.searchsorted(key, query), 0, len(key) - 1)
    left = np.clip(right - 1, 0, len(key) - 1)
    pick = np.where(np.abs(key[left] - query) <= np.abs(key[right] - query), left, right)
    idx = good[pick]
    ages = np.array([MAX_AGE_S[c] for c in SYSTEM_CODES])
    picked = eph["system_code"][idx]
    # a GLONASS record is integrated over its own age limit only: never used beyond it
    limit = (ages[picked] if max_age_s is None
             else np.where(picked == _R, np.minimum(max_age_s, ages[_R]), max_age_s))
    ok = ((eph["sv"][idx] == sv) & (eph["system_code"][idx] == code)
          & (np.abs(eph["toe_s"][idx] - t_s) <= limit))
    return np.where(ok, idx, -1)


# what ``satellite_state`` reads of a record: gather only these for large arrays of states
STATE_KEYS = ("system", "sv", "system_code", "toe", "toe_s", "toc_s", "sqrt_a", "e", "i0",
              "omega0", "omega", "m0", "delta_n", "omega_dot", "idot", "cuc", "cus", "crc",
              "crs", "cic", "cis", "af0", "af1", "af2", "tgd", "group_delay", "mu", "omega_e",
              "f_rel", "geo", "tsys_a0", "tsys_a1", "tsys_ref_s", "glonass_row", "glonass")


def gather(eph: dict[str, np.ndarray], idx: np.ndarray,
           keys: tuple[str, ...] | None = None) -> dict[str, np.ndarray]:
    """The parameters of records ``idx`` (any shape; -1 entries give record 0), all of them or
    only ``keys`` (e.g. ``STATE_KEYS``); the GLONASS state table is passed on as it is."""
    safe = np.where(idx < 0, 0, idx)
    chosen = eph if keys is None else {k: eph[k] for k in keys if k in eph}
    return {k: (np.take(v, safe, axis=0) if isinstance(v, np.ndarray) else v)
            for k, v in chosen.items()}


def satellite_state(eph: dict[str, np.ndarray], t_s: np.ndarray) -> dict[str, np.ndarray]:
    """Satellite position, velocity and clock at GPS times t, any mix of systems (module
    docstring: IS-GPS-200 Table 20-IV, Galileo OS SIS ICD 5.1, BDS SIS ICD 5.2.4.12, GLONASS
    ICD A.3.1.2).

    Parameters
    ----------
    eph : dict of ndarray
        Broadcast parameters (``gather`` output or ``ephemeris_arrays``), each broadcastable
        to the shape of ``t_s``, with ``toe_s`` and ``toc_s`` on the same time axis as ``t_s``.
    t_s : ndarray, shape S
        GPS time of signal transmission, s on the reference-week axis.

    Returns
    -------
    dict with
        ``pos`` (S + (3,), m) and ``vel`` (S + (3,), m/s): ECEF at time t, in the ECEF frame of
        time t;
        ``clock_s``: SV clock offset from its system time, dt_sv = af0 + af1 (t - toc) + af2
        (t - toc)^2 + dt_r - group delay (s; IS-GPS-200 20.3.3.3.3.1 and 20.3.3.3.3.2: the
        L1 C/A single-frequency user; the other systems' primary signal, module docstring);
        ``clock_drift_s_s``: its time derivative (s/s);
        ``relativistic_s``: dt_r = F e sqrt(A) sin E_k (s; 0 for GLONASS);
        ``group_delay_s``: the group delay subtracted in ``clock_s`` (s);
        ``system_time_offset_s``: the system's time minus GPST beyond whole seconds (s).
    """
    t = np.broadcast_to(np.asarray(t_s, dtype=float), np.broadcast(eph["toe_s"], t_s).shape)
    if t.size <= _BLOCK:
        return _state(eph, t)
    # in blocks of elements that stay in the processor's cache (twice as fast for an hour of
    # 100 satellites at 1 Hz as one pass over the whole arrays)
    flat = {k: (np.broadcast_to(v, t.shape).reshape(-1) if isinstance(v, np.ndarray) else v)
            for k, v in eph.items()}
    t_flat = t.reshape(-1)
    blocks = [_state({k: (v[a:a + _BLOCK] if isinstance(v, np.ndarray) else v)
                      for k, v in flat.items()}, t_flat[a:a + _BLOCK])
              for a in range(0, t.size, _BLOCK)]
    return {k: np.concatenate([b[k] for b in blocks]).reshape(t.shape + blocks[0][k].shape[1:])
            for k in blocks[0]}


def _state(eph: dict[str, np.ndarray], t: np.ndarray) -> dict[str, np.ndarray]:
    """``satellite_state`` of parameters broadcast to the shape of ``t``."""
    codes = np.broadcast_to(eph.get("system_code", np.zeros((), dtype=int)), t.shape)
    glonass = codes == _R
    if glonass.all():
        pos, vel, rel, rel_dot = (np.zeros(t.shape + (3,)), np.zeros(t.shape + (3,)),
                                  np.zeros(t.shape), np.zeros(t.shape))
    else:
        pos, vel, rel, rel_dot = _keplerian(eph, t, glonass)
    if glonass.any():
        rows = np.broadcast_to(eph["glonass_row"], t.shape)[glonass]
        pos[glonass], vel[glonass] = eph["glonass"].state(
            rows, t[glonass] - np.broadcast_to(eph["toe_s"], t.shape)[glonass])

    dtc = t - eph["toc_s"]
    group_delay = eph.get("group_delay", eph["tgd"])
    clock = eph["af0"] + eph["af1"] * dtc + eph["af2"] * dtc**2 + rel - group_delay
    drift = eph["af1"] + 2.0 * eph["af2"] * dtc + rel_dot
    offset = (eph["tsys_a0"] + eph["tsys_a1"] * (t - eph["tsys_ref_s"]) if "tsys_a0" in eph
              else np.zeros(t.shape))
    return {"pos": pos, "vel": vel, "clock_s": clock, "clock_drift_s_s": drift,
            "relativistic_s": rel, "group_delay_s": np.broadcast_to(group_delay, t.shape),
            "system_time_offset_s": np.broadcast_to(offset, t.shape),
            "system": np.broadcast_to(eph.get("system", "G"), t.shape),
            "sv": np.broadcast_to(eph["sv"], t.shape)}


def satellites_at(eph: dict[str, np.ndarray], system: np.ndarray, sv: np.ndarray,
                  t_s: np.ndarray, healthy_only: bool = False,
                  max_age_s: float | None = None) -> dict[str, np.ndarray]:
    """The receiver's one call: broadcast states of satellites (``system``, ``sv``) at GPS
    times ``t_s`` (all broadcast together, e.g. (n_sat, 1) against (n_sat, n_epoch) transmit
    times), each from its record nearest in time (``select_ephemeris``).

    Returns
    -------
    dict: ``satellite_state``'s arrays (with ``system`` and ``sv``), ``record`` (index in
    ``eph``, -1 where none qualifies) and ``valid`` (record >= 0; elsewhere the values are
    those of record 0 and mean nothing).
    """
    idx = select_ephemeris(eph, sv, t_s, max_age_s=max_age_s, healthy_only=healthy_only,
                           system=system)
    state = satellite_state(gather(eph, idx, STATE_KEYS), t_s)
    state["record"], state["valid"] = idx, idx >= 0
    return state


def _keplerian(eph: dict[str, np.ndarray], t: np.ndarray, skip: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Position, velocity, relativistic clock term and its rate of the Keplerian records
    (IS-GPS-200 Table 20-IV with each system's mu and Omega_e; BeiDou GEO per BDS SIS ICD
    5.2.4.12); elements where ``skip`` is set (GLONASS) are evaluated on a dummy orbit."""
    mu = eph.get("mu", KEPLER_CONSTANTS["G"][0])
    omega_e = eph.get("omega_e", KEPLER_CONSTANTS["G"][1])
    f_rel = eph.get("f_rel", relativistic_constant(KEPLER_CONSTANTS["G"][0]))
    geo = np.broadcast_to(eph.get("geo", False), t.shape)
    sqrt_a = np.where(skip, 5153.6, eph["sqrt_a"])
    a = sqrt_a**2
    n = np.sqrt(mu / a**3) + eph["delta_n"]  # corrected mean motion
    tk = t - eph["toe_s"]
    e = eph["e"]
    mk = eph["m0"] + n * tk
    ek = np.array(mk, dtype=float)
    for _ in range(_KEPLER_ITERATIONS):  # Newton on E - e sin E = M
        step = ek - (ek - e * np.sin(ek) - mk) / (1.0 - e * np.cos(ek))
        if np.array_equal(step, ek):  # a fixed point: the steps left would not change it
            break
        ek = step
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
    # the node's rate in the frame of the computation: Earth-fixed (Omega_dot - Omega_e), or
    # for a BeiDou GEO the inertial-like frame of toe (Omega_dot)
    omega_rate = eph["omega_dot"] - np.where(geo, 0.0, omega_e)
    # corrected longitude of the ascending node; toe here is in seconds of its own week
    om = eph["omega0"] + omega_rate * tk - omega_e * eph["toe"]
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
    if geo.any():
        pos[geo], vel[geo] = _beidou_geo_to_ecef(pos[geo], vel[geo],
                                                 np.broadcast_to(omega_e * tk, t.shape)[geo],
                                                 np.broadcast_to(omega_e, t.shape)[geo])
    rel = f_rel * e * sqrt_a * sin_e
    rel_dot = f_rel * e * sqrt_a * cos_e * e_dot
    return pos, vel, np.where(skip, 0.0, rel), np.where(skip, 0.0, rel_dot)


def _beidou_geo_to_ecef(pos: np.ndarray, vel: np.ndarray, angle: np.ndarray,
                        omega_e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """BDS SIS ICD 5.2.4.12: [X Y Z] = R_Z(Omega_e t_k) R_X(-5 deg) [X_GK Y_GK Z_GK], with
    R_X(phi) = [[1, 0, 0], [0, cos, sin], [0, -sin, cos]] and R_Z(phi) = [[cos, sin, 0],
    [-sin, cos, 0], [0, 0, 1]]; the velocity with the derivative of R_Z."""
    c5, s5 = np.cos(_GEO_TILT_RAD), np.sin(_GEO_TILT_RAD)

    def tilt(v: np.ndarray) -> np.ndarray:
        return np.stack([v[..., 0], c5 * v[..., 1] + s5 * v[..., 2],
                         -s5 * v[..., 1] + c5 * v[..., 2]], axis=-1)

    p, v = tilt(pos), tilt(vel)
    ca, sa = np.cos(angle), np.sin(angle)
    out_p = np.stack([ca * p[:, 0] + sa * p[:, 1], -sa * p[:, 0] + ca * p[:, 1], p[:, 2]], axis=-1)
    out_v = np.stack([ca * v[:, 0] + sa * v[:, 1] + omega_e * (-sa * p[:, 0] + ca * p[:, 1]),
                      -sa * v[:, 0] + ca * v[:, 1] + omega_e * (-ca * p[:, 0] - sa * p[:, 1]),
                      v[:, 2]], axis=-1)
    return out_p, out_v


__all__ = ["EPHEMERIS_FIT_INTERVAL_S", "EPHEMERIS_MAX_AGE_S", "MAX_AGE_S", "MIN_SQRT_A",
           "MIN_RADIUS_M", "BEIDOU_GEO_PRNS", "SYSTEM_CODES", "STATE_KEYS", "system_codes",
           "primary_frequency_hz", "ephemeris_arrays",
           "select_ephemeris", "gather", "satellite_state", "satellites_at"]
