"""Solutions from any tool: Parquet and CSV with the columns of docs/solution-format.md, RTKLIB
``.pos`` files and NMEA 0183 logs, each turned into the one solution table; and the checks that
refuse a solution that cannot belong to the dataset.

Formats (chosen by the file's suffix, else by its first bytes):

* **Parquet** (``.parquet``, ``.pq``): those columns. A column whose field metadata ``unit``
  differs from the documented unit is converted, with a note (``lat``/``lon`` in ``rad``,
  attitude in ``deg``, ``std_*`` in ``cm``: any unit pint converts to the documented one); an
  inconvertible unit is refused naming the column.
* **CSV** (``.csv``): a header row with the documented column names and units (no metadata to read).
* **RTKLIB** ``.pos`` (the output of ``rnx2rtkp``/``rtkpost``, RTKLIB 2.4.3 manual, appendix
  B.5): ``%`` header lines, the last naming the columns. The time is GPS week and seconds
  (``2312 270018.000``) or a date (``2024/05/01 03:00:18.000``), in ``GPST`` or ``UTC`` as the
  header's first column says; the position is latitude/longitude/height in degrees (WGS-84
  ellipsoidal height) or ECEF ``x-ecef y-ecef z-ecef``. ``sdn, sde, sdu`` become ``std_n,
  std_e, std_d`` (the standard deviation of down equals that of up); ``vn ve vu`` columns, when
  RTKLIB wrote velocities, become ``vn, ve, vd = -vu``. Latitude/longitude in degrees-minutes-
  seconds (``-g``) and geodetic (orthometric) heights are refused: they cannot be scored.
* **NMEA** (``.nmea``, ``.nma``, ``.gps``, ``.log``, ``.txt``): GGA sentences (time, latitude,
  longitude, and the ellipsoidal height as altitude above mean sea level plus the geoid
  separation), parsed with pynmeagps; the date comes from the RMC sentences (and the dataset's
  start date before the first RMC), and each GGA gets the speed over ground and course of the
  RMC of the same time as ``vn = v cos(course)``, ``ve = v sin(course)``. GGA with quality 0 (no
  fix) gives no row. NMEA times are UTC.

Foreign formats give NaN for what they do not carry (attitude always; ``vd`` from NMEA; the
velocity without RTKLIB's velocity output), which the scores leave out.

Times become ``t`` (s since the dataset's start, GPS time) with the dataset's ``gps_time_start``
and the leap seconds of ``simulator.timebase``.

Public names
------------
read_solution_file, check_solution, MAX_MEDIAN_HORIZONTAL_M.
"""

from __future__ import annotations

import datetime as dt
import math
from pathlib import Path

import numpy as np
import pandas as pd

from simulator import columns as col
from simulator.earth import ecef_to_geodetic
from simulator.errors import InputError, Problem, refuse_undecodable
from simulator.replay import USES_GNSS_KEY, solution_problems
from simulator.scoring.align import solution_errors
from simulator.timebase import GPS_EPOCH, SECONDS_PER_WEEK, leap_seconds

MAX_MEDIAN_HORIZONTAL_M = 100e3  # a solution whose median horizontal error exceeds it is refused
# a solution file larger than this is refused before it is read (10 million rows of a text
# solution are about 1.5 GB; a replay asks for at most 10 million rows)
MAX_SOLUTION_BYTES = 2 * 1024**3
MIN_EARTH_RADIUS_M = 6.3e6  # an ECEF position nearer the Earth's centre is no position
_UNITS = {**col.SOLUTION, **col.SOLUTION_STD, **col.SENSOR_ERRORS}
_ANGLE_UNITS = {"deg": math.pi / 180.0, "degree": math.pi / 180.0, "degrees": math.pi / 180.0,
                "rad": 1.0, "radian": 1.0, "radians": 1.0}
_NMEA_SUFFIXES = {".nmea", ".nma", ".gps", ".log", ".txt"}
_ATTITUDE = ("roll", "pitch", "yaw")


def _problem(path: Path, message: str, key: str = "") -> InputError:
    return InputError([Problem(str(path), None, key, message)])


