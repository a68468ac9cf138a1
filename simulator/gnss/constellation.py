"""The nominal GPS constellation: the 24 baseline slots of the GPS SPS Performance Standard as
broadcast Keplerian elements (a navigation table), for any date.

The Performance Standard defines each slot by its right ascension of the ascending node (RAAN)
and argument of latitude at the epoch 1993-07-01 00:00 UT, when the Greenwich hour angle was
18 h 36 min 14.4 s, on circular orbits inclined 55 deg with a 26 559.7 km semi-major axis. The
constellation is maintained on a repeating ground track (two revolutions per sidereal day), so
the slots are propagated to a date with that repeat condition: the Earth-fixed longitude of
each node regresses by (omega_e - Omega_dot) and the argument of latitude advances by exactly two
revolutions per repeat period. This keeps the sky of a given place at a given sidereal time as
the real constellation does, which a plain two-body propagation over 30 years would not.

Public names
------------
NOMINAL_SLOTS, nominal_gps_navigation.

References
----------
GPS SPS Performance Standard, 5th ed. (2020), Table 3.2-1 (baseline 24-slot constellation, slot
locations as of the epoch); 4th ed. (2008) Table 3.4-1 and 3rd ed. (2001) Table A-2-1 (nominal
constellation plan: e = 0, i = 55 deg, A = 26 559.7 km, RAAN rate -4.4874e-7 deg/s).
"""

from __future__ import annotations

import datetime as dt

import numpy as np
import pandas as pd

from simulator import columns as col
from simulator.gnss.constants import MU_GPS_M3_S2, OMEGA_E_DOT_RAD_S, SECONDS_PER_WEEK
from simulator.timebase import GPS_EPOCH, utc_to_gps

# slot: (RAAN deg, argument of latitude deg) at the reference epoch (SPS PS 2020 Table 3.2-1)
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
SLOT_EPOCH_UTC = dt.datetime(1993, 7, 1)  # reference epoch of the slot table, UT
GHA_EPOCH_RAD = np.radians((18 + 36 / 60 + 14.4 / 3600) * 15.0)  # Greenwich hour angle then
INCLINATION_RAD = np.radians(55.0)  # nominal inclination
RAAN_RATE_RAD_S = np.radians(-4.4874e-7)  # nodal regression (SPS PS 2001 Table A-2-1)
# repeat period: the node returns to the same Earth-fixed longitude (one "sidereal day" of the
# regressing orbit plane), during which the satellite completes exactly two revolutions
REPEAT_PERIOD_S = 2.0 * np.pi / (OMEGA_E_DOT_RAD_S - RAAN_RATE_RAD_S)
MEAN_MOTION_RAD_S = 4.0 * np.pi / REPEAT_PERIOD_S


def nominal_gps_navigation(utc: dt.datetime, span_s: float = 86400.0,
                           interval_s: float = 7200.0) -> pd.DataFrame:
    """Broadcast-style elements of the 24 nominal slots, one record per slot every
    ``interval_s`` from the last even interval before ``utc`` over ``span_s``.

    PRNs 1-24 are assigned to slots A1 ... F4 in order. Orbits are circular (e = 0, so the
    relativistic clock term is zero), satellite clocks are perfect (af0 = af1 = af2 = T_GD = 0)
    and every record is healthy.

    Returns
    -------
    pandas.DataFrame
        The navigation table (``simulator.columns.GNSS_NAV``).
    """
    week, tow = utc_to_gps(utc)
    first = np.floor(tow / interval_s) * interval_s
    toe_abs = week * SECONDS_PER_WEEK + first + np.arange(0.0, span_s + interval_s, interval_s)
    epoch_gps = (SLOT_EPOCH_UTC - GPS_EPOCH).total_seconds() + 9.0  # GPS - UTC = 9 s then
    since = toe_abs - epoch_gps
    raan0, arg_lat0 = (np.radians(np.array(v)) for v in zip(*NOMINAL_SLOTS.values(),
                                                                strict=True))
    # Earth-fixed longitude of the node and argument of latitude at each toe
    node_lon = (raan0[:, None] - GHA_EPOCH_RAD
                - (OMEGA_E_DOT_RAD_S - RAAN_RATE_RAD_S) * since[None, :])
    arg_lat = arg_lat0[:, None] + MEAN_MOTION_RAD_S * since[None, :]
    toe_week = np.floor(toe_abs / SECONDS_PER_WEEK)
    toe = toe_abs - toe_week * SECONDS_PER_WEEK
    n_slot, n_toe = node_lon.shape
    nav = pd.DataFrame(0.0, index=range(n_slot * n_toe), columns=list(col.GNSS_NAV))
    nav["sv"] = np.repeat(np.arange(1, n_slot + 1), n_toe)
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
