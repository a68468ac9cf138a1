"""Nominal Galileo, BeiDou and GLONASS constellations as broadcast records for any date, where
no public almanac can ship: each system's documented orbit pattern on circular orbits, with
perfect clocks (af0 = af1 = af2 = 0, no group delays) and every satellite healthy.

- Galileo: Walker 24/3/1, semi-major axis 29 600 km, inclination 56 deg, three planes 120 deg
  apart, eight slots 45 deg apart in each, adjacent planes' slots 15 deg apart in argument of
  latitude; ground track repeating after 17 revolutions in 10 sidereal days (Galileo OS Service
  Definition Document issue 1.1 (2019), 2.1 and Table 2). PRNs 1-24, planes A, B, C in order.
- BeiDou (BDS-3): 24 MEO on a Walker 24/3/1 at 27 906 km (21 528 km altitude), 55 deg, repeat
  13 revolutions in 7 sidereal days (PRNs 19-30, 32-37, 41-46, planes in order); 3 IGSO at
  geosynchronous radius, 55 deg, in planes 120 deg apart on one figure-eight ground track
  crossing the equator at 118 deg E (PRNs 38-40); 5 GEO at 140, 80, 110.5, 160 and 58.75 deg E
  (PRNs 1-5), written for the GEO algorithm of the BDS SIS ICD (5.2.4.12): inclination 5 deg and
  node at 180 deg in the ICD's inertial-like frame, which its -5 deg rotation brings onto the
  equator (BDS SIS ICD B1I 3.0, 3.1 and 5.2.4.12; China Satellite Navigation Office,
  "Development of the BeiDou Navigation Satellite System" 4.0, 2019: constellation).
- GLONASS: 24/3/1, 25 510 km, 64.8 deg, three planes 120 deg apart, slots 1-8, 9-16, 17-24 45
  deg apart in their planes (the slot number growing against the motion) and adjacent planes
  15 deg apart, repeat 17 revolutions in 8 sidereal days (GLONASS ICD 2008, 3.1.2); each slot
  on its real frequency channel (``glonass.SLOT_CHANNELS``). Records are state vectors every
  30 min (t_b on the quarter hours of Moscow time, as broadcast), one orbit integrated through
  all of them with the ICD's force model (J2, no lunisolar term), so consecutive records join
  exactly.

The absolute phase of each pattern (the right ascension of the first plane and the argument of
latitude of its first slot at the reference epoch 1993-07-01 00:00 UT, the epoch of the GPS slot
table in ``constellation``) is landnav's choice, not the real constellations' (whose planes
drift): counts, geometry and repeat periods are nominal, the moment a given satellite rises at a
given place is not. The plane's node regresses at the J2 secular rate -1.5 n J2 (a_e / a)^2
cos i (Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed., eq. 9-41); the mean
motion keeps the ground track repeating. A scenario that must reproduce a particular day's sky
names that day's navigation file.

Public names
------------
GALILEO, BEIDOU_MEO, BEIDOU_IGSO, BEIDOU_GEO_LONGITUDES_DEG, GLONASS, circular_records,
nominal_galileo_navigation, nominal_beidou_navigation, nominal_glonass_navigation.
"""

from __future__ import annotations

import datetime as dt
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from simulator import columns as col
from simulator.earth import A_M
from simulator.gnss.constants import (
    KEPLER_CONSTANTS,
    MU_GLO_M3_S2,
    OMEGA_E_GLO_RAD_S,
)
from simulator.gnss.glonass import SLOT_CHANNELS, STEP_S, rk4_step
from simulator.gnss.timesystems import BDS_WEEK_OFFSET, BDT_MINUS_GPST_S
from simulator.timebase import GPS_EPOCH, SECONDS_PER_WEEK, leap_seconds, utc_to_gps

if TYPE_CHECKING:
    import pandas as pd

J2 = 1.08263e-3  # second zonal harmonic (WGS-84), for the nodes' regression
REFERENCE_UTC = dt.datetime(1993, 7, 1)  # the patterns' phase epoch (the GPS slot table's)
GHA_REFERENCE_RAD = np.radians((18 + 36 / 60 + 14.4 / 3600) * 15.0)  # Greenwich hour angle then


class Walker(NamedTuple):
    """A Walker T/P/F pattern: ``prns`` (T of them, plane by plane), ``planes`` P, phasing F,
    inclination (deg), ground-track repeat ``revolutions`` in ``days`` sidereal days of the
    regressing plane, the first plane's right ascension (deg) at ``REFERENCE_UTC``."""

    prns: tuple[int, ...]
    planes: int
    phasing: int
    inclination_deg: float
    revolutions: int
    days: int
    raan0_deg: float = 0.0
    slot_step_sign: float = 1.0  # +1: the slot number grows along the motion


