"""``landnav export DATASET [--rinex DIR] [--nmea FILE]``: the dataset's GNSS streams in the
formats receivers and tools exchange: RINEX 3.04 observation and navigation files, NMEA 0183."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from simulator.commands import SUMMARIES
from simulator.dataset.io import open_dataset
from simulator.earth import geodetic_to_ecef
from simulator.errors import InputError, Problem
from simulator.gnss.nmea import write_nmea
from simulator.gnss.rinex_writer import write_rinex_nav, write_rinex_obs
from simulator.outputs import atomic_output_file
from simulator.timebase import gps_to_utc, leap_seconds


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "export", help=SUMMARIES["export"],
        description="Export the GNSS streams of a dataset: --rinex DIR writes a RINEX 3.04 "
                    "observation file (C1C, D1C, S1C from gnss_raw) and a navigation file (the "
                    "broadcast elements of gnss_nav) into DIR; --nmea FILE writes GGA, RMC, VTG, "
                    "GSA and GSV sentences for every fix epoch of gnss_fix.")
    p.add_argument("dataset", metavar="DATASET", help="dataset directory")
    p.add_argument("--rinex", metavar="DIR", help="directory for the .obs and .nav files")
    p.add_argument("--nmea", metavar="FILE", help="NMEA 0183 output file")
    p.add_argument("--force", action="store_true", help="overwrite existing output files")
    p.set_defaults(run=run)


def _need(dataset, name: str, option: str) -> None:
    if not dataset.has(name):
        raise InputError([Problem(str(dataset.path), None, "", f"{option} needs the {name!r} "
                                  "stream, which this dataset does not have (is sensors.gnss "
                                  "configured with that output?)")])


def run(args: argparse.Namespace) -> int:
    if not args.rinex and not args.nmea:
        raise InputError([Problem("landnav export", None, "", "nothing to do: give --rinex DIR "
                                  "and/or --nmea FILE")])
    dataset = open_dataset(args.dataset)
    week = int(dataset.field("gps_time_start", "week"))
    tow = float(dataset.field("gps_time_start", "tow"))
    gnss = dataset.manifest.get("sensors", {}).get("gnss", {})
    if args.rinex:
        _need(dataset, "gnss_raw", "--rinex")
        _need(dataset, "gnss_nav", "--rinex")
        raw = dataset.read("gnss_raw")
        origin = {k: dataset.field("origin", k) for k in ("lat", "lon", "alt")}
        approx = np.ravel(geodetic_to_ecef(np.radians(origin["lat"]), np.radians(origin["lon"]),
                                           origin["alt"]))
        out = Path(args.rinex)
        name = Path(args.dataset).resolve().name
        obs, nav = out / f"{name}.obs", out / f"{name}.nav"
        iono = gnss.get("broadcast_iono", {})
        # both files are made before either is moved into place: never an .obs without its .nav
        with (atomic_output_file(obs, args.force, [dataset.path]) as obs_tmp,
              atomic_output_file(nav, args.force, [dataset.path]) as nav_tmp):
            write_rinex_obs(obs_tmp, raw, week, tow, approx)
            write_rinex_nav(nav_tmp, dataset.read("gnss_nav"),
                            leap_seconds(gps_to_utc(week, tow)), iono.get("alpha"),
                            iono.get("beta"))
        print(f"wrote {obs} and {nav}")
    if args.nmea:
        _need(dataset, "gnss_fix", "--nmea")
        raw = dataset.read("gnss_raw") if dataset.has("gnss_raw") else pd.DataFrame()
        with atomic_output_file(args.nmea, args.force, [dataset.path]) as tmp:
            write_nmea(tmp, dataset.read("gnss_fix"), raw, week, tow)
        print(f"wrote {args.nmea}")
    return 0
