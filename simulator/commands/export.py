"""``landnav export DATASET [--rinex DIR] [--nmea FILE]``: the dataset's GNSS streams in the
formats receivers and tools exchange: RINEX 3.04 observation and navigation files, NMEA 0183
(``simulator.dataset.export``, the library functions)."""

from __future__ import annotations

import argparse

from simulator.commands import SUMMARIES
from simulator.dataset.export import check_export, export_nmea, export_rinex
from simulator.dataset.io import open_dataset
from simulator.errors import InputError, Problem


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


def run(args: argparse.Namespace) -> int:
    if not args.rinex and not args.nmea:
        raise InputError([Problem("landnav export", None, "", "nothing to do: give --rinex DIR "
                                  "and/or --nmea FILE")])
    dataset = open_dataset(args.dataset)
    check_export(dataset, args.rinex, args.nmea, args.force)  # refused before anything is written
    if args.rinex:
        obs, nav = export_rinex(dataset, args.rinex, args.force, option="--rinex")
        print(f"wrote {obs} and {nav}")
    if args.nmea:
        export_nmea(dataset, args.nmea, args.force, option="--nmea")
        print(f"wrote {args.nmea}")
    return 0