GALILEO = Walker(tuple(range(1, 25)), 3, 1, 56.0, 17, 10)
BEIDOU_MEO = Walker((*range(19, 31), *range(32, 38), *range(41, 47)), 3, 1, 55.0, 13, 7, 30.0)
GLONASS = Walker(tuple(range(1, 25)), 3, 1, 64.8, 17, 8, 60.0, -1.0)
BEIDOU_IGSO = {"prns": (38, 39, 40), "inclination_deg": 55.0, "crossing_lon_deg": 118.0}
BEIDOU_GEO_LONGITUDES_DEG = {1: 140.0, 2: 80.0, 3: 110.5, 4: 160.0, 5: 58.75}


def _node_rate(mean_motion: float, a_m: float, inclination: float) -> float:
    """J2 secular regression of the node, rad/s (Vallado eq. 9-41, circular orbit)."""
    return -1.5 * mean_motion * J2 * (A_M / a_m) ** 2 * np.cos(inclination)


def _walker_elements(pattern: Walker, mu: float, omega_e: float, since_s: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray, float, float, float]:
    """Earth-fixed node longitude and argument of latitude (n_sat, n_t) at ``since_s`` seconds
    after ``REFERENCE_UTC``, with the semi-major axis (m), inclination (rad) and node rate;
    ``mu`` and ``omega_e`` are the system's."""
    inc = np.radians(pattern.inclination_deg)
    n_sat = len(pattern.prns)
    per_plane = n_sat // pattern.planes
    k = np.arange(n_sat)
    plane, slot = k // per_plane, k % per_plane
    raan0 = np.radians(pattern.raan0_deg) + 2 * np.pi * plane / pattern.planes
    arg_lat0 = (pattern.slot_step_sign * 2 * np.pi * slot / per_plane
                + 2 * np.pi * pattern.phasing * plane / n_sat)
    # the repeat condition fixes the mean motion; the node rate depends on it only weakly, so
    # two passes settle it
    node_rate, a = 0.0, 0.0
    for _ in range(2):
        node_period = 2 * np.pi / (omega_e - node_rate)
        mean_motion = 2 * np.pi * pattern.revolutions / (pattern.days * node_period)
        a = (mu / mean_motion**2) ** (1.0 / 3.0)
        node_rate = _node_rate(mean_motion, a, inc)
    node_lon = (raan0[:, None] - GHA_REFERENCE_RAD
                - (omega_e - node_rate) * since_s[None, :])
    arg_lat = arg_lat0[:, None] + mean_motion * since_s[None, :]
    return node_lon, arg_lat, a, inc, node_rate


def circular_records(system: str, prns: np.ndarray, node_lon: np.ndarray, arg_lat: np.ndarray,
                     toe_gps_abs: np.ndarray, a_m: float | np.ndarray,
                     inclination: float | np.ndarray, node_rate: float | np.ndarray,
                     ) -> pd.DataFrame:
    """Keplerian broadcast records of circular orbits given, per satellite (rows) and toe
    (columns), the Earth-fixed longitude of the node and the argument of latitude at toe.

    Broadcast convention (IS-GPS-200 Table 20-IV; Galileo and BeiDou MEO/IGSO the same): node
    longitude at toe = Omega_0 - Omega_e toe, with toe in seconds of the system's week (BDT for
    BeiDou) and the system's Omega_e; omega = 0, so M_0 is the argument of latitude.

    Parameters
    ----------
    system : RINEX letter (G, E, C, J)
    prns : ndarray, shape (n_sat,)
    node_lon, arg_lat : ndarray, shape (n_sat, n_toe), rad
    toe_gps_abs : ndarray, shape (n_toe,), GPS seconds since 1980-01-06
    a_m, inclination, node_rate : semi-major axis (m), inclination (rad), node rate (rad/s),
        scalars or per satellite (n_sat,)

    Returns
    -------
    pandas.DataFrame, the navigation table (``simulator.columns.GNSS_NAV``).
    """
    omega_e = KEPLER_CONSTANTS[system][1]
    sys_abs = toe_gps_abs + (BDT_MINUS_GPST_S - BDS_WEEK_OFFSET * SECONDS_PER_WEEK
                             if system == "C" else 0.0)
    n_sat, n_toe = node_lon.shape
    nav = _records(system, prns, sys_abs, np.arange(n_toe) % 256)
    toe = sys_abs - np.floor(sys_abs / SECONDS_PER_WEEK) * SECONDS_PER_WEEK

    def per_sat(value: float | np.ndarray) -> np.ndarray:
        return np.repeat(np.broadcast_to(np.asarray(value, dtype=float), (n_sat,)), n_toe)

    nav["sqrt_a"] = np.sqrt(per_sat(a_m))
    nav["i0"] = per_sat(inclination)
    nav["omega_dot"] = per_sat(node_rate)
    nav["omega0"] = np.angle(np.exp(1j * (node_lon + omega_e * toe[None, :]))).ravel()
    nav["m0"] = np.angle(np.exp(1j * arg_lat)).ravel()
    return nav.astype({c: int for c in _INT_COLUMNS})


