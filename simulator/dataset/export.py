"""A dataset's GNSS streams in the formats receivers and tools exchange, as library functions
(``landnav export`` is a thin layer over them): RINEX 3.04 observation and navigation files for
RTKLIB and other GNSS software, and NMEA 0183 sentences.

Public functions
----------------
export_rinex, export_nmea.
"""

from __future__ import annotations

import contextlib
import math
from pathlib import Path

import numpy as np
import pandas as pd

from simulator.dataset.io import Dataset
from simulator.earth import geodetic_to_ecef
from simulator.errors import InputError, Problem
from simulator.gnss.nmea import write_nmea
from simulator.gnss.rinex_writer import write_rinex_nav, write_rinex_obs
from simulator.outputs import atomic_output_file, check_output_file
from simulator.timebase import SECONDS_PER_WEEK, gps_to_utc, leap_seconds


def _need(dataset: Dataset, name: str, option: str) -> None:
    if not dataset.has(name):
        raise InputError([Problem(str(dataset.path), None, "", f"{option} needs the {name!r} "
                                  "stream, which this dataset does not have (is sensors.gnss "
                                  "configured with that output?)")])


def _gps_start(dataset: Dataset) -> tuple[int, float]:
    """GPS week and time of week (s) of ``t = 0``: a week from 0 (the GPS epoch) on, a time
    of week in [0, 604800) s."""
    week = int(dataset.field("gps_time_start", "week"))
    tow = float(dataset.field("gps_time_start", "tow"))
    where = str(dataset.path / "manifest.json")
    if not 0 <= week <= MAX_GPS_WEEK:
        raise InputError([Problem(where, None, "gps_time_start.week", f"{week} is not a GPS "
                                  f"week (0, the GPS epoch 1980-01-06, to {MAX_GPS_WEEK})")])
    if not 0.0 <= tow < SECONDS_PER_WEEK:
        raise InputError([Problem(where, None, "gps_time_start.tow", f"{tow!r} is not a time "
                                  f"of week in [0, {SECONDS_PER_WEEK:g}) s")])
    return week, tow


# what each exported column may hold, in its SI unit: the RINEX and NMEA fields have fixed
# widths and ranges; a missing value (NaN) is written as an empty field
MAX_GPS_WEEK = 11_000  # 2190: the latest start a scenario may give
_RANGES = {
    "gnss_raw": {"sv": (1, 99), "pseudorange": (0.0, 1e9), "doppler": (-1e8, 1e8),
                 "cn0": (0.0, 99.0), "elevation": (-math.pi / 2, math.pi / 2),
                 "azimuth": (-2 * math.pi, 2 * math.pi)},
    "gnss_fix": {"lat": (-90.0, 90.0), "lon": (-180.0, 180.0), "alt": (-1e5, 1e6),
                 "speed": (0.0, 1e4), "course": (-2 * math.pi, 2 * math.pi),
                 "hdop": (0.0, 1e3), "vdop": (0.0, 1e3), "num_sats": (0, 99), "fix": (0, 9)},
}
MAX_NAV_MAGNITUDE = 1e99  # a RINEX D19.12 field holds a two-digit exponent


def _read_checked(dataset: Dataset, name: str) -> pd.DataFrame:
    """A GNSS stream whose every exported value fits its field (module note above)."""
    frame = dataset.read(name)
    path = str(dataset.path / dataset.manifest["streams"][name]["file"])
    checks = _RANGES.get(name) or {c: (-MAX_NAV_MAGNITUDE, MAX_NAV_MAGNITUDE)
                                   for c in frame.columns if c != "sv"
                                   and pd.api.types.is_numeric_dtype(frame[c])}
    for column, (low, high) in checks.items():
        if column not in frame:
            continue
        values = frame[column].to_numpy(dtype=float)
        bad = ~((values >= low) & (values <= high))
        bad &= ~np.isnan(values) if name in _RANGES else True
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InputError([Problem(path, None, column, f"row {i} holds {values[i]:g}, "
                                      f"outside [{low:g}, {high:g}]: it cannot be exported "
                                      f"({int(bad.sum())} such row(s))")])
    return frame


