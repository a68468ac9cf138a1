"""``landnav validate SCENARIO...``: check scenario files against the schema and physics limits."""

from __future__ import annotations

import argparse
import sys

from simulator.commands import SUMMARIES
from simulator.errors import InputError


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "validate", help=SUMMARIES["validate"],
        description="Check scenario files against the schema (keys, types, units, ranges) and "
                    "the physics limits (lateral acceleration, grade). Every problem of every "
                    "file is printed as `file:line: key.path: message`. Exit code 0 when all "
                    "files are valid, 2 otherwise.")
    p.add_argument("scenarios", nargs="+", metavar="SCENARIO", help="YAML scenario file(s)")
    p.add_argument("--set", dest="overrides", action="append", default=[],
                   metavar="KEY.PATH=VALUE", help="override a value before validating")
    p.add_argument("--import-plugins", action="store_true",
                   help="also import each module:Class estimator (this runs its module's code) "
                        "and check its config; without it such an entry is checked for its form "
                        "only, and validating runs no code the scenario names")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from simulator.pipeline import load_scenario

    failed = False
    for path in args.scenarios:
        try:
            scenario = load_scenario(path, args.overrides, import_plugins=args.import_plugins)
        except InputError as exc:
            failed = True
            for problem in exc.problems:
                print(problem, file=sys.stderr)
            continue
        print(f"{path}: ok ({scenario.name})")
    return 2 if failed else 0