def _factor(unit: str, spec_unit: str, path: Path, column: str) -> float:
    """The factor that turns values in ``unit`` into ``spec_unit``."""
    a, b = _ANGLE_UNITS.get(unit.lower()), _ANGLE_UNITS.get(spec_unit)
    if a is not None and b is not None:
        return a / b
    from simulator.units import UnitError, to_si  # pint: loaded only for an unusual unit

    try:
        return to_si(f"1 {unit}", spec_unit)
    except UnitError as exc:
        raise _problem(path, f"column {column}: its unit metadata {unit!r} cannot be converted "
                             f"to {spec_unit!r} ({exc})", column) from None


def _honour_units(frame: pd.DataFrame, units: dict[str, str], path: Path) -> list[str]:
    notes = []
    for name, unit in units.items():
        spec = _UNITS.get(name)
        if spec is None or not unit or unit == spec or (spec == "1" and unit in ("", "1")):
            continue
        factor = _factor(unit, spec, path, name)
        frame[name] = frame[name].to_numpy(float) * factor
        notes.append(f"{path}: column {name} in {unit!r} (its unit metadata) converted to "
                     f"{spec!r}")
    return notes


def _parquet(path: Path) -> tuple[pd.DataFrame, list[str], bool]:
    from simulator.dataset.parquet import read_metadata, read_table, read_units

    frame = read_table(path)
    uses_gnss = read_metadata(path).get(USES_GNSS_KEY, "true") != "false"
    return frame, _honour_units(frame, read_units(path), path), uses_gnss


def _csv(path: Path) -> pd.DataFrame:
    try:
        return pd.read_csv(path, comment=None, skipinitialspace=True)
    except (ValueError, OSError) as exc:
        raise _problem(path, f"not a readable CSV file: {exc}") from None


def _gps_seconds(stamps: pd.Series, utc: bool) -> np.ndarray:
    """Seconds since the GPS epoch of naive datetimes in GPS time, or in UTC when ``utc``."""
    seconds = (stamps - pd.Timestamp(GPS_EPOCH)).dt.total_seconds().to_numpy()
    if utc:
        seconds = seconds + np.array([leap_seconds(s.to_pydatetime()) for s in stamps])
    return seconds


