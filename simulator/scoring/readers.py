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
import warnings
from array import array
from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np
import pandas as pd

from simulator import columns as col
from simulator.earth import ecef_to_geodetic
from simulator.errors import InputError, Problem, refuse_undecodable, refuse_unless_regular
from simulator.replay import MAX_SOLUTION_ROWS, USES_GNSS_KEY, solution_problems
from simulator.scoring.align import solution_errors
from simulator.scoring.csv_rows import first_short_row
from simulator.timebase import GPS_EPOCH, SECONDS_PER_WEEK, leap_seconds

MAX_MEDIAN_HORIZONTAL_M = 100e3  # a solution whose median horizontal error exceeds it is refused
# a solution file larger than this is refused before it is read (10 million rows of a text
# solution are about 1.5-2.4 GB), and one of more rows than a replay may ask for is refused as
# soon as its reader gets there: text is read in chunks of _CHUNK_ROWS, so reading holds the
# numbers of the rows read and one chunk
MAX_SOLUTION_BYTES = 2 * 1024**3
_CHUNK_ROWS = 200_000
_MAX_HEADER_CHARS = 65_536  # an RTKLIB header line longer than this is no header
MIN_EARTH_RADIUS_M = 6.3e6  # an ECEF position nearer the Earth's centre is no position
_UNITS = {**col.SOLUTION, **col.SOLUTION_STD, **col.SENSOR_ERRORS}
# the columns a solution file is read for (any other column is left unread)
_READ = {**_UNITS, **col.SOLUTION_NIS, **col.SOLUTION_FIX}
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


def _too_many_rows(path: Path, rows: int) -> InputError:
    return _problem(path, f"more than {MAX_SOLUTION_ROWS:,} rows ({rows:,} read), more than a "
                          "solution may hold (a replay asks for at most as many); score it in "
                          "parts")


class _Rows:
    """Where a solution file's row ``i`` (0 for the first row of data) is, for messages: the
    file's line when its rows are lines after ``first_line - 1`` others, else the row."""

    def __init__(self, first_line: int | None = None) -> None:
        self.first_line = first_line

    def __call__(self, i: int) -> str:
        return f"row {i}" if self.first_line is None else f"line {i + self.first_line}"


def _parquet(path: Path) -> tuple[pd.DataFrame, list[str], bool]:
    import pyarrow as pa
    import pyarrow.parquet as pq

    from simulator.dataset.parquet import read_metadata, read_table, read_units

    try:
        schema = pq.ParquetFile(path)
        rows, names = schema.metadata.num_rows, schema.schema_arrow.names
    except (pa.ArrowException, OSError) as exc:
        raise _problem(path, f"not a readable Parquet file: {exc}") from None
    if rows > MAX_SOLUTION_ROWS:
        raise _too_many_rows(path, rows)
    frame = read_table(path, [n for n in names if n in _READ], read_only=True)
    uses_gnss = read_metadata(path).get(USES_GNSS_KEY, "true") != "false"
    units = {k: v for k, v in read_units(path).items() if k in frame.columns}
    _refuse_text(path, frame, _Rows())
    return frame, _honour_units(frame, units, path), uses_gnss


def _chunks(path: Path, what: str, where: _Rows, keep: tuple[str, ...] = (), **options
            ) -> Iterator[pd.DataFrame]:
    """``pandas.read_csv(path, **options)`` (a file of the format ``what``) chunk by chunk,
    each with its cells (but the columns ``keep``) checked as numbers (``_refuse_text``,
    naming the file's line; pandas numbers a chunk's rows from the file's first); refused past
    ``MAX_SOLUTION_ROWS``."""
    rows = 0
    try:
        with warnings.catch_warnings():
            # a row of more fields than the header: refused, not its fields dropped (nor the
            # first columns taken as the index, as pandas would without index_col=False)
            warnings.simplefilter("error", pd.errors.ParserWarning)
            for chunk in pd.read_csv(path, chunksize=_CHUNK_ROWS, index_col=False, **options):
                _refuse_text(path, chunk, where, keep)
                rows += len(chunk)
                if rows > MAX_SOLUTION_ROWS:
                    raise _too_many_rows(path, rows)
                yield chunk
    except pd.errors.ParserWarning:
        raise _problem(path, f"not a readable {what} file: a row has more fields than the "
                             "header names") from None
    except (ValueError, OSError) as exc:
        raise _problem(path, f"not a readable {what} file: {exc}") from None