def check_export(dataset: Dataset, rinex_dir: str | Path | None, nmea_path: str | Path | None,
                 force: bool = False) -> None:
    """Everything ``export_rinex`` and ``export_nmea`` would refuse, checked before either
    writes: the streams, the GPS start, every exported value, the output names."""
    _gps_start(dataset)  # refuses a week or a time of week out of range
    names = []
    if rinex_dir is not None:
        _need(dataset, "gnss_raw", "--rinex")
        _need(dataset, "gnss_nav", "--rinex")
        names += ["gnss_raw", "gnss_nav"]
        base = Path(dataset.path).resolve().name
        for suffix in ("obs", "nav"):
            check_output_file(Path(rinex_dir) / f"{base}.{suffix}", force, [dataset.path],
                              "rinex")
    if nmea_path is not None:
        _need(dataset, "gnss_fix", "--nmea")
        names += ["gnss_fix", *(["gnss_raw"] if dataset.has("gnss_raw") else [])]
        check_output_file(nmea_path, force, [dataset.path], "nmea")
    for name in dict.fromkeys(names):
        _read_checked(dataset, name)


def _receiver_clock(dataset: Dataset, stream: str) -> pd.Series | None:
    """The receiver's clock error c dt_r (m) per epoch ``t`` from its GNSS truth, so that the
    RINEX epochs are the receiver's time tags (``write_rinex_obs``); None without the truth."""
    if not dataset.has(stream):
        return None
    truth = dataset.read(stream)
    return truth.groupby("t")["receiver_clock"].first()


def export_rinex(dataset: Dataset, directory: str | Path, force: bool = False,
                 option: str = "export_rinex") -> tuple[Path, Path]:
    """Write ``DIR/NAME.obs`` (every signal of ``gnss_raw``: C, L, D, S) and ``DIR/NAME.nav``
    (the broadcast records of every system of ``gnss_nav``, the broadcast ionosphere and the
    navigation file's system time offsets), ``NAME`` the dataset
    folder's name, and, when the dataset has a base station, ``DIR/NAME_base.obs`` (its
    ``gnss_base_raw``, APPROX POSITION its true position); the paths of the first two. The
    files are made before any is moved into place (never an ``.obs`` without its ``.nav``); an
    existing file is replaced only with ``force``. ``option`` names the caller in the message
    for a dataset without those streams."""
    _need(dataset, "gnss_raw", option)
    _need(dataset, "gnss_nav", option)
    week, tow = _gps_start(dataset)
    origin = {k: dataset.field("origin", k) for k in ("lat", "lon", "alt")}
    approx = np.ravel(geodetic_to_ecef(np.radians(origin["lat"]), np.radians(origin["lon"]),
                                       origin["alt"]))
    out = Path(directory)
    name = Path(dataset.path).resolve().name
    obs, nav = out / f"{name}.obs", out / f"{name}.nav"
    drawn = dataset.manifest.get("sensors", {}).get("gnss", {})
    iono = drawn.get("broadcast_iono", {})
    base = out / f"{name}_base.obs" if dataset.has("gnss_base_raw") else None
    for path in (obs, nav, *([base] if base is not None else [])):  # refused before any begins
        check_output_file(path, force, [dataset.path], "rinex")
    with contextlib.ExitStack() as stack:
        obs_tmp = stack.enter_context(atomic_output_file(obs, force, [dataset.path], "rinex"))
        nav_tmp = stack.enter_context(atomic_output_file(nav, force, [dataset.path], "rinex"))
        if base is not None:
            base_tmp = stack.enter_context(atomic_output_file(base, force, [dataset.path],
                                                              "rinex"))
            where = dataset.manifest["gnss_base"]
            write_rinex_obs(base_tmp, _read_checked(dataset, "gnss_base_raw"), week, tow,
                            np.array([where["x"], where["y"], where["z"]]), marker="BASE",
                            receiver_clock_m=_receiver_clock(dataset, "truth_gnss_base"))
        write_rinex_obs(obs_tmp, _read_checked(dataset, "gnss_raw"), week, tow, approx,
                        receiver_clock_m=_receiver_clock(dataset, "truth_gnss"))
        write_rinex_nav(nav_tmp, _read_checked(dataset, "gnss_nav"),
                        leap_seconds(gps_to_utc(week, tow)), iono.get("alpha"), iono.get("beta"),
                        drawn.get("time_corrections"))
    return obs, nav


def export_nmea(dataset: Dataset, path: str | Path, force: bool = False,
                option: str = "export_nmea") -> Path:
    """Write GGA, RMC, VTG, GSA and GSV sentences for every fix epoch of ``gnss_fix`` (the
    satellites of ``gnss_raw`` when the dataset has it) into ``path``; the path."""
    _need(dataset, "gnss_fix", option)
    week, tow = _gps_start(dataset)
    raw = _read_checked(dataset, "gnss_raw") if dataset.has("gnss_raw") else pd.DataFrame()
    fix = _read_checked(dataset, "gnss_fix")
    with atomic_output_file(path, force, [dataset.path], "nmea") as tmp:
        write_nmea(tmp, fix, raw, week, tow)
    return Path(path)
