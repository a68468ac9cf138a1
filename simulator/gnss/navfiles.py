"""Navigation-file readers: RINEX 2 and 3 GPS navigation messages and YUMA almanacs, each turned
into the one navigation table (columns ``simulator.columns.GNSS_NAV``, one row per ephemeris).

The table's ``attrs`` carry ``kind`` (``ephemeris`` or ``almanac``) and the broadcast ionosphere
coefficients when the file has them: ``iono_alpha`` (s, s/sc, s/sc^2, s/sc^3) and ``iono_beta``
(s, ...), IS-GPS-200 20.3.3.5.1.7.

Numbers are read with a regular expression rather than fixed columns, so files that separate
their fields by blanks instead of keeping the RINEX 2 columns (e.g. Stanford's ``sugl0010.20n``)
read as well as strict ones; a missing trailing field of a record line reads as zero.

Public functions
----------------
read_rinex_nav, read_yuma, read_navigation.

References
----------
RINEX 2.11 (Gurtner & Estey, IGS/RTCM-SC104, 2007), Table A4; RINEX 3.04 (IGS/RTCM-SC104, 2018),
Table A6 (GPS navigation message file, data record); ICD-GPS-240 / YUMA almanac format as
published by the US Coast Guard Navigation Center.
"""

from __future__ import annotations

import datetime as dt
import re
from pathlib import Path
from typing import TYPE_CHECKING

from simulator import columns as col
from simulator.timebase import GPS_EPOCH, SECONDS_PER_WEEK

if TYPE_CHECKING:
    import pandas as pd

_NUMBER = re.compile(r"[+-]?(?:\d+\.\d*|\.\d+|\d+)(?:[DdEe][+-]?\d+)?")

# the 28 numbers after the clock epoch of a GPS record, in file order (RINEX 2.11 Table A4)
_ORBIT_FIELDS = (
    "af0", "af1", "af2",
    "iode", "crs", "delta_n", "m0",
    "cuc", "e", "cus", "sqrt_a",
    "toe", "cic", "omega0", "cis",
    "i0", "crc", "omega", "omega_dot",
    "idot", "l2_codes", "week", "l2p_flag",
    "accuracy", "health", "tgd", "iodc",
    "transmit_time", "fit_interval",
)
# broadcast-orbit lines per record of each RINEX 3 system (data lines after the first one)
_RINEX3_LINES = {"G": 7, "E": 7, "C": 7, "J": 7, "I": 7, "R": 3, "S": 3}


def _numbers(text: str) -> list[float]:
    return [float(x.replace("D", "E").replace("d", "e")) for x in _NUMBER.findall(text)]


def _gps_seconds(epoch: dt.datetime) -> float:
    return (epoch - GPS_EPOCH).total_seconds()


def _table(rows: list[dict], attrs: dict) -> pd.DataFrame:
    import pandas as pd

    nav = pd.DataFrame(rows, columns=list(col.GNSS_NAV))
    nav = nav.astype({"sv": int, "week": int, "iode": int, "health": int})
    nav = nav.sort_values(["sv", "week", "toe"], kind="stable").reset_index(drop=True)
    nav.attrs.update(attrs)
    return nav


def _record(sv: int, epoch: dt.datetime, values: list[float]) -> dict:
    rec = dict(zip(_ORBIT_FIELDS, values, strict=False))
    rec["sv"] = sv
    week = int(rec["week"])
    rec["week"] = week
    rec["toc"] = _gps_seconds(epoch) - week * SECONDS_PER_WEEK
    return {k: rec.get(k, 0.0) for k in col.GNSS_NAV}


def _header(lines: list[str]) -> tuple[float, dict, int]:
    version, attrs = 2.0, {"kind": "ephemeris"}
    for i, line in enumerate(lines):
        label = line[60:].strip()
        if label == "RINEX VERSION / TYPE":
            version = float(line[:9])
        elif label == "ION ALPHA":
            attrs["iono_alpha"] = _numbers(line[:60])[:4]
        elif label == "ION BETA":
            attrs["iono_beta"] = _numbers(line[:60])[:4]
        elif label == "IONOSPHERIC CORR" and line[:4] in ("GPSA", "GPSB"):
            key = "iono_alpha" if line[:4] == "GPSA" else "iono_beta"
            attrs[key] = _numbers(line[5:60])[:4]
        elif label == "END OF HEADER":
            return version, attrs, i + 1
    raise ValueError("no END OF HEADER in the navigation file")


def _record_numbers(block: list[str], first: str) -> list[float]:
    values = _numbers(first)
    for line in block:
        found = _numbers(line)
        values += found + [0.0] * (4 - len(found))  # blank trailing fields read as zero
    return values


MAX_NAVIGATION_FILE_BYTES = 50_000_000  # a day of merged IGS broadcast files is about 1 MB