def _joined(chunks: list[pd.DataFrame], columns: Iterable[str]) -> pd.DataFrame:
    """The chunks as one table, joined a column at a time, each chunk's column released as
    it is copied: the rows are held about once, not twice as ``pandas.concat`` holds them."""
    if not chunks:
        return pd.DataFrame(columns=list(columns), dtype=float)
    names = list(chunks[0].columns)
    joined = {}
    for name in names:
        joined[name] = np.concatenate([chunk.pop(name).to_numpy() for chunk in chunks])
    return pd.DataFrame(joined, copy=False)


def _csv(path: Path) -> pd.DataFrame:
    """A CSV solution, its known columns only (header names stripped of spaces); a row of
    fewer fields than the header is refused (pandas would fill them with NaN)."""
    short = first_short_row(path)
    if short is not None:
        missing = short.missing()
        raise _problem(path, f"line {short.line}: {short.fields} field(s) where the header names "
                             f"{len(short.header)}: no {', '.join(missing[:5])}"
                             f"{', ...' if len(missing) > 5 else ''} (a truncated or cut line?)",
                       missing[0])
    chunks = [chunk.rename(columns=str.strip) for chunk in _chunks(
        path, "CSV", _Rows(first_line=2), comment=None, skipinitialspace=True,
        usecols=lambda name: name.strip() in _READ)]
    return _joined(chunks, col.SOLUTION)


def _leap_seconds(utc_s: np.ndarray) -> np.ndarray:
    """GPS - UTC (s) at UTC times given as seconds since the GPS epoch's midnight (leap seconds
    start at midnight, so one value a day)."""
    days = np.floor(utc_s / 86400.0)
    unique, at = np.unique(days, return_inverse=True)
    return np.array([leap_seconds(GPS_EPOCH + dt.timedelta(days=float(d))) for d in unique],
                    dtype=float)[at] if len(days) else np.zeros(0)


def _gps_seconds(stamps: pd.Series, utc: bool) -> np.ndarray:
    """Seconds since the GPS epoch of naive datetimes in GPS time, or in UTC when ``utc``."""
    seconds = (stamps - pd.Timestamp(GPS_EPOCH)).dt.total_seconds().to_numpy()
    return seconds + _leap_seconds(seconds) if utc else seconds


def _pos_header(path: Path) -> tuple[list[str], bool, int]:
    """The column names an RTKLIB header's last line naming them gives (``%`` removed), whether
    a header line says the heights are geodetic, and how many lines precede the rows."""
    names: list[str] | None = None
    geodetic = False
    lines = 0
    with path.open(encoding="utf-8", errors="replace") as stream:
        while True:
            line = stream.readline(_MAX_HEADER_CHARS)
            if len(line) >= _MAX_HEADER_CHARS and not line.endswith("\n"):
                raise _problem(path, f"line {lines + 1} is longer than "
                                     f"{_MAX_HEADER_CHARS} characters: not an RTKLIB .pos file")
            if line.strip() and not line.startswith("%"):
                break
            if not line:
                break
            lines += 1
            geodetic = geodetic or "geodetic" in line
            if "Q" in line.split():
                names = line[1:].split()
    if names is None:
        raise _problem(path, "not an RTKLIB .pos file (no '%' header line naming the columns)")
    return names, geodetic, lines