def _pos(path: Path, gps_start: tuple[int, float]) -> tuple[pd.DataFrame, list[str]]:
    lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    header = [ln for ln in lines if ln.startswith("%")]
    names_line = next((ln for ln in reversed(header) if "Q" in ln.split()), None)
    if names_line is None:
        raise _problem(path, "not an RTKLIB .pos file (no '%' header line naming the columns)")
    names = names_line[1:].split()
    system = names[0]
    if system not in ("GPST", "UTC"):
        raise _problem(path, f"time system {system!r}: only GPST and UTC are read")
    if any("geodetic" in ln for ln in header):
        raise _problem(path, "heights are geodetic (above the geoid); write ellipsoidal heights"
                             " (RTKLIB option out-height=ellipsoidal)")
    rows = [ln.split() for ln in lines if ln.strip() and not ln.startswith("%")]
    if not rows:
        return pd.DataFrame(columns=list(col.SOLUTION)), []
    width = len(names) + 1  # the time takes two fields (week and seconds, or date and time)
    if any(len(r) != width for r in rows):
        raise _problem(path, f"rows do not have the {width} fields the header names "
                             "(latitude/longitude in degrees-minutes-seconds cannot be read; "
                             "write degrees)")
    table = pd.DataFrame([r[2:] for r in rows], columns=names[1:])
    _refuse_text(path, table, offset=len(lines) - len(rows))
    table = table.apply(pd.to_numeric)
    first = [r[0] for r in rows]
    if "/" in first[0]:
        try:
            stamps = pd.to_datetime([f"{r[0]} {r[1]}" for r in rows],
                                    format="%Y/%m/%d %H:%M:%S.%f")
        except (ValueError, OverflowError) as exc:
            raise _problem(path, f"a time is not a date and time YYYY/MM/DD hh:mm:ss.sss "
                                 f"({exc})") from None
        seconds = _gps_seconds(pd.Series(stamps), system == "UTC")
    else:
        clock = pd.DataFrame({"week": first, "seconds": [r[1] for r in rows]})
        _refuse_text(path, clock, offset=len(lines) - len(rows))
        seconds = (clock["week"].astype(float).to_numpy() * SECONDS_PER_WEEK
                   + clock["seconds"].astype(float).to_numpy())
        if system == "UTC":
            raise _problem(path, "UTC given as week and seconds is not an RTKLIB output; use "
                                 "GPST or a date")
    out = pd.DataFrame({"t": seconds - (gps_start[0] * SECONDS_PER_WEEK + gps_start[1])})
    notes = [f"{path}: RTKLIB {system} solution, {len(out)} rows"]
    if "latitude(deg)" in table:
        out["lat"], out["lon"] = table["latitude(deg)"], table["longitude(deg)"]
        out["alt"] = table["height(m)"]
    elif "x-ecef(m)" in table:
        xyz = table[["x-ecef(m)", "y-ecef(m)", "z-ecef(m)"]].to_numpy(float)
        lat, lon, alt = ecef_to_geodetic(xyz)
        out["lat"], out["lon"], out["alt"] = np.degrees(lat), np.degrees(lon), alt
        centre = np.linalg.norm(xyz, axis=1) < MIN_EARTH_RADIUS_M
        if centre.any():  # RTKLIB's "no solution" rows: no position, not one 6370 km off
            out.loc[centre, ["lat", "lon", "alt"]] = np.nan
            notes.append(f"{path}: {int(centre.sum())} row(s) at the Earth's centre "
                         "(x, y, z = 0: no solution) have no position")
    else:
        raise _problem(path, "neither latitude(deg)/longitude(deg)/height(m) nor x/y/z-ecef(m) "
                             "columns (east/north/up relative positions cannot be scored)")
    if "vn(m/s)" in table:
        out["vn"], out["ve"], out["vd"] = table["vn(m/s)"], table["ve(m/s)"], -table["vu(m/s)"]
    else:
        out["vn"] = out["ve"] = out["vd"] = np.nan
    for name in _ATTITUDE:
        out[name] = np.nan
    if "sdn(m)" in table:
        out["std_n"], out["std_e"], out["std_d"] = table["sdn(m)"], table["sde(m)"], table["sdu(m)"]
    # the quality flag as SPEC section 8's fix status: Q = 1 fixed (2), Q = 2 float (1), else
    # none (0: single point, DGPS, dead reckoning)
    out["fix_status"] = np.select([table["Q"] == 1, table["Q"] == 2], [2, 1], 0)
    return out, notes


def _float(value: object) -> float:
    """An NMEA field as a float, NaN where it is empty."""
    return float(value) if value not in ("", None) else math.nan


def _nmea(path: Path, gps_start: tuple[int, float]) -> tuple[pd.DataFrame, list[str]]:
    from pynmeagps import NMEAReader

    start_date = (GPS_EPOCH + dt.timedelta(seconds=gps_start[0] * SECONDS_PER_WEEK
                                           + gps_start[1])).date()
    gga, rmc = [], {}
    untimed = 0
    date = start_date
    with path.open("rb") as stream:
        for _, msg in NMEAReader(stream, quitonerror=0):
            if msg is None:
                continue
            if msg.msgID == "RMC" and msg.date:
                date = msg.date
                if msg.status == "A":
                    rmc[(date, msg.time)] = (_float(msg.spd), _float(msg.cog))
            elif msg.msgID == "GGA" and msg.quality and msg.lat != "" and not msg.time:
                untimed += 1
            elif msg.msgID == "GGA" and msg.quality and msg.lat != "":
                gga.append((date, msg.time, msg.lat, msg.lon,
                             _float(msg.alt) + (_float(msg.sep) if msg.sep != "" else 0.0)))
    if not gga:
        return pd.DataFrame(columns=list(col.SOLUTION)), (
            [f"{path}: {untimed} GGA sentence(s) without a time left out"] if untimed else [])
    stamps = pd.Series([dt.datetime.combine(d, tm) for d, tm, *_ in gga])
    seconds = _gps_seconds(stamps, utc=True)
    speed_course = np.array([rmc.get((d, tm), (np.nan, np.nan)) for d, tm, *_ in gga],
                            dtype=float)
    speed = speed_course[:, 0] * 1852.0 / 3600.0  # knots
    course = np.radians(speed_course[:, 1])
    out = pd.DataFrame({"t": seconds - (gps_start[0] * SECONDS_PER_WEEK + gps_start[1]),
                        "lat": [g[2] for g in gga], "lon": [g[3] for g in gga],
                        "alt": [g[4] for g in gga], "vn": speed * np.cos(course),
                        "ve": speed * np.sin(course), "vd": np.nan})
    for name in _ATTITUDE:
        out[name] = np.nan
    notes = [f"{path}: NMEA GGA/RMC solution, {len(out)} rows (UTC times)"]
    if untimed:
        notes.append(f"{path}: {untimed} GGA sentence(s) without a time left out")
    return out, notes