def read_rinex_nav(path: str | Path) -> pd.DataFrame:
    """Read the GPS records of a RINEX 2.x or 3.x navigation file into the navigation table.

    Other systems' records in a mixed RINEX 3 file are skipped.
    """
    lines = Path(path).read_text(errors="replace").splitlines()
    version, attrs, i = _header(lines)
    rows = []
    _rinex_records(path, lines, i, version, rows)
    if not rows:
        raise ValueError(f"{path}: no GPS navigation record")
    return _table(rows, attrs)


def _rinex_records(path: str | Path, lines: list[str], i: int, version: float,
                   rows: list) -> None:
    while i < len(lines):
        try:
            i = _rinex_record(lines, i, version, rows)
        except (ValueError, IndexError, TypeError, KeyError) as exc:
            raise ValueError(f"{path}:{i + 1}: not a readable RINEX navigation record ({exc})"
                             ) from None


def _rinex_record(lines: list[str], i: int, version: float, rows: list) -> int:
    """Read the record at line ``i`` into ``rows``; return the index of the next line."""
    line = lines[i]
    if not line.strip():
        return i + 1
    if version >= 3:
        system = line[0]
        n_more = _RINEX3_LINES.get(system, 7)
        if system == "G":
            parts = line[3:23].split()
            epoch = dt.datetime(*(int(p) for p in parts))
            values = _record_numbers(lines[i + 1:i + 1 + n_more], line[23:])
            rows.append(_record(int(line[1:3]), epoch, values))
    else:
        n_more = 7
        parts = line[:22].split()
        year = int(parts[1])
        year += 2000 if year < 80 else 1900
        second = float(parts[6])
        epoch = dt.datetime(year, int(parts[2]), int(parts[3]), int(parts[4]), int(parts[5]),
                            int(second), int(round((second % 1) * 1e6)))
        values = _record_numbers(lines[i + 1:i + 1 + n_more], line[22:])
        rows.append(_record(int(parts[0]), epoch, values))
    return i + 1 + n_more


_YUMA_KEYS = {
    "id": "sv", "health": "health", "eccentricity": "e", "time of applicability": "toe",
    "orbital inclination": "i0", "rate of right ascen": "omega_dot", "sqrt(a)": "sqrt_a",
    "right ascen at week": "omega0", "argument of perigee": "omega", "mean anom": "m0",
    "af0": "af0", "af1": "af1", "week": "week",
}


def read_yuma(path: str | Path, reference_week: int | None = None) -> pd.DataFrame:
    """Read a YUMA almanac into the navigation table (harmonic terms, af2 and T_GD zero).

    YUMA weeks are modulo 1024; the full week is the one nearest ``reference_week`` (default:
    the 2019-2038 era, weeks 2048-3071). YUMA angles are in radians and ``Orbital Inclination``
    is the full inclination.
    """
    rows, rec = [], {}
    for line in Path(path).read_text(errors="replace").splitlines():
        if line.startswith("****"):
            if rec:
                rows.append(rec)
            rec = {}
            continue
        if ":" not in line:
            continue
        label, value = line.split(":", 1)
        label = label.strip().lower()
        for prefix, key in _YUMA_KEYS.items():
            if label.startswith(prefix):
                rec[key] = _numbers(value)[0]
                break
    if rec:
        rows.append(rec)
    for n, rec in enumerate(rows, start=1):
        missing = sorted(set(_YUMA_KEYS.values()) - set(rec))
        if missing:
            raise ValueError(f"{path}: almanac record {n} (PRN {rec.get('sv', '?')}) lacks "
                             f"{', '.join(missing)}: truncated or not a YUMA almanac")
    if not rows:
        raise ValueError(f"{path}: no almanac record")
    ref = 2048 + 512 if reference_week is None else reference_week
    out = []
    for rec in rows:
        week = int(rec["week"]) % 1024
        week += 1024 * round((ref - week) / 1024)
        full = {k: 0.0 for k in col.GNSS_NAV}
        full.update(rec)
        full.update(week=week, toc=rec["toe"], sv=int(rec["sv"]), health=int(rec["health"]))
        out.append(full)
    return _table(out, {"kind": "almanac"})


def read_navigation(path: str | Path, reference_week: int | None = None) -> pd.DataFrame:
    """Read a RINEX navigation file or a YUMA almanac, recognised by its content.

    Raises
    ------
    ValueError
        Naming the file (and line) when it is neither, is truncated, or too large to be one.
    """
    if Path(path).stat().st_size > MAX_NAVIGATION_FILE_BYTES:
        raise ValueError(f"{path}: larger than {MAX_NAVIGATION_FILE_BYTES / 1e6:g} MB, not a "
                         "navigation file or almanac")
    head = Path(path).read_text(errors="replace")[:4000]
    if "RINEX VERSION / TYPE" in head:
        return read_rinex_nav(path)
    if "almanac for PRN" in head or "Time of Applicability" in head:
        return read_yuma(path, reference_week)
    raise ValueError(f"{path}: neither a RINEX navigation file nor a YUMA almanac")


__all__ = ["read_rinex_nav", "read_yuma", "read_navigation"]
