"""RINEX 3.04 writers: an observation file (per signal: pseudorange, carrier phase with its
loss-of-lock indicator, Doppler, C/N0) from the ``gnss_raw`` stream and a GPS navigation file
from the ``gnss_nav`` stream.

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

from simulator.gnss.constants import C_M_S, SECONDS_PER_WEEK
from simulator.timebase import GPS_EPOCH, gps_to_utc, leap_seconds

PROGRAM = "landnav"
_SYSTEM_NAMES = {"G": "GPS", "E": "GALILEO", "C": "BEIDOU", "R": "GLONASS", "J": "QZSS"}
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


def _obs_types(raw: pd.DataFrame) -> dict[str, list[tuple[str, str]]]:
    """Per system (in order of appearance): its observation types as (RINEX code, column)
    pairs, C L D S for each of its signals in the receiver's order (L only with carrier
    phase)."""
    kinds = [("C", "pseudorange"), ("L", "carrier_phase"), ("D", "doppler"), ("S", "cn0")]
    out: dict[str, list[tuple[str, str]]] = {}
    for system in pd.unique(raw["system"]):
        signals = pd.unique(raw.loc[raw["system"] == system, "signal"])
        out[str(system)] = [(f"{k}{sig}", column) for sig in signals for k, column in kinds
                            if column in raw]
    return out


def _type_lines(system: str, codes: list[str]) -> list[str]:
    """SYS / # / OBS TYPES: A1, 2X, I3, 13 (1X, A3), continued on lines of 6X + 13 types."""
    lines = []
    for i in range(0, len(codes), 13):
        head = f"{system}  {len(codes):3d}" if i == 0 else " " * 6
        lines.append(_label(head + "".join(f" {c}" for c in codes[i:i + 13]),
                            "SYS / # / OBS TYPES"))
    return lines


def _cells(values: np.ndarray, lli: np.ndarray | None, ssi: np.ndarray) -> np.ndarray:
    """F14.3 observation, LLI digit (blank for 0) and signal strength digit; 16 blanks where
    the value is missing."""
    text = np.char.mod("%14.3f", np.nan_to_num(values))
    flag = np.full(len(values), " ") if lli is None else np.where(
        lli > 0, np.char.mod("%d", np.nan_to_num(lli).astype(int) & 3), " ")
    cell = np.char.add(np.char.add(text, flag), np.char.mod("%d", ssi))
    return np.where(np.isnan(values), " " * 16, cell)


