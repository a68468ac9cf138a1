"""RINEX 3.04 writers: a GPS observation file (C1C pseudorange, D1C Doppler, S1C C/N0) from the
``gnss_raw`` stream and a GPS navigation file from the ``gnss_nav`` stream.

Epochs are written in GPS time (the dataset's ``t`` plus the GPS time of ``t = 0``); values are
rounded to the formats' resolution (F14.3 for observations, D19.12 for navigation parameters).

Public functions
----------------
write_rinex_obs, write_rinex_nav, signal_strength_indicator.

References
----------
RINEX 3.04 (IGS/RTCM-SC104, 2018): Table A2 (observation header), A3 (observation data record),
A5 (navigation header), A6 (GPS navigation data record); section 5.7 (signal strength
indicator from C/N0).
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np
import pandas as pd

from simulator.gnss.constants import SECONDS_PER_WEEK
from simulator.timebase import GPS_EPOCH, gps_to_utc, leap_seconds

PROGRAM = "landnav"
# the order of the 28 numbers after the clock epoch of a GPS record (RINEX 3.04 Table A6),
# with the fields the navigation table does not hold written as the constant beside them
_NAV_ORDER = (
    ("af0", "af1", "af2"),
    ("iode", "crs", "delta_n", "m0"),
    ("cuc", "e", "cus", "sqrt_a"),
    ("toe", "cic", "omega0", "cis"),
    ("i0", "crc", "omega", "omega_dot"),
    ("idot", 0.0, "week", 0.0),  # L2 codes, L2 P data flag
    (2.0, "health", "tgd", "iode"),  # SV accuracy (m), IODC = IODE
    ("toe", 4.0),  # transmission time (taken as toe), fit interval (h)
)


def _label(text: str, label: str) -> str:
    return f"{text:<60.60}{label:<20}"


def _d19(value: float) -> str:
    return f"{value:19.12E}".replace("E", "D")


def _obs(value: float) -> str:
    """An observation field (F14.3); blank when the value is missing (RINEX 3.04 5.1)."""
    return f"{value:14.3f}" if np.isfinite(value) else " " * 14


def signal_strength_indicator(cn0_dbhz: np.ndarray) -> np.ndarray:
    """RINEX signal strength indicator 1-9 from C/N0 (RINEX 3.04 section 5.7: 1 below 12 dB-Hz,
    one step per 6 dB, 9 at 54 dB-Hz and above)."""
    level = np.floor(np.nan_to_num(np.asarray(cn0_dbhz, dtype=float), nan=0.0) / 6.0)
    return np.clip(level, 1, 9).astype(int)


def _gps_datetime(week: int, seconds: float) -> dt.datetime:
    return GPS_EPOCH + dt.timedelta(seconds=week * SECONDS_PER_WEEK + seconds)


def _stamp() -> str:
    return dt.datetime.now(dt.UTC).strftime("%Y%m%d %H%M%S UTC")


def write_rinex_obs(path: str | Path, raw: pd.DataFrame, gps_week: int, gps_tow_s: float,
                    approx_xyz_m: np.ndarray, marker: str = "LANDNAV") -> Path:
    """Write the raw measurements as a RINEX 3.04 GPS observation file.

    Parameters
    ----------
    raw : pandas.DataFrame
        The ``gnss_raw`` stream (``t``, ``sv``, ``pseudorange``, ``doppler``, ``cn0``).
    gps_week, gps_tow_s : GPS time of ``t = 0``.
    approx_xyz_m : array_like, shape (3,)
        The APPROX POSITION XYZ header value (e.g. the first fix), m.
    """
    path = Path(path)
    raw = raw.sort_values(["t", "sv"], kind="stable")
    first = _gps_datetime(gps_week, gps_tow_s + float(raw["t"].iloc[0])) if len(raw) else \
        _gps_datetime(gps_week, gps_tow_s)
    x, y, z = (float(v) for v in approx_xyz_m)
    times = np.unique(raw["t"].to_numpy())
    lines = [
        _label("     3.04           OBSERVATION DATA    G (GPS)", "RINEX VERSION / TYPE"),
        _label(f"{PROGRAM:<20}{PROGRAM:<20}{_stamp()}", "PGM / RUN BY / DATE"),
        _label(marker, "MARKER NAME"),
        _label("NON_PHYSICAL", "MARKER TYPE"),
        _label(f"{PROGRAM:<20}{PROGRAM:<40}", "OBSERVER / AGENCY"),
        _label(f"{'0':<20}{'LANDNAV SIMULATED':<20}{'1':<20}", "REC # / TYPE / VERS"),
        _label(f"{'0':<20}{'LANDNAV SIMULATED':<20}", "ANT # / TYPE"),
        _label(f"{x:14.4f}{y:14.4f}{z:14.4f}", "APPROX POSITION XYZ"),
        _label(f"{0.0:14.4f}{0.0:14.4f}{0.0:14.4f}", "ANTENNA: DELTA H/E/N"),
        _label("G    3 C1C D1C S1C", "SYS / # / OBS TYPES"),
        _label("DBHZ", "SIGNAL STRENGTH UNIT"),
    ]
    if len(times) > 1:
        lines.append(_label(f"{float(np.min(np.diff(times))):10.3f}", "INTERVAL"))
    lines += [
        _label(f"{first.year:6d}{first.month:6d}{first.day:6d}{first.hour:6d}{first.minute:6d}"
               f"{first.second + first.microsecond / 1e6:13.7f}     GPS", "TIME OF FIRST OBS"),
        _label(f"{leap_seconds(gps_to_utc(gps_week, gps_tow_s)):6d}", "LEAP SECONDS"),
        _label("", "END OF HEADER"),
    ]
    ssi = signal_strength_indicator(raw["cn0"].to_numpy())
    rows = raw.assign(ssi=ssi)
    for t, epoch in rows.groupby("t", sort=True):
        stamp = _gps_datetime(gps_week, gps_tow_s + float(t))
        seconds = stamp.second + stamp.microsecond / 1e6
        lines.append(f"> {stamp.year:4d} {stamp.month:02d} {stamp.day:02d} {stamp.hour:02d} "
                     f"{stamp.minute:02d}{seconds:11.7f}  0{len(epoch):3d}")
        for sv, pr, dop, cn0, s in epoch[["sv", "pseudorange", "doppler", "cn0",
                                           "ssi"]].itertuples(index=False):
            strength = f"{s:1d}" if np.isfinite(cn0) else " "
            lines.append(f"G{int(sv):02d}{_obs(pr)} {strength}{_obs(dop)} {strength}"
                         f"{_obs(cn0)}  ")
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    return path


def write_rinex_nav(path: str | Path, nav: pd.DataFrame, leap_s: int,
                    iono_alpha: list[float] | None = None,
                    iono_beta: list[float] | None = None) -> Path:
    """Write the GPS records of the navigation table as a RINEX 3.04 GPS navigation file
    (records as they are, with the ionosphere coefficients in IONOSPHERIC CORR when given);
    other systems' records are not written."""
    path = Path(path)
    if "system" in nav.columns:
        nav = nav[nav["system"] == "G"]
    lines = [
        _label("     3.04           N: GNSS NAV DATA    G: GPS", "RINEX VERSION / TYPE"),
        _label(f"{PROGRAM:<20}{PROGRAM:<20}{_stamp()}", "PGM / RUN BY / DATE"),
    ]
    for name, coeffs in (("GPSA", iono_alpha), ("GPSB", iono_beta)):
        if coeffs is not None:
            text = name + " " + "".join(f"{c:12.4E}".replace("E", "D") for c in coeffs)
            lines.append(_label(text, "IONOSPHERIC CORR"))
    lines += [_label(f"{leap_s:6d}", "LEAP SECONDS"), _label("", "END OF HEADER")]
    for rec in nav.sort_values(["sv", "week", "toe"], kind="stable").to_dict("records"):
        toc = _gps_datetime(int(rec["week"]), float(rec["toc"]))
        values = [[rec[k] if isinstance(k, str) else k for k in group] for group in _NAV_ORDER]
        lines.append(f"G{int(rec['sv']):02d} {toc.year:4d} {toc.month:02d} {toc.day:02d} "
                     f"{toc.hour:02d} {toc.minute:02d} {toc.second:02d}"
                     + "".join(_d19(v) for v in values[0]))
        lines += ["    " + "".join(_d19(v) for v in group) for group in values[1:]]
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    return path
