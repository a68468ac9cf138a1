"""Options shared by the commands that read a scenario (``--seed``, ``--set``)."""

from __future__ import annotations

import argparse


def add_scenario_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--seed", type=int, default=None,
                        help="random seed (replaces the scenario's seed)")
    parser.add_argument("--set", dest="overrides", action="append", default=[],
                        metavar="KEY.PATH=VALUE",
                        help="override any scenario value, e.g. --set sensors.imu.rate=200 or "
                             "--set trajectory.segments.2.straight.length=500 (repeatable; "
                             "validated like the file and recorded in the manifest)")