def write_rinex_obs(path: str | Path, raw: pd.DataFrame, gps_week: int, gps_tow_s: float,
                    approx_xyz_m: np.ndarray, marker: str = "LANDNAV",
                    receiver_clock_m: pd.Series | None = None) -> Path:
    """Write the raw measurements as a RINEX 3.04 observation file.

    Every system's signals get the observation types C (pseudorange), L (carrier phase, when
    the stream has it, with the loss-of-lock indicator), D (Doppler) and S (C/N0, dB-Hz), e.g.
    ``C1C L1C D1C S1C C2W L2W D2W S2W``; each value carries the signal strength indicator.

    Parameters
    ----------
    raw : pandas.DataFrame
        The ``gnss_raw`` stream (``t``, ``sv``, ``pseudorange``, ``doppler``, ``cn0``; with
        ``system``, ``signal``, ``carrier_phase`` and ``lli`` where it has them: without,
        GPS L1 C/A).
    gps_week, gps_tow_s : GPS time of ``t = 0``.
    approx_xyz_m : array_like, shape (3,)
        The APPROX POSITION XYZ header value (e.g. the first fix), m.
    receiver_clock_m : pandas.Series, optional
        The receiver clock error c dt_r (m) at each epoch ``t`` (index). The epochs are then
        written as RINEX has them, the receiver's time tags t + dt_r: a receiver stamps its
        measurements with its own clock, and GNSS software takes the transmit time as the tag
        minus pseudorange / c, which is the true one only so (with true-time tags two
        receivers' clock errors would not cancel in double differences: 1e-4 s moves a range
        by up to 8 cm). Without it, the true times t.
    """
    path = Path(path)
    if "signal" not in raw:
        raw = raw.assign(system="G", signal="1C")
    tag_s = (pd.Series(0.0, index=np.unique(raw["t"].to_numpy())) if receiver_clock_m is None
             else receiver_clock_m / C_M_S)
    types = _obs_types(raw)
    raw = raw.sort_values(["t", "system", "sv"], kind="stable")
    first = (_gps_datetime(gps_week, gps_tow_s + float(raw["t"].iloc[0])
                           + float(tag_s.get(raw["t"].iloc[0], 0.0)))
             if len(raw) else _gps_datetime(gps_week, gps_tow_s))
    x, y, z = (float(v) for v in approx_xyz_m)
    times = np.unique(raw["t"].to_numpy())
    letters = "".join(types) if len(types) > 1 else next(iter(types), "G")
    kind = "M (MIXED)" if len(types) > 1 else f"{letters} ({_SYSTEM_NAMES.get(letters, '')})"
    lines = [
        _label(f"     3.04           OBSERVATION DATA    {kind}", "RINEX VERSION / TYPE"),
        _label(f"{PROGRAM:<20}{PROGRAM:<20}{_stamp()}", "PGM / RUN BY / DATE"),
        _label(marker, "MARKER NAME"),
        _label("NON_PHYSICAL", "MARKER TYPE"),
        _label(f"{PROGRAM:<20}{PROGRAM:<40}", "OBSERVER / AGENCY"),
        _label(f"{'0':<20}{'LANDNAV SIMULATED':<20}{'1':<20}", "REC # / TYPE / VERS"),
        _label(f"{'0':<20}{'LANDNAV SIMULATED':<20}", "ANT # / TYPE"),
        _label(f"{x:14.4f}{y:14.4f}{z:14.4f}", "APPROX POSITION XYZ"),
        _label(f"{0.0:14.4f}{0.0:14.4f}{0.0:14.4f}", "ANTENNA: DELTA H/E/N"),
    ]
    for system, pairs in types.items():
        lines += _type_lines(system, [code for code, _ in pairs])
    lines.append(_label("DBHZ", "SIGNAL STRENGTH UNIT"))
    if len(times) > 1:
        lines.append(_label(f"{float(np.min(np.diff(times))):10.3f}", "INTERVAL"))
    lines += [
        _label(f"{first.year:6d}{first.month:6d}{first.day:6d}{first.hour:6d}{first.minute:6d}"
               f"{first.second + first.microsecond / 1e6:13.7f}     GPS", "TIME OF FIRST OBS"),
    ]
    for system, pairs in types.items():  # no phase corrections applied (RINEX 3.04 A2)
        lines += [_label(f"{system} {code} {0.0:8.5f}", "SYS / PHASE SHIFT")
                  for code, column in pairs if column == "carrier_phase"]
    lines += [
        _label(f"{leap_seconds(gps_to_utc(gps_week, gps_tow_s)):6d}", "LEAP SECONDS"),
        _label("", "END OF HEADER"),
    ]
    # one text line per satellite and epoch: each system's signals side by side
    records = []
    for system, pairs in types.items():  # one pass per system, vectorised over its rows
        rows = raw[raw["system"] == system]
        values = [c for c in ("pseudorange", "carrier_phase", "doppler", "cn0", "lli")
                  if c in rows]
        wide = rows.set_index(["t", "sv", "signal"])[values].unstack("signal")
        line = np.char.mod(f"{system}%02d", wide.index.get_level_values("sv").to_numpy())
        for code, column in pairs:
            sig = code[1:]
            values = wide[(column, sig)].to_numpy(dtype=float)
            cn0 = wide[("cn0", sig)].to_numpy(dtype=float)
            ssi = signal_strength_indicator(np.nan_to_num(cn0, nan=0.0))
            lli = wide[("lli", sig)].to_numpy(dtype=float) if column == "carrier_phase" \
                else None
            line = np.char.add(line, _cells(values, lli, ssi))
        records.append(pd.DataFrame({"t": wide.index.get_level_values("t").to_numpy(),
                                     "system": system, "line": np.char.rstrip(line)}))
    table = pd.concat(records, ignore_index=True).sort_values(["t", "system"], kind="stable")
    for t, epoch in table.groupby("t", sort=True):  # one pass per epoch: its header line
        exact = gps_tow_s + float(t) + float(tag_s.get(t, 0.0))
        stamp = _gps_datetime(gps_week, np.floor(exact))  # the fraction kept to 0.1 us
        seconds = stamp.second + (exact - np.floor(exact))
        lines.append(f"> {stamp.year:4d} {stamp.month:02d} {stamp.day:02d} {stamp.hour:02d} "
                     f"{stamp.minute:02d}{seconds:11.7f}  0{len(epoch):3d}")
        lines += epoch["line"].tolist()
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
