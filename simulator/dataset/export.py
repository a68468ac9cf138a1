"""A dataset's GNSS streams in the formats receivers and tools exchange, as library functions
(``landnav export`` is a thin layer over them): RINEX 3.04 observation and navigation files for
RTKLIB and other GNSS software, and NMEA 0183 sentences.

Public functions
----------------
export_rinex, export_nmea.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from simulator.dataset.io import Dataset
from simulator.earth import geodetic_to_ecef
from simulator.errors import InputError, Problem
from simulator.gnss.nmea import write_nmea
from simulator.gnss.rinex_writer import write_rinex_nav, write_rinex_obs
from simulator.outputs import atomic_output_file, check_output_file
from simulator.timebase import gps_to_utc, leap_seconds


def _need(dataset: Dataset, name: str, option: str) -> None:
    if not dataset.has(name):
        raise InputError([Problem(str(dataset.path), None, "", f"{option} needs the {name!r} "
                                  "stream, which this dataset does not have (is sensors.gnss "
                                  "configured with that output?)")])


def _gps_start(dataset: Dataset) -> tuple[int, float]:
    """GPS week and time of week (s) of ``t = 0``."""
    return (int(dataset.field("gps_time_start", "week")),
            float(dataset.field("gps_time_start", "tow")))


def export_rinex(dataset: Dataset, directory: str | Path, force: bool = False,
                 option: str = "export_rinex") -> tuple[Path, Path]:
    """Write ``DIR/NAME.obs`` (C1C, D1C, S1C of ``gnss_raw``) and ``DIR/NAME.nav`` (the broadcast
    elements of ``gnss_nav`` and the broadcast ionosphere), ``NAME`` the dataset folder's name;
    their paths. Both files are made before either is moved into place (never an ``.obs``
    without its ``.nav``); an existing file is replaced only with ``force``. ``option`` names
    the caller in the message for a dataset without those streams."""
    _need(dataset, "gnss_raw", option)
    _need(dataset, "gnss_nav", option)
    week, tow = _gps_start(dataset)
    origin = {k: dataset.field("origin", k) for k in ("lat", "lon", "alt")}
    approx = np.ravel(geodetic_to_ecef(np.radians(origin["lat"]), np.radians(origin["lon"]),
                                       origin["alt"]))
    out = Path(directory)
    name = Path(dataset.path).resolve().name
    obs, nav = out / f"{name}.obs", out / f"{name}.nav"
    iono = dataset.manifest.get("sensors", {}).get("gnss", {}).get("broadcast_iono", {})
    for path in (obs, nav):  # both refused before either is begun
        check_output_file(path, force, [dataset.path], "rinex")
    with (atomic_output_file(obs, force, [dataset.path], "rinex") as obs_tmp,
          atomic_output_file(nav, force, [dataset.path], "rinex") as nav_tmp):
        write_rinex_obs(obs_tmp, dataset.read("gnss_raw"), week, tow, approx)
        write_rinex_nav(nav_tmp, dataset.read("gnss_nav"), leap_seconds(gps_to_utc(week, tow)),
                        iono.get("alpha"), iono.get("beta"))
    return obs, nav


def export_nmea(dataset: Dataset, path: str | Path, force: bool = False,
                option: str = "export_nmea") -> Path:
    """Write GGA, RMC, VTG, GSA and GSV sentences for every fix epoch of ``gnss_fix`` (the
    satellites of ``gnss_raw`` when the dataset has it) into ``path``; the path."""
    _need(dataset, "gnss_fix", option)
    week, tow = _gps_start(dataset)
    raw = dataset.read("gnss_raw") if dataset.has("gnss_raw") else pd.DataFrame()
    with atomic_output_file(path, force, [dataset.path], "nmea") as tmp:
        write_nmea(tmp, dataset.read("gnss_fix"), raw, week, tow)
    return Path(path)
