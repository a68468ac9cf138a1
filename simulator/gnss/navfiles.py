"""Navigation-file readers: RINEX 2 and 3 navigation messages of GPS, QZSS, Galileo, BeiDou and
GLONASS (mixed files included) and YUMA almanacs, each turned into the one navigation table
(columns ``simulator.columns.GNSS_NAV``, one row per broadcast record).

What the columns hold per system (``system``, the RINEX letter):

- every system: ``sv`` (PRN, or GLONASS slot), ``week``, ``toe``, ``toc`` (week and seconds of
  week in the system's own time: GPST for G/J, GST for E (week continuous with GPS, as RINEX
  writes it), BDT week and seconds for C; GLONASS has no week, so its t_b is written as GPS week
  and seconds of week), ``health`` (0 = healthy), ``iode`` (IODE, Galileo IODnav, BeiDou AODE,
  GLONASS the index of t_b in its day, t_b / 900 s);
- Keplerian systems: the IS-GPS-200 parameters (``sqrt_a`` ... ``cis``, ``af0`` ... ``af2``);
  ``tgd`` is GPS/QZSS T_GD, Galileo BGD(E5a, E1), BeiDou TGD1 (B1I); ``tgd2`` is Galileo
  BGD(E5b, E1), BeiDou TGD2 (B2I); ``data_source`` is Galileo's (bit 0 I/NAV E1-B, bit 1
  F/NAV E5a-I, bit 2 I/NAV E5b-I, bits 8/9: the clock is for E1,E5a / E1,E5b);
- GLONASS: ``glo_x ... glo_az`` the PZ-90 state vector at t_b (m, m/s, m/s^2: the lunisolar
  accelerations), ``glo_channel`` the FDMA frequency number k, ``af0`` = -tau_n and ``af1`` =
  +gamma_n (RINEX's SV clock bias and relative frequency bias; ``toc`` = ``toe`` = t_b), the
  Keplerian columns zero.

Galileo files carry I/NAV and F/NAV records of the same ephemeris: an F/NAV record is kept only
where no I/NAV record has its toe (a receiver on E1 decodes I/NAV). Exact repeats are dropped.
NavIC (``I``) and SBAS (``S``) records are skipped; their counts are in ``attrs["skipped"]``.

The table's ``attrs``: ``kind`` (``ephemeris`` or ``almanac``); the header's ionosphere
coefficients: ``iono_alpha`` / ``iono_beta`` (GPS Klobuchar, s, s/sc, ...; IS-GPS-200
20.3.3.5.1.7), ``bds_alpha`` / ``bds_beta`` (BeiDou Klobuchar, BDS SIS ICD 5.2.4.7),
``qzss_alpha`` / ``qzss_beta``, ``nequick_ai`` (Galileo NeQuick ai0, ai1, ai2: sfu, sfu/deg,
sfu/deg^2; OS SIS ICD 5.1.6); ``time_corrections`` (``TIME SYSTEM CORR`` label -> (a0, a1,
t_ref, week), see ``simulator.gnss.timesystems``); ``leap_seconds`` (GPS - UTC, s); ``skipped``.

RINEX 3 records are read in their fixed 19-character fields (a blank field reads as zero);
RINEX 2 records with a regular expression, so files that separate their fields by blanks
instead of keeping the RINEX 2 columns (e.g. Stanford's ``sugl0010.20n``) read as well as
strict ones. RINEX 4 files are refused with a message.

Public functions
----------------
read_rinex_nav, read_yuma, read_navigation.

References
----------
RINEX 2.11 (Gurtner & Estey, IGS/RTCM-SC104, 2007), Tables A4 (GPS) and A11 (GLONASS); RINEX 3.04
(IGS/RTCM-SC104, 2018), Tables A5 (header), A6 (GPS), A8 (Galileo), A10 (GLONASS), A12 (QZSS),
A14 (BDS); ICD-GPS-240 / YUMA almanac format as published by the US Coast Guard Navigation Center.
"""

from __future__ import annotations

import datetime as dt
import re
from pathlib import Path
from typing import TYPE_CHECKING

from simulator import columns as col
from simulator.gnss.timesystems import GLONASST_MINUS_UTC_S
from simulator.timebase import GPS_EPOCH, SECONDS_PER_WEEK, leap_seconds

if TYPE_CHECKING:
    import pandas as pd

_NUMBER = re.compile(r"[+-]?(?:\d+\.\d*|\.\d+|\d+)(?:[DdEe][+-]?\d+)?")
_BDT_EPOCH = dt.datetime(2006, 1, 1)  # BDT week 0, 00:00:00 BDT

# the 29 numbers of a Keplerian record after the clock epoch, in file order (RINEX 2.11 Table
# A4, RINEX 3.04 Table A6); Galileo and BeiDou put other quantities at some places (_RENAMED)
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
_RENAMED = {"E": {"l2_codes": "data_source", "iodc": "tgd2"},
            "C": {"iodc": "tgd2"}}