_INT_COLUMNS = ("sv", "week", "iode", "health", "data_source", "glo_channel")


def _records(system: str, prns: np.ndarray, toe_abs: np.ndarray, iode: np.ndarray
             ) -> pd.DataFrame:
    """An empty navigation table of satellites ``prns`` (rows) x record times ``toe_abs``
    (seconds since the system's week 0), with system, sv, week, toe = toc and iode set."""
    import pandas as pd

    n_sat, n_toe = len(prns), len(toe_abs)
    week = np.floor(toe_abs / SECONDS_PER_WEEK)
    nav = pd.DataFrame(0.0, index=range(n_sat * n_toe), columns=list(col.GNSS_NAV))
    nav["system"] = system
    nav["sv"] = np.repeat(prns, n_toe)
    nav["week"] = np.tile(week, n_sat)
    nav["toe"] = nav["toc"] = np.tile(toe_abs - week * SECONDS_PER_WEEK, n_sat)
    nav["iode"] = np.tile(iode, n_sat)
    return nav


def _toe_grid(utc: dt.datetime, span_s: float, interval_s: float, offset_s: float = 0.0
              ) -> np.ndarray:
    """GPS seconds since 1980-01-06 of record times every ``interval_s`` (plus ``offset_s``)
    from the last one at or before ``utc`` until ``span_s`` later is covered."""
    week, tow = utc_to_gps(utc)
    start = week * SECONDS_PER_WEEK + tow
    first = np.floor((start - offset_s) / interval_s) * interval_s + offset_s
    return first + np.arange(0.0, span_s + 2 * interval_s, interval_s)


def _since_reference(toe_gps_abs: np.ndarray) -> np.ndarray:
    reference_gps = (REFERENCE_UTC - GPS_EPOCH).total_seconds() + leap_seconds(REFERENCE_UTC)
    return toe_gps_abs - reference_gps


def nominal_galileo_navigation(utc: dt.datetime, span_s: float = 86400.0,
                               interval_s: float = 3600.0) -> pd.DataFrame:
    """The nominal Galileo constellation (module docstring) as records every ``interval_s``
    covering ``span_s`` from ``utc``."""
    toe = _toe_grid(utc, span_s, interval_s)
    node_lon, arg_lat, a, inc, rate = _walker_elements(GALILEO, *KEPLER_CONSTANTS["E"],
                                                       _since_reference(toe))
    nav = circular_records("E", np.array(GALILEO.prns), node_lon, arg_lat, toe, a, inc, rate)
    nav["data_source"] = 517  # I/NAV E1-B, clock for E1,E5b
    return nav


def nominal_beidou_navigation(utc: dt.datetime, span_s: float = 86400.0,
                              interval_s: float = 3600.0) -> pd.DataFrame:
    """The nominal BeiDou-3 constellation (24 MEO, 3 IGSO, 5 GEO; module docstring) as records
    every ``interval_s`` covering ``span_s`` from ``utc``."""
    import pandas as pd

    mu, omega_e = KEPLER_CONSTANTS["C"]
    toe = _toe_grid(utc, span_s, interval_s)
    since = _since_reference(toe)
    node_lon, arg_lat, a, inc, rate = _walker_elements(BEIDOU_MEO, mu, omega_e, since)
    meo = circular_records("C", np.array(BEIDOU_MEO.prns), node_lon, arg_lat, toe, a, inc, rate)
    a_geo = (mu / omega_e**2) ** (1.0 / 3.0)  # geosynchronous
    # IGSO: node longitude + argument of latitude is the crossing longitude at every time
    prns = np.array(BEIDOU_IGSO["prns"])
    u = (-2 * np.pi / 3 * np.arange(len(prns)))[:, None] + omega_e * since[None, :]
    igso = circular_records("C", prns, np.radians(BEIDOU_IGSO["crossing_lon_deg"]) - u, u,
                            toe, a_geo, np.radians(BEIDOU_IGSO["inclination_deg"]), 0.0)
    # GEO, in the ICD's frame of toe: node at 180 deg, inclination 5 deg, the satellite at
    # argument of latitude (longitude - 180 deg) at toe, moving at Omega_e
    prns = np.array(list(BEIDOU_GEO_LONGITUDES_DEG))
    lon = np.radians(np.array(list(BEIDOU_GEO_LONGITUDES_DEG.values())))
    geo = circular_records("C", prns, np.full((len(prns), len(toe)), np.pi),
                           np.repeat(lon[:, None] - np.pi, len(toe), axis=1), toe, a_geo,
                           np.radians(5.0), 0.0)
    return pd.concat([meo, igso, geo], ignore_index=True)


