"""The skies landnav ships, as broadcast records (a navigation table) for any date: with
``sky_navigation``, the drive's sky of every enabled system, Galileo, BeiDou and GLONASS from
their nominal constellations (``simulator.gnss.nominal``) or all from a navigation file. For
GPS, the real constellation of a broadcast almanac (the default sky,
``almanac_gps_navigation``) and the nominal 24 baseline slots of the GPS SPS Performance
Standard, optionally with expandable slots split into their fore/aft pairs.

The Performance Standard defines each slot by its right ascension of the ascending node (RAAN)
and argument of latitude at the epoch 1993-07-01 00:00 UT, when the Greenwich hour angle was
18 h 36 min 14.4 s, on circular orbits inclined 55 deg with a 26 559.7 km semi-major axis. The
constellation is maintained on a repeating ground track (two revolutions per sidereal day), so
the slots are propagated to a date with that repeat condition: the Earth-fixed longitude of
each node regresses by (omega_e - Omega_dot) and the argument of latitude advances by exactly two
revolutions per repeat period, which keeps the slots on their ground tracks (a plain two-body
propagation over decades would not). It is the nominal pattern, not the real sky: the real
constellation drifts along and across its tracks (the real 2020-01-01 almanac has its planes
about 14 deg of node longitude, about an hour of sidereal time, away from the propagated 1993
slots), so a scenario that must reproduce a real sky names a real almanac or navigation file.

The "Expandable 24" configuration (flown since 2011) splits the expandable slots B1, D2 and F2
each into a fore (F) and an aft (A) location in the same plane, ahead of and behind the baseline
slot, giving 27 slots. ``expanded`` chooses which of them are split. PRNs: 1-24 are the baseline
slots A1 ... F4 in order; an expanded slot's fore location keeps its slot's PRN (B1F 5, D2F 14,
F2F 22) and its aft location takes a PRN of its own (B1A 25, D2A 26, F2A 27), whatever else is
expanded.

The real constellation (``almanac_gps_navigation``, scenario name ``gps-almanac``) is the YUMA
almanac of week 38 (mod 1024, GPS week 2086), time of applicability 503808 s (2020-01-03
19:56:48 GPST), as published for 2020-01-01 by the US Coast Guard Navigation Center (NAVCEN) and
distributed with Stanford's MAAST toolset (``almyuma_01jan2020.txt``); US Government work, public
domain. It is the newest real almanac this project can obtain (no package on PyPI ships one), and
it is shipped as package data (``simulator/gnss/data/yuma_2020-01-01.txt``, byte-identical to the
file of the reference data). 31 PRNs: 30 healthy and PRN 04 flagged unhealthy (health 63: GPS III
SV01, launched December 2018, set healthy on 2020-01-13).

A scenario at another date sees the almanac's sky re-epoched by a whole number k of ground-track
repeat periods P (``REPEAT_PERIOD_S``, 86 155 s: two revolutions per sidereal day of the
regressing orbit plane): the Earth-fixed positions at time t are those the almanac gives at
t - k P, with k chosen so that t - k P lies within half a period of the time of applicability
(where the almanac is accurate to a few kilometres). So every satellite keeps its plane's
Earth-fixed node longitude and its place on its ground track, the whole constellation stays one
consistent real snapshot, and the elements are only shifted in time (toe, toc, week and the
node's week-start longitude Omega_0, which carries the Earth's rotation; IS-GPS-200 Table
20-IV), never propagated over years. They are written as a record per satellite every two hours,
as broadcast ephemerides are (each the same orbit re-referenced to its toe), so that exported
RINEX navigation files are accepted by receivers' and RTKLIB's age checks. Consequence: a 2026
scenario sees the 2020 constellation (its 31 satellites, PRNs and slots, the
sidereal-time-of-day pattern of their passes), not the 2026 one: satellites launched or retired
since then are not there, and the real slow drift of the constellation along its tracks is not
followed. Counts and geometry are those of a real 31-satellite GPS (8.6-10.0 above 10 deg,
averaged over a day, at seven sites from 34 S to 60 N); a scenario that must reproduce a
particular day's sky names that day's navigation file.

Public names
------------
NOMINAL_SLOTS, EXPANDABLE_SLOTS, AFT_PRN, ALMANAC_FILE, ALMANAC_WEEK, NOMINAL_SYSTEMS, GPS_SKIES,
nominal_slots, nominal_gps_navigation, almanac_gps_navigation, missing_systems, QZSS_WITHOUT_FILE,
sky_navigation.

References
----------
IS-GPS-200N Table 20-VI (almanac parameters, evaluated with the Table 20-IV algorithm).
GPS SPS Performance Standard, 4th ed. (2008), Table 3.4-1 (baseline 24-slot constellation, slot
locations as of the epoch; the same values as the 3rd ed. (2001) Table 3-1) and Table 3.4-2
(expandable 24-slot constellation definition); 3rd ed. (2001) Table A-2-1 (nominal constellation
plan: e = 0, i = 55 deg, A = 26 559.7 km, RAAN rate -4.4874e-7 deg/s). The 5th ed. (2020) Tables
3.2-1 and 3.2-2 restate the same slots at 2016-12-31 23:59:43 UTC (Greenwich hour angle
100.765 deg): every RAAN +16.003 deg and argument of latitude -28.586 deg from the values here,
the same ground-track equatorial crossings (see tests/gnss/test_gnss_constellation.py).
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from simulator.gnss.constants import MU_GPS_M3_S2, OMEGA_E_DOT_RAD_S, SECONDS_PER_WEEK
from simulator.gnss.navfiles import read_navigation, read_yuma
from simulator.gnss.nominal import (
    circular_records,
    nominal_beidou_navigation,
    nominal_galileo_navigation,
    nominal_glonass_navigation,
)
from simulator.gnss.timesystems import SYSTEM_LETTERS, SYSTEMS
from simulator.timebase import GPS_EPOCH, utc_to_gps

if TYPE_CHECKING:
    import pandas as pd

# slot: (RAAN deg, argument of latitude deg) at the reference epoch (SPS PS 2008 Table 3.4-1)
NOMINAL_SLOTS: dict[str, tuple[float, float]] = {
    "A1": (272.847, 268.126), "A2": (272.847, 161.786), "A3": (272.847, 11.676),
    "A4": (272.847, 41.806),
    "B1": (332.847, 80.956), "B2": (332.847, 173.336), "B3": (332.847, 309.976),
    "B4": (332.847, 204.376),
    "C1": (32.847, 111.876), "C2": (32.847, 11.796), "C3": (32.847, 339.666),
    "C4": (32.847, 241.556),
    "D1": (92.847, 135.226), "D2": (92.847, 265.446), "D3": (92.847, 35.156),
    "D4": (92.847, 167.356),
    "E1": (152.847, 197.046), "E2": (152.847, 302.596), "E3": (152.847, 66.066),
    "E4": (152.847, 333.686),
    "F1": (212.847, 238.886), "F2": (212.847, 345.226), "F3": (212.847, 105.206),
    "F4": (212.847, 135.346),
}
# expandable slot: {location: (RAAN deg, argument of latitude deg)} at the same epoch, fore
# first (SPS PS 2008 Table 3.4-2, as also transcribed in github.com/Cfrazzle/SRCL_FFNAV
# GPS_Simulator/FFNAV_RunGPS.m; checked against the 2020 edition's Table 3.2-2 in the tests)
EXPANDABLE_SLOTS: dict[str, dict[str, tuple[float, float]]] = {
    "B1": {"B1F": (332.847, 94.916), "B1A": (332.847, 66.356)},
    "D2": {"D2F": (92.847, 282.676), "D2A": (92.847, 257.976)},
    "F2": {"F2F": (212.847, 0.456), "F2A": (212.847, 334.016)},
}
AFT_PRN = {"B1A": 25, "D2A": 26, "F2A": 27}  # PRNs of the aft locations (fore keeps the slot's)
SLOT_EPOCH_UTC = dt.datetime(1993, 7, 1)  # reference epoch of the slot table, UT
GHA_EPOCH_RAD = np.radians((18 + 36 / 60 + 14.4 / 3600) * 15.0)  # Greenwich hour angle then
INCLINATION_RAD = np.radians(55.0)  # nominal inclination
RAAN_RATE_RAD_S = np.radians(-4.4874e-7)  # nodal regression (SPS PS 2001 Table A-2-1)
# repeat period: the node returns to the same Earth-fixed longitude (one "sidereal day" of the
# regressing orbit plane), during which the satellite completes exactly two revolutions
REPEAT_PERIOD_S = 2.0 * np.pi / (OMEGA_E_DOT_RAD_S - RAAN_RATE_RAD_S)
MEAN_MOTION_RAD_S = 4.0 * np.pi / REPEAT_PERIOD_S


def nominal_slots(expanded: Iterable[str] = ()) -> pd.DataFrame:
    """The slot table of the nominal constellation with the ``expanded`` slots (any of
    ``EXPANDABLE_SLOTS``: B1, D2, F2) replaced by their fore/aft pairs.

    Returns
    -------
    pandas.DataFrame
        One row per satellite, in PRN order: ``prn``, ``slot`` (A1 ... F4, B1F, B1A, ...),
        ``raan_deg`` and ``arg_lat_deg`` at the reference epoch ``SLOT_EPOCH_UTC``.
    """
    import pandas as pd

    expanded = list(expanded)
    unknown = sorted(set(expanded) - set(EXPANDABLE_SLOTS))
    if unknown:
        raise ValueError(f"not expandable slot(s) {', '.join(unknown)}; the expandable slots "
                         f"are {', '.join(EXPANDABLE_SLOTS)}")
    rows = []
    for prn, (slot, location) in enumerate(NOMINAL_SLOTS.items(), start=1):
        if slot not in expanded:
            rows.append((prn, slot, *location))
            continue
        (fore, fore_loc), (aft, aft_loc) = EXPANDABLE_SLOTS[slot].items()
        rows += [(prn, fore, *fore_loc), (AFT_PRN[aft], aft, *aft_loc)]
    table = pd.DataFrame(rows, columns=["prn", "slot", "raan_deg", "arg_lat_deg"])
    return table.sort_values("prn", ignore_index=True)


def nominal_gps_navigation(utc: dt.datetime, span_s: float = 86400.0,
                           interval_s: float = 7200.0,
                           expanded: Iterable[str] = ()) -> pd.DataFrame:
    """Broadcast-style elements of the nominal slots (``nominal_slots(expanded)``), one record
    per satellite every ``interval_s`` from the last even interval before ``utc`` over
    ``span_s``.

    PRNs are those of ``nominal_slots`` (1-24 for slots A1 ... F4 in order; 25-27 for the aft
    locations of expanded slots). Orbits are circular (e = 0, so the relativistic clock term is
    zero), satellite clocks are perfect (af0 = af1 = af2 = T_GD = 0) and every record is
    healthy.

    Returns
    -------
    pandas.DataFrame
        The navigation table (``simulator.columns.GNSS_NAV``).
    """
    slots = nominal_slots(expanded)
    week, tow = utc_to_gps(utc)
    first = np.floor(tow / interval_s) * interval_s
    toe_abs = week * SECONDS_PER_WEEK + first + np.arange(0.0, span_s + interval_s, interval_s)
    epoch_gps = (SLOT_EPOCH_UTC - GPS_EPOCH).total_seconds() + 9.0  # GPS - UTC = 9 s then
    since = toe_abs - epoch_gps
    raan0 = np.radians(slots["raan_deg"].to_numpy())
    arg_lat0 = np.radians(slots["arg_lat_deg"].to_numpy())
    # Earth-fixed longitude of the node and argument of latitude at each toe
    node_lon = (raan0[:, None] - GHA_EPOCH_RAD
                - (OMEGA_E_DOT_RAD_S - RAAN_RATE_RAD_S) * since[None, :])
    arg_lat = arg_lat0[:, None] + MEAN_MOTION_RAD_S * since[None, :]
    a_m = (MU_GPS_M3_S2 / MEAN_MOTION_RAD_S**2) ** (1.0 / 3.0)
    nav = circular_records("G", slots["prn"].to_numpy(), node_lon, arg_lat, toe_abs, a_m,
                           INCLINATION_RAD, RAAN_RATE_RAD_S)
    return nav


# the shipped real almanac (NAVCEN YUMA for 2020-01-01) and its full GPS week (YUMA's week 38)
ALMANAC_FILE = Path(__file__).parent / "data" / "yuma_2020-01-01.txt"
ALMANAC_WEEK = 2086


def almanac_gps_navigation(utc: dt.datetime, span_s: float = 86400.0,
                           interval_s: float = 7200.0, path: Path = ALMANAC_FILE,
                           week: int = ALMANAC_WEEK) -> pd.DataFrame:
    """The real GPS constellation of an almanac, re-epoched to ``utc`` by whole ground-track
    repeat periods (module docstring), as broadcast-style records: one per satellite every
    ``interval_s`` from the last even interval before ``utc`` over ``span_s`` (so that a record
    is always within half an interval, as broadcast ephemerides are, and RINEX readers that
    refuse older ones accept them).

    Each record is the almanac's orbit re-referenced to its toe: the two-body elements carried
    over the time from the (shifted) time of applicability, exactly (M_0 + n dt, Omega_0 with
    the node's regression and the Earth's rotation, af0 + af1 dt; IS-GPS-200 Table 20-IV), so
    every record gives the same Earth-fixed orbit, that of the almanac at t - k P.

    Parameters
    ----------
    utc : datetime
        Start of the drive (UTC).
    span_s : float
        Length of the drive, s; the shift is chosen for its middle.
    interval_s : float
        Spacing of the records' toe, s (broadcast ephemerides: 2 h).
    path, week : the YUMA almanac and its full GPS week (default: the shipped 2020-01-01 one).

    Returns
    -------
    pandas.DataFrame
        The navigation table (``simulator.columns.GNSS_NAV``), unhealthy satellites included
        with their health code; ``attrs``: ``kind`` = ``almanac``, ``source`` (the file's name)
        and ``epoch_shift_s`` (k P, s).
    """
    alm = read_yuma(path, reference_week=week)
    toa_abs = alm["week"].to_numpy() * SECONDS_PER_WEEK + alm["toe"].to_numpy()
    start_week, start_tow = utc_to_gps(utc)
    start_abs = start_week * SECONDS_PER_WEEK + start_tow
    shift_s = round((start_abs + 0.5 * span_s - float(np.median(toa_abs))) / REPEAT_PERIOD_S
                    ) * REPEAT_PERIOD_S
    toe_abs = (np.floor(start_abs / interval_s) * interval_s
               + np.arange(0.0, span_s + interval_s, interval_s))
    n_toe = len(toe_abs)
    nav = alm.loc[alm.index.repeat(n_toe)].reset_index(drop=True)
    new_abs = np.tile(toe_abs, len(alm))
    delta = new_abs - np.repeat(toa_abs + shift_s, n_toe)  # time from the elements' epoch
    new_week = np.floor(new_abs / SECONDS_PER_WEEK)
    new_toe = new_abs - new_week * SECONDS_PER_WEEK
    mean_motion = np.sqrt(MU_GPS_M3_S2 / nav["sqrt_a"].to_numpy() ** 6) + nav["delta_n"].to_numpy()
    # Omega_k = Omega_0 + (Omega_dot - omega_e) t_k - omega_e toe: the same Earth-fixed node at
    # the same time needs Omega_0 to take up the node's motion over delta and the change of
    # toe within its week
    omega0 = (nav["omega0"].to_numpy() + OMEGA_E_DOT_RAD_S * (new_toe - nav["toe"].to_numpy())
              + (nav["omega_dot"].to_numpy() - OMEGA_E_DOT_RAD_S) * delta)
    nav["omega0"] = np.angle(np.exp(1j * omega0))
    nav["m0"] = np.angle(np.exp(1j * (nav["m0"].to_numpy() + mean_motion * delta)))
    nav["af0"] = nav["af0"].to_numpy() + nav["af1"].to_numpy() * delta
    nav["week"] = new_week.astype(int)
    nav["toe"] = nav["toc"] = new_toe
    nav["iode"] = np.tile(np.arange(n_toe) % 256, len(alm))
    nav.attrs.update(kind="almanac", source=Path(path).name, epoch_shift_s=float(shift_s))
    return nav


# the nominal constellation of each system without a shipped almanac (``simulator.gnss.nominal``)
NOMINAL_SYSTEMS = {"E": nominal_galileo_navigation, "C": nominal_beidou_navigation,
                   "R": nominal_glonass_navigation}
GPS_SKIES = ("gps-almanac", "nominal-gps")  # the GPS skies known by name


def missing_systems(nav: pd.DataFrame, systems: Iterable[str], source: str) -> str | None:
    """What is wrong when ``nav`` (read from ``source``) lacks some of ``systems`` (scenario
    names ``gps``, ``galileo``, ...), or None."""
    have = set(nav["system"]) if "system" in nav.columns else {"G"}
    lacking = [name for name in systems if SYSTEMS[name] not in have]
    if not lacking:
        return None
    names = ", ".join(sorted(SYSTEM_LETTERS[s] for s in have))
    return f"{source}: no {', '.join(lacking)} navigation record (the file has {names})"


QZSS_WITHOUT_FILE = "qzss needs a navigation file that has it (no nominal QZSS constellation)"


def sky_navigation(source: str, systems: Iterable[str], utc: dt.datetime, span_s: float,
                   expanded: Iterable[str] = (), reference_week: int | None = None
                   ) -> pd.DataFrame:
    """The navigation table of a drive's sky: the records of ``systems`` (scenario names).

    ``source`` is a named GPS sky (``gps-almanac``, ``nominal-gps``: GPS from it, Galileo,
    BeiDou and GLONASS from their nominal constellations, ``simulator.gnss.nominal``) or a
    RINEX navigation file / YUMA almanac, which must hold every system asked for.

    Raises
    ------
    ValueError
        Naming the file and the systems it lacks (or QZSS with a named sky: QZSS has no
        nominal constellation here).
    """
    import pandas as pd

    systems = list(systems)
    if source not in GPS_SKIES:
        nav = read_navigation(source, reference_week=reference_week)
        problem = missing_systems(nav, systems, source)
        if problem:
            raise ValueError(problem)
        attrs = dict(nav.attrs)
        nav = nav[nav["system"].isin([SYSTEMS[s] for s in systems])].reset_index(drop=True)
        nav.attrs.update(attrs)
        return nav
    if "qzss" in systems:
        raise ValueError(QZSS_WITHOUT_FILE)
    parts = []
    if "gps" in systems:
        parts.append(almanac_gps_navigation(utc, span_s) if source == "gps-almanac"
                     else nominal_gps_navigation(utc, span_s + 7200.0, expanded=expanded))
    parts += [NOMINAL_SYSTEMS[SYSTEMS[s]](utc, span_s) for s in systems if s != "gps"]
    attrs = dict(parts[0].attrs) if "gps" in systems else {"kind": "ephemeris"}
    nav = pd.concat(parts, ignore_index=True)
    nav.attrs.update(attrs)
    return nav