# the numbers of a GLONASS record (RINEX 2.11 Table A11, RINEX 3.04 Table A10), km units
_GLONASS_FIELDS = (
    "minus_tau_n", "gamma_n", "frame_time",
    "glo_x", "glo_vx", "glo_ax", "health",
    "glo_y", "glo_vy", "glo_ay", "glo_channel",
    "glo_z", "glo_vz", "glo_az", "age",
)
KEPLERIAN_SYSTEMS = ("G", "J", "E", "C")
READ_SYSTEMS = KEPLERIAN_SYSTEMS + ("R",)
# broadcast-orbit lines per record of each RINEX 3 system (data lines after the first one)
_RINEX3_LINES = {"G": 7, "E": 7, "C": 7, "J": 7, "I": 7, "R": 3, "S": 3}
_RINEX2_TYPES = {"N": "G", "G": "R"}  # RINEX 2 file type -> system
_INT_COLUMNS = ("sv", "week", "iode", "health", "data_source", "glo_channel")
_HEADER_IONO = {"GPSA": "iono_alpha", "GPSB": "iono_beta", "BDSA": "bds_alpha",
                "BDSB": "bds_beta", "QZSA": "qzss_alpha", "QZSB": "qzss_beta", "GAL ": "nequick_ai"}
F_NAV_BIT = 2  # Galileo data source: F/NAV E5a-I


def _numbers(text: str) -> list[float]:
    return [float(x.replace("D", "E").replace("d", "e")) for x in _NUMBER.findall(text)]


def _fields(text: str, first: int, count: int) -> list[float]:
    """``count`` fixed 19-character numeric fields from column ``first`` (blank = 0)."""
    out = []
    for k in range(count):
        field = text[first + 19 * k: first + 19 * (k + 1)].strip()
        out.append(float(field.replace("D", "E").replace("d", "e")) if field else 0.0)
    return out


def _gps_seconds(epoch: dt.datetime) -> float:
    return (epoch - GPS_EPOCH).total_seconds()


def _table(rows: list[dict], attrs: dict) -> pd.DataFrame:
    import pandas as pd

    nav = pd.DataFrame(rows, columns=list(col.GNSS_NAV))
    nav = nav.astype({c: int for c in _INT_COLUMNS})
    fnav = (nav["system"] == "E") & ((nav["data_source"] & F_NAV_BIT) != 0)
    nav = nav.assign(_fnav=fnav).sort_values(["system", "sv", "week", "toe", "_fnav"],
                                             kind="stable")
    nav = nav.drop_duplicates(["system", "sv", "week", "toe"]).drop(columns="_fnav")
    nav = nav.reset_index(drop=True)
    nav.attrs.update(attrs)
    return nav


def _blank(system: str, sv: int) -> dict:
    rec = {k: 0.0 for k in col.GNSS_NAV}
    rec.update(system=system, sv=sv)
    return rec


def _kepler_record(system: str, sv: int, epoch: dt.datetime, values: list[float]) -> dict:
    """One Keplerian record; ``epoch`` is the clock epoch in the system's own time."""
    names = [_RENAMED.get(system, {}).get(k, k) for k in _ORBIT_FIELDS]
    rec = _blank(system, sv)
    rec.update({k: v for k, v in zip(names, values, strict=False) if k in rec})
    week = int(rec["week"])
    if system == "C":
        since_week = (epoch - _BDT_EPOCH).total_seconds() - week * SECONDS_PER_WEEK
    else:
        since_week = _gps_seconds(epoch) - week * SECONDS_PER_WEEK
    rec.update(week=week, toc=since_week)
    return rec