GLONASS_RECORD_INTERVAL_S = 1800.0
GLONASS_TB_OFFSET_S = 900.0  # t_b on the quarter hours (00:15, 00:45, ... Moscow time)


def nominal_glonass_navigation(utc: dt.datetime, span_s: float = 86400.0) -> pd.DataFrame:
    """The nominal GLONASS constellation (module docstring): state-vector records every 30 min
    covering ``span_s`` from ``utc``, one orbit per slot integrated through them (ICD 2008
    A.3.1.2, no lunisolar term) from the nominal circular state at the first t_b."""

    leap = leap_seconds(utc)
    # t_b on the UTC quarter hours (Moscow time is UTC + 3 h), as GPS seconds
    toe = _toe_grid(utc, span_s, GLONASS_RECORD_INTERVAL_S, GLONASS_TB_OFFSET_S + leap)
    node_lon, arg_lat, a, inc, rate = _walker_elements(GLONASS, MU_GLO_M3_S2,
                                                       OMEGA_E_GLO_RAD_S, _since_reference(toe[:1]))
    lon, u = node_lon[:, 0], arg_lat[:, 0]
    in_plane = a * np.stack([np.cos(u), np.sin(u), np.zeros_like(u)], axis=-1)
    in_plane_rate = a * np.sqrt(MU_GLO_M3_S2 / a**3) * np.stack(
        [-np.sin(u), np.cos(u), np.zeros_like(u)], axis=-1)
    rot = _rotation(lon, inc)
    pos = np.einsum("nij,nj->ni", rot, in_plane)
    node_spin = (rate - OMEGA_E_GLO_RAD_S) * np.stack(
        [-pos[:, 1], pos[:, 0], np.zeros(len(pos))], axis=-1)
    state = np.concatenate([pos, np.einsum("nij,nj->ni", rot, in_plane_rate) + node_spin],
                           axis=-1)
    steps = int(round(GLONASS_RECORD_INTERVAL_S / STEP_S))
    no_lunisolar = np.zeros((len(pos), 3))
    states = [state]
    for _ in range(len(toe) - 1):  # one orbit through every record: recursive in time
        for _ in range(steps):
            state = rk4_step(state, no_lunisolar, STEP_S)
        states.append(state)
    states = np.stack(states, axis=1)  # (n_sat, n_toe, 6)
    n_toe = states.shape[1]
    moscow_s = (toe - leap + 3 * 3600.0) % 86400.0  # t_b in Moscow time of day
    nav = _records("R", np.array(GLONASS.prns), toe, moscow_s // 900)
    for k, key in enumerate(("glo_x", "glo_y", "glo_z", "glo_vx", "glo_vy", "glo_vz")):
        nav[key] = states[..., k].ravel()
    nav["glo_channel"] = np.repeat([SLOT_CHANNELS[p] for p in GLONASS.prns], n_toe)
    return nav.astype({c: int for c in _INT_COLUMNS})


def _rotation(node_lon: np.ndarray, inclination: float) -> np.ndarray:
    """R3(-node) R1(-i): orbit plane to Earth-fixed axes, shape (n, 3, 3)."""
    co, so = np.cos(node_lon), np.sin(node_lon)
    ci, si = np.cos(inclination), np.sin(inclination)
    zero, one = np.zeros_like(co), np.ones_like(co)
    return np.stack([np.stack([co, -so * ci, so * si], axis=-1),
                     np.stack([so, co * ci, -co * si], axis=-1),
                     np.stack([zero, si * one, ci * one], axis=-1)], axis=-2)


__all__ = ["GALILEO", "BEIDOU_MEO", "BEIDOU_IGSO", "BEIDOU_GEO_LONGITUDES_DEG", "GLONASS",
           "circular_records", "nominal_galileo_navigation", "nominal_beidou_navigation",
           "nominal_glonass_navigation"]
