"""The nominal GPS constellation: the 24 baseline slots of the GPS SPS Performance Standard,
optionally with expandable slots split into their fore/aft pairs, as broadcast Keplerian elements
(a navigation table), for any date.

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

Public names
------------
NOMINAL_SLOTS, EXPANDABLE_SLOTS, AFT_PRN, nominal_slots, nominal_gps_navigation.

References
----------
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
from typing import TYPE_CHECKING

import numpy as np

from simulator import columns as col
from simulator.gnss.constants import MU_GPS_M3_S2, OMEGA_E_DOT_RAD_S, SECONDS_PER_WEEK
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
    import pandas as pd

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
    toe_week = np.floor(toe_abs / SECONDS_PER_WEEK)
    toe = toe_abs - toe_week * SECONDS_PER_WEEK
    n_slot, n_toe = node_lon.shape
    nav = pd.DataFrame(0.0, index=range(n_slot * n_toe), columns=list(col.GNSS_NAV))
    nav["sv"] = np.repeat(slots["prn"].to_numpy(), n_toe)
    nav["week"] = np.tile(toe_week, n_slot).astype(int)
    nav["toe"] = nav["toc"] = np.tile(toe, n_slot)
    nav["iode"] = np.tile(np.arange(n_toe) % 256, n_slot)
    nav["health"] = 0
    nav["sqrt_a"] = (MU_GPS_M3_S2 / MEAN_MOTION_RAD_S**2) ** (1.0 / 6.0)
    nav["i0"] = INCLINATION_RAD
    # broadcast convention: node longitude at toe = omega0 - omega_e * toe (IS-GPS-200 20-IV)
    nav["omega0"] = np.angle(np.exp(1j * (node_lon + OMEGA_E_DOT_RAD_S * toe[None, :]))).ravel()
    nav["m0"] = np.angle(np.exp(1j * arg_lat)).ravel()  # omega = 0: M0 is the arg. of latitude
    nav["omega_dot"] = RAAN_RATE_RAD_S
    nav = nav.astype({"sv": int, "week": int, "iode": int, "health": int})
    return nav