def _pos_rows(path: Path, table: pd.DataFrame, names: list[str], where: _Rows,
              gps_start: tuple[int, float]) -> pd.DataFrame:
    """One chunk of an RTKLIB solution's rows (``table``: the two time fields as text
    ``_time1, _time2``, then the header's columns as numbers) as solution rows."""
    system = names[0]
    first = table["_time1"]
    if first.str.contains("/", regex=False).iloc[0]:
        try:
            stamps = pd.to_datetime(first + " " + table["_time2"],
                                    format="%Y/%m/%d %H:%M:%S.%f")
        except (ValueError, OverflowError) as exc:
            raise _problem(path, f"a time is not a date and time YYYY/MM/DD hh:mm:ss.sss "
                                 f"({exc})") from None
        seconds = _gps_seconds(pd.Series(stamps), system == "UTC")
    else:
        if system == "UTC":
            raise _problem(path, "UTC given as week and seconds is not an RTKLIB output; use "
                                 "GPST or a date")
        clock = table[["_time1", "_time2"]].copy()
        _refuse_text(path, clock, where)
        seconds = (clock["_time1"].to_numpy(float) * SECONDS_PER_WEEK
                   + clock["_time2"].to_numpy(float))
    out = pd.DataFrame({"t": seconds - (gps_start[0] * SECONDS_PER_WEEK + gps_start[1])},
                       index=table.index)
    if "longitude(deg)" in table:
        out["lat"], out["lon"] = table["latitude(deg)"], table["longitude(deg)"]
        out["alt"] = table["height(m)"]
    else:
        xyz = table[["x-ecef(m)", "y-ecef(m)", "z-ecef(m)"]].to_numpy(float)
        lat, lon, alt = ecef_to_geodetic(xyz)
        out["lat"], out["lon"], out["alt"] = np.degrees(lat), np.degrees(lon), alt
        # RTKLIB's "no solution" rows: no position, not one 6370 km off
        out.loc[np.linalg.norm(xyz, axis=1) < MIN_EARTH_RADIUS_M, ["lat", "lon", "alt"]] = np.nan
    if "vn(m/s)" in table:
        out["vn"], out["ve"], out["vd"] = table["vn(m/s)"], table["ve(m/s)"], -table["vu(m/s)"]
    else:
        out["vn"] = out["ve"] = out["vd"] = np.nan
    for name in _ATTITUDE:
        out[name] = np.nan
    if "sdn(m)" in table:
        out["std_n"], out["std_e"] = table["sdn(m)"], table["sde(m)"]
        out["std_d"] = table["sdu(m)"]
    # the quality flag as SPEC section 8's fix status: Q = 1 fixed (2), Q = 2 float (1), else
    # none (0: single point, DGPS, dead reckoning)
    out["fix_status"] = np.select([table["Q"] == 1, table["Q"] == 2], [2, 1], 0)
    return out


def _pos(path: Path, gps_start: tuple[int, float]) -> tuple[pd.DataFrame, list[str], _Rows]:
    names, geodetic, header_lines = _pos_header(path)
    system = names[0]
    if system not in ("GPST", "UTC"):
        raise _problem(path, f"time system {system!r}: only GPST and UTC are read")
    if geodetic:
        raise _problem(path, "heights are geodetic (above the geoid); write ellipsoidal heights"
                             " (RTKLIB option out-height=ellipsoidal)")
    if not ({"latitude(deg)", "longitude(deg)", "height(m)"} <= set(names)
            or {"x-ecef(m)", "y-ecef(m)", "z-ecef(m)"} <= set(names)):
        raise _problem(path, "neither latitude(deg)/longitude(deg)/height(m) nor x/y/z-ecef(m) "
                             "columns (east/north/up relative positions cannot be scored)")
    for group in (("vn(m/s)", "ve(m/s)", "vu(m/s)"), ("sdn(m)", "sde(m)", "sdu(m)")):
        if 0 < len(set(group) & set(names)) < len(group):
            raise _problem(path, f"the header names some of {', '.join(group)} but not all")
    where = _Rows(first_line=header_lines + 1)
    fields = ["_time1", "_time2", *names[1:]]
    chunks = []
    for table in _chunks(path, "RTKLIB .pos", where, ("_time1", "_time2"), sep=r"\s+",
                         header=None, names=fields, comment="%", skiprows=header_lines,
                         dtype=str, keep_default_na=False):
        if table.empty:
            continue
        short = table.index[table[fields[-1]].isna().to_numpy()]
        if len(short):
            raise _problem(path, f"{where(int(short[0]))}: rows "
                                 f"do not have the {len(fields)} fields the header names "
                                 "(latitude/longitude in degrees-minutes-seconds cannot be "
                                 "read; write degrees)")
        chunks.append(_pos_rows(path, table, names, where, gps_start))
    out = _joined(chunks, col.SOLUTION)
    notes = [f"{path}: RTKLIB {system} solution, {len(out)} rows"]
    if "x-ecef(m)" in names and len(out):
        centre = int(out["lat"].isna().sum())
        if centre:
            notes.append(f"{path}: {centre} row(s) at the Earth's centre (x, y, z = 0: no "
                         "solution) have no position")
    return out, notes, where