def _glonass_record(sv: int, epoch_utc: dt.datetime, values: list[float], leap_s: int) -> dict:
    """One GLONASS record; ``epoch_utc`` is t_b in UTC (RINEX), written as GPS week and tow."""
    got = dict(zip(_GLONASS_FIELDS, values, strict=False))
    rec = _blank("R", sv)
    t_gps = _gps_seconds(epoch_utc) + leap_s
    week = int(t_gps // SECONDS_PER_WEEK)
    rec.update(week=week, toe=t_gps - week * SECONDS_PER_WEEK)
    rec["toc"] = rec["toe"]
    rec.update(af0=got["minus_tau_n"], af1=got["gamma_n"], health=got["health"],
               glo_channel=got["glo_channel"])
    for key in ("glo_x", "glo_y", "glo_z", "glo_vx", "glo_vy", "glo_vz", "glo_ax", "glo_ay",
                "glo_az"):
        rec[key] = got[key] * 1e3  # km -> m
    moscow = epoch_utc + dt.timedelta(seconds=GLONASST_MINUS_UTC_S)
    rec["iode"] = (moscow.hour * 3600 + moscow.minute * 60 + moscow.second) // 900
    return rec


def _header(lines: list[str]) -> tuple[float, str, dict, int]:
    """Version, file system letter (RINEX 3: M for mixed), attrs and the first record line."""
    version, system = 2.0, "G"
    attrs: dict = {"kind": "ephemeris", "time_corrections": {}, "skipped": {}}
    for i, line in enumerate(lines):
        label = line[60:].strip()
        if label == "RINEX VERSION / TYPE":
            version = float(line[:9])
            code = line[20] if len(line) > 20 else "N"
            system = _RINEX2_TYPES.get(code, code) if version < 3 else (line[40:41] or "G")
        elif label == "ION ALPHA":
            attrs["iono_alpha"] = _numbers(line[:60])[:4]
        elif label == "ION BETA":
            attrs["iono_beta"] = _numbers(line[:60])[:4]
        elif label == "IONOSPHERIC CORR" and line[:4] in _HEADER_IONO:
            attrs[_HEADER_IONO[line[:4]]] = _numbers(line[5:60])[:4 if line[:4] != "GAL " else 3]
        elif label == "TIME SYSTEM CORR":
            a0, a1 = (float(line[a:b].replace("D", "E") or 0.0) for a, b in ((5, 22), (22, 38)))
            attrs["time_corrections"][line[:4]] = (a0, a1, float(line[38:45] or 0.0),
                                                   int(line[45:50] or 0))
        elif label == "LEAP SECONDS":
            attrs["leap_seconds"] = int(line[:6])
        elif label == "END OF HEADER":
            return version, system, attrs, i + 1
    raise ValueError("no END OF HEADER in the navigation file")


MAX_NAVIGATION_FILE_BYTES = 50_000_000  # a day of merged multi-GNSS broadcast files is ~5 MB


def read_rinex_nav(path: str | Path) -> pd.DataFrame:
    """Read the GPS, QZSS, Galileo, BeiDou and GLONASS records of a RINEX 2.x or 3.x
    navigation file (single-system or mixed) into the navigation table (module docstring)."""
    lines = Path(path).read_text(errors="replace").splitlines()
    try:
        version, system, attrs, i = _header(lines)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None
    if version >= 4:
        raise ValueError(f"{path}: RINEX {version:g} navigation files are not read (RINEX 2 "
                         "and 3 are)")
    rows: list[dict] = []
    while i < len(lines):
        try:
            i = _rinex_record(lines, i, version, system, attrs, rows)
        except (ValueError, IndexError, TypeError, KeyError) as exc:
            raise ValueError(f"{path}:{i + 1}: not a readable RINEX navigation record ({exc})"
                             ) from None
    if not rows:
        raise ValueError(f"{path}: no GPS, QZSS, Galileo, BeiDou or GLONASS navigation record")
    return _table(rows, attrs)


def _leap(attrs: dict, epoch_utc: dt.datetime) -> int:
    return attrs.get("leap_seconds") or leap_seconds(epoch_utc)


def _rinex_record(lines: list[str], i: int, version: float, file_system: str, attrs: dict,
                  rows: list) -> int:
    """Read the record at line ``i`` into ``rows``; return the index of the next line."""
    line = lines[i]
    if not line.strip():
        return i + 1
    if version >= 3:
        system = line[0]
        n_more = _RINEX3_LINES.get(system, 7)
        if system == "R" and version >= 3.05:
            n_more = 4  # the status-flags line of RINEX 3.05
        if system not in READ_SYSTEMS:
            attrs["skipped"][system] = attrs["skipped"].get(system, 0) + 1
            return i + 1 + n_more
        epoch = dt.datetime(*(int(p) for p in line[3:23].split()))
        values = _fields(line, 23, 3)
        for more in lines[i + 1:i + 1 + n_more]:
            values += _fields(more, 4, 4)
        sv = int(line[1:3])
    else:
        system = file_system
        n_more = 7 if system != "R" else 3
        parts = line[:22].split()
        year = int(parts[1])
        year += 2000 if year < 80 else 1900
        second = float(parts[6])
        epoch = dt.datetime(year, int(parts[2]), int(parts[3]), int(parts[4]), int(parts[5]),
                            int(second), int(round((second % 1) * 1e6)))
        values = _numbers(line[22:])
        for more in lines[i + 1:i + 1 + n_more]:
            found = _numbers(more)
            values += found + [0.0] * (4 - len(found))  # blank trailing fields read as zero
        sv = int(parts[0])
    if i + 1 + n_more > len(lines):
        raise ValueError(f"the record of {system}{sv:02d} ends after {len(lines) - i} of its "
                         f"{n_more + 1} lines")
    if version < 3 and len(_numbers(line[22:])) < 3:
        raise ValueError("its first line does not hold the clock's three numbers")
    if system == "R":
        rows.append(_glonass_record(sv, epoch, values, _leap(attrs, epoch)))
    else:
        rows.append(_kepler_record(system, sv, epoch, values))
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
        full = _blank("G", int(rec["sv"]))
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