def _kind(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix in (".parquet", ".pq"):
        return "parquet"
    if suffix in (".csv", ".pos"):
        return suffix[1:]
    if suffix in _NMEA_SUFFIXES:
        return "nmea"
    with path.open("rb") as stream:
        head = stream.read(4)  # never the whole file
    if head == b"PAR1":
        return "parquet"
    return {b"%": "pos", b"$": "nmea"}.get(head[:1], "csv")


def read_solution_file(path: str | Path, gps_start: tuple[int, float]
                       ) -> tuple[pd.DataFrame, list[str], bool]:
    """Read a solution in any supported format (module docstring).

    Parameters
    ----------
    path : the file.
    gps_start : (GPS week, seconds of week) of the dataset's t = 0 (manifest ``gps_time_start``).

    Returns
    -------
    frame : the solution table, docs/solution-format.md columns, t increasing.
    notes : lines telling what was converted (units, format), for the user.
    uses_gnss : False only for a Parquet file landnav wrote for an estimator without GNSS
        (schema metadata ``landnav.uses_gnss``); any other solution is taken to use GNSS.

    Raises
    ------
    InputError
        Naming the file: unreadable, unknown format, a missing column, t not increasing, an
        inconvertible unit.
    """
    path = Path(path)
    refuse_undecodable(path, "solution file's name")
    if not path.is_file():
        raise _problem(path, "no such solution file")
    size = path.stat().st_size
    if size > MAX_SOLUTION_BYTES:
        raise _problem(path, f"{size / 1e9:.3g} GB, more than a solution file may be "
                             f"({MAX_SOLUTION_BYTES / 1e9:.3g} GB, about 10 million rows); "
                             "score it in parts")
    kind = _kind(path)
    notes: list[str] = []
    uses_gnss = True
    if kind == "parquet":
        frame, notes, uses_gnss = _parquet(path)
    elif kind == "csv":
        frame = _csv(path)
        _refuse_text(path, frame, [c for c in frame.columns if c in _UNITS], offset=1)
    elif kind == "pos":
        frame, notes = _pos(path, gps_start)
    else:
        frame, notes = _nmea(path, gps_start)
    _refuse_text(path, frame, [c for c in frame.columns if c in _UNITS])
    problems = solution_problems(frame)
    if problems:
        raise InputError([Problem(str(path), None, "", p) for p in problems])
    return frame, notes, uses_gnss


def _refuse_text(path: Path, frame: pd.DataFrame, columns: list[str] | None = None,
                 offset: int = 0) -> None:
    """Refuse a cell of ``frame``'s ``columns`` (all by default) that is not a number (empty
    cells are missing values), naming its column and the file's line (``offset``: the lines
    before the first row; 0 when there are no lines, as in Parquet: then the row); numbers
    written as text become numbers, in place."""
    for name in frame.columns if columns is None else columns:
        values = frame[name]
        if pd.api.types.is_numeric_dtype(values.dtype) or pd.api.types.is_bool_dtype(
                values.dtype):
            continue
        if not (pd.api.types.is_object_dtype(values.dtype)
                or pd.api.types.is_string_dtype(values.dtype)):
            raise _problem(path, f"column {name} holds {values.dtype} values, not numbers "
                                 "(times are seconds since the dataset's start)", name)
        numbers = pd.to_numeric(values, errors="coerce")
        bad = numbers.isna() & values.notna() & (values.astype(str).str.strip() != "")
        if bad.any():
            i = int(np.flatnonzero(bad.to_numpy())[0])
            where = f"line {i + offset + 1}" if offset else f"row {i}"
            raise _problem(path, f"{where}: {values.iloc[i]!r} is not a number", name)
        frame[name] = numbers


def _cause(frame: pd.DataFrame, truth: pd.DataFrame) -> str:
    """The likely cause of a solution far from the truth."""
    lat = frame["lat"].to_numpy(float)
    lon = frame["lon"].to_numpy(float)
    true_lat = float(truth["lat"].median())
    true_lon = float(truth["lon"].median())
    if (np.nanmax(np.abs(lat)) <= math.pi / 2 and np.nanmax(np.abs(lon)) <= math.pi
            and abs(math.degrees(np.nanmedian(lat)) - true_lat) < 1.0):
        return ("lat and lon look like radians: write degrees (docs/solution-format.md), or "
                "give the Parquet columns the unit 'rad'")
    if abs(np.nanmedian(lat) - true_lon) < 1.0 and abs(np.nanmedian(lon) - true_lat) < 1.0:
        return "lat and lon look swapped"
    return ("is it a solution of another dataset (this one starts at lat "
            f"{true_lat:.4f}, lon {true_lon:.4f}), or are the times shifted?")


def check_solution(path: str | Path, frame: pd.DataFrame, truth: pd.DataFrame) -> None:
    """Refuse a solution that cannot be scored against this truth, naming the likely cause.

    Refused: no rows; negative standard deviations; no row, or a single one, with a position
    within the truth's time span; attitude values beyond 2 pi
    (degrees where radians are due); a median horizontal error over
    ``MAX_MEDIAN_HORIZONTAL_M``.

    Raises
    ------
    InputError
        Naming the file and the likely cause.
    """
    path = Path(path)
    if len(frame) == 0:
        raise _problem(path, "the solution has no rows")
    for name in col.SOLUTION_STD:
        values = frame[name].to_numpy(float) if name in frame else np.zeros(0)
        if np.any(values < 0):
            raise _problem(path, f"{name} has negative values (row "
                                 f"{int(np.flatnonzero(values < 0)[0])}): a standard "
                                 "deviation is never negative", name)
    t = frame["t"].to_numpy(float)
    t0, t1 = float(truth["t"].iloc[0]), float(truth["t"].iloc[-1])
    if t[-1] < t0 or t[0] > t1:
        raise _problem(path, f"its t runs from {t[0]:.3f} to {t[-1]:.3f} s and the truth from "
                             f"{t0:.3f} to {t1:.3f} s: no overlap. t is seconds since the "
                             "dataset's start (manifest gps_time_start); is it a GPS time of "
                             "week, Unix time, or a solution of another dataset?")
    for name in _ATTITUDE:
        values = frame[name].to_numpy(float)
        if np.any(np.abs(values[np.isfinite(values)]) > 2 * math.pi + 1e-6):
            raise _problem(path, f"{name} has values beyond 2 pi: degrees? Attitude is in "
                                 "radians (docs/solution-format.md), or give the Parquet "
                                 "column the unit 'deg'", name)
    h = solution_errors(truth, frame).errors["err_h"].to_numpy()
    h = h[np.isfinite(h)]
    if h.size == 0:
        raise _problem(path, "no row within the truth's time span has a finite position")
    if h.size < 2:
        raise _problem(path, "only one row within the truth's time span has a position: "
                             "scores need at least two")
    median = float(np.median(h))
    if median > MAX_MEDIAN_HORIZONTAL_M:
        raise _problem(path, f"median horizontal error {median / 1e3:.0f} km (over "
                             f"{MAX_MEDIAN_HORIZONTAL_M / 1e3:.0f} km): {_cause(frame, truth)}")
