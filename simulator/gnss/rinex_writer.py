"""RINEX 3.04 writers: an observation file (per signal: pseudorange, carrier phase with its
loss-of-lock indicator, Doppler, C/N0) from the ``gnss_raw`` stream and a navigation file of
every system (GPS, Galileo, BeiDou, GLONASS, QZSS; mixed) from the ``gnss_nav`` stream.

Observation epochs are written in GPS time (the dataset's ``t`` plus the GPS time of ``t = 0``,
plus the receiver's clock error when given); navigation records in each system's time (GPST,
GST, BDT, QZSST; GLONASS in UTC); values are
rounded to the formats' resolution (F14.3 for observations, D19.12 for navigation parameters).

Public functions
----------------
write_rinex_obs, write_rinex_nav, signal_strength_indicator.

References
----------
RINEX 3.04 (IGS/RTCM-SC104, 2018): Table A2 (observation header), A3 (observation data record),
A5 (navigation header), A6 (GPS), A8 (Galileo), A10 (GLONASS), A12 (QZSS) and A14 (BeiDou)
navigation data records; section 5.7 (signal strength
indicator from C/N0).
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np
import pandas as pd

from simulator.gnss.constants import C_M_S, SECONDS_PER_WEEK
from simulator.gnss.timesystems import BDS_WEEK_OFFSET
from simulator.timebase import GPS_EPOCH, gps_to_utc, leap_seconds

PROGRAM = "landnav"
_SYSTEM_NAMES = {"G": "GPS", "E": "GALILEO", "C": "BEIDOU", "R": "GLONASS", "J": "QZSS"}
# the numbers of each system's Keplerian record after the clock epoch, a tuple per line
# (RINEX 3.04 Tables A6 GPS, A8 Galileo, A12 QZSS, A14 BeiDou); a field the navigation table
# does not hold is written as the constant in its place
_ORBIT_LINES = (
    ("iode", "crs", "delta_n", "m0"),
    ("cuc", "e", "cus", "sqrt_a"),
    ("toe", "cic", "omega0", "cis"),
    ("i0", "crc", "omega", "omega_dot"),
)
_LAST_LINES = {
    # IDOT, L2 codes, week, L2 P flag; URA (m), health, T_GD, IODC (= IODE); transmission
    # time (taken as toe), fit interval (h; QZSS: the flag, 0 = 2 h)
    "G": (("idot", 0.0, "week", 0.0), (2.0, "health", "tgd", "iode"), ("toe", 4.0)),
    "J": (("idot", 0.0, "week", 0.0), (2.0, "health", "tgd", "iode"), ("toe", 0.0)),
    # IDOT, data sources, GAL week, spare; SISA (m), health, BGD E5a/E1, BGD E5b/E1;
    # transmission time
    "E": (("idot", "data_source", "week", 0.0), (3.12, "health", "tgd", "tgd2"), ("toe",)),
    # IDOT, spare, BDT week, spare; URA (m), SatH1, TGD1, TGD2; transmission time, AODC
    "C": (("idot", 0.0, "week", 0.0), (2.0, "health", "tgd", "tgd2"), ("toe", "iode")),
}
NAV_SYSTEMS = ("G", "E", "C", "R", "J")  # the order of the records in a written file


def _label(text: str, label: str) -> str:
    return f"{text:<60.60}{label:<20}"


def _d19(value: float) -> str:
    return f"{value:19.12E}".replace("E", "D")


def _d(value: float, width: int, digits: int) -> str:
    """A Dw.d field (TIME SYSTEM CORR: a0 D17.10, a1 D16.9)."""
    return f"{value:{width}.{digits}E}".replace("E", "D")


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


def _epoch(stamp: dt.datetime) -> str:
    return (f"{stamp.year:4d} {stamp.month:02d} {stamp.day:02d} {stamp.hour:02d} "
            f"{stamp.minute:02d} {stamp.second:02d}")


def _kepler_lines(rec: dict) -> list[str]:
    """One GPS, Galileo, BeiDou or QZSS record: the clock epoch in the system's own time (BDT
    for BeiDou, whose week 0 began with GPS week 1356, so that its week and seconds give the
    calendar reading as GPS ones do) and the broadcast orbit lines."""
    system = rec["system"]
    week = int(rec["week"]) + (BDS_WEEK_OFFSET if system == "C" else 0)
    head = f"{system}{int(rec['sv']):02d} {_epoch(_gps_datetime(week, float(rec['toc'])))}"
    groups = [[rec[k] if isinstance(k, str) else k for k in line]
              for line in (*_ORBIT_LINES, *_LAST_LINES[system])]
    clock = (rec["af0"], rec["af1"], rec["af2"])
    return [head + "".join(_d19(v) for v in clock)] + [
        "    " + "".join(_d19(v) for v in group) for group in groups]


def _glonass_lines(rec: dict, leap_s: int) -> list[str]:
    """One GLONASS record (RINEX 3.04 Table A10): t_b in UTC, -tau_n, +gamma_n, the message
    frame time (taken as t_b, seconds of the UTC week), then X, Y, Z in km with velocity,
    lunisolar acceleration and health, frequency channel, age (0)."""
    utc_s = int(rec["week"]) * SECONDS_PER_WEEK + float(rec["toe"]) - leap_s
    stamp = GPS_EPOCH + dt.timedelta(seconds=utc_s)
    frame = utc_s - np.floor(utc_s / SECONDS_PER_WEEK) * SECONDS_PER_WEEK
    km = {k: rec[k] / 1e3 for k in ("glo_x", "glo_y", "glo_z", "glo_vx", "glo_vy", "glo_vz",
                                    "glo_ax", "glo_ay", "glo_az")}
    groups = ((km["glo_x"], km["glo_vx"], km["glo_ax"], rec["health"]),
              (km["glo_y"], km["glo_vy"], km["glo_ay"], rec["glo_channel"]),
              (km["glo_z"], km["glo_vz"], km["glo_az"], 0.0))
    return [f"R{int(rec['sv']):02d} {_epoch(stamp)}"
            + "".join(_d19(v) for v in (rec["af0"], rec["af1"], frame))] + [
        "    " + "".join(_d19(v) for v in group) for group in groups]


def write_rinex_nav(path: str | Path, nav: pd.DataFrame, leap_s: int,
                    iono_alpha: list[float] | None = None,
                    iono_beta: list[float] | None = None,
                    time_corrections: dict | None = None) -> Path:
    """Write the navigation table as a RINEX 3.04 navigation file: every GPS, Galileo,
    BeiDou, QZSS and GLONASS record as it is (a mixed file, ``M``, when there are several
    systems), with the GPS ionosphere coefficients in IONOSPHERIC CORR and the system time
    offsets in TIME SYSTEM CORR when given.

    Parameters
    ----------
    nav : pandas.DataFrame
        The navigation table (``simulator.gnss.navfiles``; without ``system``, GPS records).
    leap_s : int
        GPS - UTC (s): the LEAP SECONDS line and the UTC epochs of the GLONASS records.
    time_corrections : dict, optional
        ``TIME SYSTEM CORR`` label -> (a0 s, a1 s/s, reference seconds of week, week), as the
        reader's ``attrs["time_corrections"]``.

    A record's epoch is written to the whole second (RINEX: I2 seconds); the reader of this
    module's files (``read_rinex_nav``) gives back every value to the D19.12 resolution.
    """
    path = Path(path)
    if "system" not in nav.columns:
        nav = nav.assign(system="G")
    nav = nav[nav["system"].isin(NAV_SYSTEMS)]
    present = [s for s in NAV_SYSTEMS if (nav["system"] == s).any()]
    kind = (f"{present[0]}: {_SYSTEM_NAMES[present[0]]}" if len(present) == 1
            else "M: MIXED")
    lines = [
        _label(f"     3.04           N: GNSS NAV DATA    {kind}", "RINEX VERSION / TYPE"),
        _label(f"{PROGRAM:<20}{PROGRAM:<20}{_stamp()}", "PGM / RUN BY / DATE"),
    ]
    for name, coeffs in (("GPSA", iono_alpha), ("GPSB", iono_beta)):
        if coeffs is not None:
            text = name + " " + "".join(f"{c:12.4E}".replace("E", "D") for c in coeffs)
            lines.append(_label(text, "IONOSPHERIC CORR"))
    for label, (a0, a1, t_ref, week) in (time_corrections or {}).items():
        text = f"{label:<4} {_d(a0, 17, 10)}{_d(a1, 16, 9)} {int(t_ref):6d} {int(week):4d}"
        lines.append(_label(text, "TIME SYSTEM CORR"))
    lines += [_label(f"{leap_s:6d}", "LEAP SECONDS"), _label("", "END OF HEADER")]
    order = {s: i for i, s in enumerate(NAV_SYSTEMS)}
    nav = nav.assign(_order=nav["system"].map(order)).sort_values(
        ["_order", "sv", "week", "toe"], kind="stable")
    for rec in nav.to_dict("records"):
        lines += (_glonass_lines(rec, leap_s) if rec["system"] == "R"
                  else _kepler_lines(rec))
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    return path