def _float(value: object) -> float:
    """An NMEA field as a float, NaN where it is empty."""
    return float(value) if value not in ("", None) else math.nan


def _nmea(path: Path, gps_start: tuple[int, float]) -> tuple[pd.DataFrame, list[str]]:
    from pynmeagps import NMEAReader

    start_date = (GPS_EPOCH + dt.timedelta(seconds=gps_start[0] * SECONDS_PER_WEEK
                                           + gps_start[1])).date()
    # GGA: UTC seconds since the GPS epoch, lat, lon, ellipsoidal height; RMC: the same time,
    # speed over ground (knots), course (deg); plain arrays (8 bytes a number)
    gga = {name: array("d") for name in ("utc", "lat", "lon", "alt")}
    rmc = {name: array("d") for name in ("utc", "speed", "course")}
    untimed = 0
    date = start_date

    def utc_seconds(time: dt.time) -> float:
        return (dt.datetime.combine(date, time) - GPS_EPOCH).total_seconds()

    with path.open("rb") as stream:
        for _, msg in NMEAReader(stream, quitonerror=0):
            if msg is None:
                continue
            if msg.msgID == "RMC" and msg.date:
                date = msg.date
                if msg.status == "A":
                    for name, value in zip(rmc, (utc_seconds(msg.time), _float(msg.spd),
                                                 _float(msg.cog)), strict=True):
                        rmc[name].append(value)
            elif msg.msgID == "GGA" and msg.quality and msg.lat != "" and not msg.time:
                untimed += 1
            elif msg.msgID == "GGA" and msg.quality and msg.lat != "":
                height = _float(msg.alt) + (_float(msg.sep) if msg.sep != "" else 0.0)
                for name, value in zip(gga, (utc_seconds(msg.time), msg.lat, msg.lon, height),
                                       strict=True):
                    gga[name].append(value)
            if max(len(gga["utc"]), len(rmc["utc"])) > MAX_SOLUTION_ROWS:
                raise _too_many_rows(path, max(len(gga["utc"]), len(rmc["utc"])))
    notes = [f"{path}: {untimed} GGA sentence(s) without a time left out"] if untimed else []
    if not gga["utc"]:
        return pd.DataFrame(columns=list(col.SOLUTION), dtype=float), notes
    utc = np.frombuffer(gga["utc"], dtype=float)
    seconds = utc + _leap_seconds(utc)
    # each GGA with the speed and course of the RMC of its time (the last of equal times)
    speed_knots, course_deg = np.full(len(utc), np.nan), np.full(len(utc), np.nan)
    rmc_utc = np.frombuffer(rmc["utc"], dtype=float)
    if len(rmc_utc):
        last = len(rmc_utc) - 1 - np.unique(rmc_utc[::-1], return_index=True)[1]
        at = np.minimum(np.searchsorted(rmc_utc[last], utc), len(last) - 1)
        found = rmc_utc[last][at] == utc
        speed_knots[found] = np.frombuffer(rmc["speed"], dtype=float)[last][at[found]]
        course_deg[found] = np.frombuffer(rmc["course"], dtype=float)[last][at[found]]
    speed = speed_knots * 1852.0 / 3600.0
    course = np.radians(course_deg)
    out = pd.DataFrame({"t": seconds - (gps_start[0] * SECONDS_PER_WEEK + gps_start[1]),
                        "lat": np.frombuffer(gga["lat"], dtype=float),
                        "lon": np.frombuffer(gga["lon"], dtype=float),
                        "alt": np.frombuffer(gga["alt"], dtype=float),
                        "vn": speed * np.cos(course), "ve": speed * np.sin(course),
                        "vd": np.nan})
    for name in _ATTITUDE:
        out[name] = np.nan
    return out, [f"{path}: NMEA GGA/RMC solution, {len(out)} rows (UTC times)", *notes]


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
    refuse_unless_regular(path, "solution file")
    size = path.stat().st_size
    if size > MAX_SOLUTION_BYTES:
        raise _problem(path, f"{size / 1e9:.3g} GB, more than a solution file may be "
                             f"({MAX_SOLUTION_BYTES / 1e9:.3g} GB, about 10 million rows); "
                             "score it in parts")
    kind = _kind(path)
    notes: list[str] = []
    uses_gnss = True
    where = _Rows()
    if kind == "parquet":
        frame, notes, uses_gnss = _parquet(path)
    elif kind == "csv":
        frame, where = _csv(path), _Rows(first_line=2)
    elif kind == "pos":
        frame, notes, where = _pos(path, gps_start)
    else:
        frame, notes = _nmea(path, gps_start)
    _refuse_out_of_range(path, frame, where)
    problems = solution_problems(frame)
    if problems:
        raise InputError([Problem(str(path), None, "", p) for p in problems])
    return frame, notes, uses_gnss


