"""A dataset's GNSS streams in the formats receivers and tools exchange, as library functions
(``landnav export`` is a thin layer over them): RINEX 3.04 observation and navigation files for
RTKLIB and other GNSS software, and NMEA 0183 sentences.

Public functions
----------------
export_rinex, export_nmea.
"""

from __future__ import annotations

import contextlib
from pathlib import Path

import numpy as np
import pandas as pd

from simulator.dataset.io import Dataset
from simulator.earth import geodetic_to_ecef
from simulator.errors import InputError, Problem
from simulator.gnss.nmea import write_nmea
from simulator.gnss.rinex_writer import write_rinex_nav, write_rinex_obs
from simulator.outputs import atomic_output_file
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
    (the broadcast elements of ``gnss_nav`` and the broadcast ionosphere), ``NAME`` the dataset
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
    iono = dataset.manifest.get("sensors", {}).get("gnss", {}).get("broadcast_iono", {})
    base = out / f"{name}_base.obs" if dataset.has("gnss_base_raw") else None
    with contextlib.ExitStack() as stack:
        obs_tmp = stack.enter_context(atomic_output_file(obs, force, [dataset.path]))
        nav_tmp = stack.enter_context(atomic_output_file(nav, force, [dataset.path]))
        if base is not None:
            base_tmp = stack.enter_context(atomic_output_file(base, force, [dataset.path]))
            where = dataset.manifest["gnss_base"]
            write_rinex_obs(base_tmp, dataset.read("gnss_base_raw"), week, tow,
                            np.array([where["x"], where["y"], where["z"]]), marker="BASE",
                            receiver_clock_m=_receiver_clock(dataset, "truth_gnss_base"))
        write_rinex_obs(obs_tmp, dataset.read("gnss_raw"), week, tow, approx,
                        receiver_clock_m=_receiver_clock(dataset, "truth_gnss"))
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
    with atomic_output_file(path, force, [dataset.path]) as tmp:
        write_nmea(tmp, dataset.read("gnss_fix"), raw, week, tow)
    return Path(path)
