"""``landnav export DATASET [--rinex DIR] [--nmea FILE] [--mcap FILE]``: the dataset in the
formats receivers and tools exchange: RINEX 3.04 observation and navigation files, NMEA 0183
(``simulator.dataset.export``), a ROS 2 bag in MCAP (``simulator.dataset.rosbag``)."""

from __future__ import annotations

import argparse
from pathlib import Path

from simulator.commands import SUMMARIES
from simulator.errors import InputError, Problem


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "export", help=SUMMARIES["export"],
        description="Export the GNSS streams of a dataset: --rinex DIR writes a RINEX 3.04 "
                    "observation file (C1C, D1C, S1C from gnss_raw) and a navigation file (the "
                    "broadcast elements of gnss_nav) into DIR; --nmea FILE writes GGA, RMC, VTG, "
                    "GSA and GSV sentences for every fix epoch of gnss_fix; --mcap FILE writes a "
                    "ROS 2 bag in MCAP with every stream as standard messages (ENU/FLU frames, "
                    "covariances from the datasheet, UTC stamps; docs/ros2.md), one .mcap file "
                    "when FILE ends in .mcap, else a rosbag2 folder with metadata.yaml. "
                    "Example: landnav export runs/quickstart/dataset --mcap quickstart.mcap "
                    "--solution runs/quickstart/solutions/ins_odo_ekf.parquet")
    p.add_argument("dataset", metavar="DATASET", help="dataset directory")
    p.add_argument("--rinex", metavar="DIR", help="directory for the .obs and .nav files")
    p.add_argument("--nmea", metavar="FILE", help="NMEA 0183 output file")
    p.add_argument("--mcap", metavar="FILE", help="ROS 2 bag: FILE.mcap, or a rosbag2 folder")
    p.add_argument("--solution", metavar="FILE", action="append", default=[],
                   help="with --mcap: an estimator solution (Parquet or CSV) to add as "
                        "nav_msgs/Odometry on /solutions/STEM/odometry (repeatable)")
    p.add_argument("--force", action="store_true", help="overwrite existing output files")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from simulator.dataset.export import check_export, export_nmea, export_rinex
    from simulator.dataset.io import open_dataset

    if not args.rinex and not args.nmea and not args.mcap:
        raise InputError([Problem("landnav export", None, "", "nothing to do: give --rinex DIR, "
                                  "--nmea FILE and/or --mcap FILE")])
    if args.solution and not args.mcap:
        raise InputError([Problem("landnav export", None, "--solution",
                                  "solutions go into a ROS 2 bag: give --mcap FILE too")])
    dataset = open_dataset(args.dataset)
    # refused before anything is written
    check_export(dataset, args.rinex, args.nmea, args.force)
    if args.rinex:
        obs, nav = export_rinex(dataset, args.rinex, args.force, option="--rinex")
        base = obs.with_name(f"{obs.stem}_base.obs")
        print(f"wrote {obs}, {nav}" + (f" and {base}" if dataset.has("gnss_base_raw") else ""))
    if args.nmea:
        export_nmea(dataset, args.nmea, args.force, option="--nmea")
        print(f"wrote {args.nmea}")
    if args.mcap:
        from simulator.dataset.rosbag import export_mcap
        from simulator.scoring.readers import read_solution_file

        start = (int(dataset.field("gps_time_start", "week")),
                 float(dataset.field("gps_time_start", "tow")))
        solutions = {Path(f).stem: read_solution_file(f, start)[0] for f in args.solution}
        export_mcap(dataset, args.mcap, args.force, solutions, option="--mcap")
        print(f"wrote {args.mcap}")
    return 0
