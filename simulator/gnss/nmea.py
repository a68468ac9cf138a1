"""NMEA 0183 output of the receiver: GGA, RMC, VTG, GSA and GSV sentences per fix epoch, from
the ``gnss_fix`` and ``gnss_raw`` streams.

Times are UTC (GPS time of the epoch minus the leap seconds); positions are the fix's WGS-84
latitude and longitude; GGA field 9 is the altitude above mean sea level (the geoid) and field
11 the geoid separation N (geoid above the ellipsoid), as NMEA 0183 defines them, so that the
ellipsoidal height is their sum. N is EGM96 at the fix's position (``simulator.geoid``, the
barometer's geoid); a real receiver uses its own built-in geoid, often a coarser grid, so its N
may differ by a metre or two. Epochs without a fix give GGA quality 0, RMC status V and empty
position fields, as receivers do; so does an epoch flagged as a fix whose position is not finite.

Public functions
----------------
nmea_checksum, nmea_sentences, write_nmea.

References
----------
NMEA 0183 version 4.10 (National Marine Electronics Association, 2012), sentences GGA, RMC,
VTG, GSA, GSV; checksum: XOR of every character between '$' and '*'.
"""

from __future__ import annotations

import datetime as dt
from functools import reduce
from pathlib import Path

import numpy as np
import pandas as pd

from simulator.geoid import geoid_undulation_m
from simulator.gnss.fix import primary_rows
from simulator.timebase import gps_to_utc

KNOTS_PER_M_S = 3600.0 / 1852.0  # international nautical mile, 1852 m
_SV_PER_GSV = 4


def nmea_checksum(body: str) -> str:
    """Two hex digits: the XOR of the characters of the sentence between '$' and '*'."""
    return f"{reduce(lambda a, ch: a ^ ord(ch), body, 0):02X}"


def _sentence(*fields: str) -> str:
    body = ",".join(fields)
    return f"${body}*{nmea_checksum(body)}"


def _latlon(value_deg: float, hemispheres: str, degree_digits: int) -> tuple[str, str]:
    if not np.isfinite(value_deg):
        return "", ""
    hemi = hemispheres[0] if value_deg >= 0 else hemispheres[1]
    a = abs(value_deg)
    degrees = int(a)
    minutes = (a - degrees) * 60.0
    if round(minutes, 6) >= 60.0:  # rounding carried into the next degree
        degrees, minutes = degrees + 1, 0.0
    return f"{degrees:0{degree_digits}d}{minutes:09.6f}", hemi


def _num(value: float, digits: int) -> str:
    return f"{value:.{digits}f}" if np.isfinite(value) else ""


def _count(value: float, digits: int = 2) -> str:
    """A whole-number field, zero-padded; empty when the value is missing."""
    return f"{int(round(value)):0{digits}d}" if np.isfinite(value) else ""


def _epoch_sentences(stamp: dt.datetime, fix: dict, sats: pd.DataFrame) -> list[str]:
    hms = stamp.strftime("%H%M%S") + f".{stamp.microsecond // 10000:02d}"
    # a fix flag without a finite position (a hand-edited or faulted stream) is no fix
    has_fix = bool(np.isfinite(fix["fix"]) and fix["fix"] > 0
                   and np.isfinite(fix["lat"]) and np.isfinite(fix["lon"])
                   and np.isfinite(fix["alt"]))
    lat, ns = _latlon(fix["lat"] if has_fix else np.nan, "NS", 2)
    lon, ew = _latlon(fix["lon"] if has_fix else np.nan, "EW", 3)
    knots = fix["speed"] * KNOTS_PER_M_S
    course = np.degrees(fix["course"])
    hdop, vdop = fix["hdop"], fix["vdop"]
    pdop = np.hypot(hdop, vdop)
    mode = "A" if has_fix else "N"
    out = [
        _sentence("GPGGA", hms, lat, ns, lon, ew, "1" if has_fix else "0",
                  _count(fix["num_sats"]), _num(hdop, 1),
                  _num(fix["alt"] - fix["separation"], 2), "M", _num(fix["separation"], 2),
                  "M" if has_fix else "", "", ""),
        _sentence("GPRMC", hms, "A" if has_fix else "V", lat, ns, lon, ew,
                  _num(knots, 3), _num(course, 2), stamp.strftime("%d%m%y"), "", "", mode),
        _sentence("GPVTG", _num(course, 2), "T", "", "M", _num(knots, 3), "N",
                  _num(fix["speed"] * 3.6, 3), "K", mode),
    ]
    # GSA lists the satellites the fix used: not the unhealthy ones GSV shows in view
    healthy = sats[sats["health"] == 0] if "health" in sats else sats
    used = [f"{int(sv):02d}" for sv in healthy["sv"]][:12] if has_fix else []
    out.append(_sentence("GPGSA", "A", "3" if has_fix and fix["fix"] > 1 else "2" if has_fix
                         else "1",
                         *(used + [""] * (12 - len(used))), _num(pdop, 1), _num(hdop, 1),
                         _num(vdop, 1)))
    n_msg = max(1, -(-len(sats) // _SV_PER_GSV))
    rows = list(sats[["sv", "elevation", "azimuth", "cn0"]].itertuples(index=False))
    for k in range(n_msg):
        fields = ["GPGSV", str(n_msg), str(k + 1), f"{len(sats):02d}"]
        for sv, el, az, cn0 in rows[k * _SV_PER_GSV:(k + 1) * _SV_PER_GSV]:
            fields += [f"{int(sv):02d}", _count(np.degrees(el)),
                       _count(np.degrees(az) % 360, 3), _count(cn0)]
        out.append(_sentence(*fields))
    return out


def nmea_sentences(fix: pd.DataFrame, raw: pd.DataFrame, gps_week: int,
                   gps_tow_s: float) -> list[str]:
    """The sentences of every fix epoch, in order (GGA, RMC, VTG, GSA, then the GSV group).

    Parameters
    ----------
    fix, raw : pandas.DataFrame
        The ``gnss_fix`` and ``gnss_raw`` streams (``raw`` may be empty: GSV then lists none).
    gps_week, gps_tow_s : GPS time of ``t = 0``.
    """
    raw = primary_rows(raw)  # one row per satellite
    by_epoch = dict(tuple(raw.groupby("t"))) if len(raw) else {}
    empty = pd.DataFrame(columns=["sv", "elevation", "azimuth", "cn0"])
    lines: list[str] = []
    fix = fix.assign(separation=np.where(fix["fix"] > 0, geoid_undulation_m(fix["lat"], fix["lon"]),
                                         np.nan))
    for rec in fix.to_dict("records"):
        stamp = gps_to_utc(gps_week, gps_tow_s + float(rec["t"]))
        lines += _epoch_sentences(stamp, rec, by_epoch.get(rec["t"], empty))
    return lines


def write_nmea(path: str | Path, fix: pd.DataFrame, raw: pd.DataFrame, gps_week: int,
               gps_tow_s: float) -> Path:
    """Write ``nmea_sentences`` to a text file, one sentence per line (CR LF ends)."""
    path = Path(path)
    text = "\r\n".join(nmea_sentences(fix, raw, gps_week, gps_tow_s)) + "\r\n"
    path.write_bytes(text.encode("ascii"))
    return path