def _refuse_text(path: Path, frame: pd.DataFrame, where: _Rows,
                 keep: tuple[str, ...] = ()) -> None:
    """Refuse a cell of ``frame`` (but its columns ``keep``) that is not a number (empty cells
    are missing values), naming its column and ``where`` its row is (the frame's index counts
    the file's rows); numbers written as text become numbers, in place."""
    for name in frame.columns:
        values = frame[name]
        if name in keep or pd.api.types.is_numeric_dtype(values.dtype) or (
                pd.api.types.is_bool_dtype(values.dtype)):
            continue
        if not (pd.api.types.is_object_dtype(values.dtype)
                or pd.api.types.is_string_dtype(values.dtype)):
            raise _problem(path, f"column {name} holds {values.dtype} values, not numbers "
                                 "(times are seconds since the dataset's start)", name)
        numbers = pd.to_numeric(values, errors="coerce")
        bad = (numbers.isna() & values.notna() & (values.astype(str).str.strip() != "")
               ).to_numpy()
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise _problem(path, f"{where(int(frame.index[i]))}: {values.iloc[i]!r} is not a "
                                 "number", name)
        frame[name] = numbers


def _refuse_out_of_range(path: Path, frame: pd.DataFrame, where: _Rows) -> None:
    """Refuse an infinite value in any column, and a latitude, longitude (deg) or height (m)
    that no position has, naming the first such row and its column (NaN is a missing value)."""
    what = {"lat": "a latitude in degrees", "lon": "a longitude in degrees",
            "alt": "a land vehicle's ellipsoidal height in metres"}
    spans = {k: (*span, what[k]) for k, span in col.POSITION_SPANS.items()}
    for name in frame.columns:
        values = frame[name].to_numpy(float)
        low, high, what = spans.get(name, (-np.inf, np.inf, ""))
        bad = np.isinf(values) | (values < low) | (values > high)
        if not bad.any():
            continue
        i = int(np.flatnonzero(bad)[0])
        reason = ("is not finite (a missing value is an empty cell or NaN)"
                  if np.isinf(values[i]) else f"lies outside [{low:g}, {high:g}]: not {what}")
        raise _problem(path, f"{where(i)}: {name} = {values[i]:g} {reason}", name)


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
