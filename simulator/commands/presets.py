"""``landnav presets``: list the sensor presets with their parameters."""

from __future__ import annotations

import argparse

from simulator.commands import SUMMARIES


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "presets", help=SUMMARIES["presets"],
        description="List every sensor preset (sensors.<sensor>.preset) with the parameters it "
                    "sets, in the units of datasheets (deg/h, deg/sqrt(h), mg, ug/sqrt(Hz), %, "
                    "ppm, hPa; the dataset files hold SI); their sources are in "
                    "docs/scenario-reference.md.")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from simulator.scenario.reference import presets_text

    print(presets_text())
    return 0
