"""``landnav generate SCENARIO -o DIR``: write a scenario's dataset."""

from __future__ import annotations

import argparse
import time

from simulator.commands import SUMMARIES
from simulator.commands.options import add_scenario_options


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "generate", help=SUMMARIES["generate"],
        description="Generate the dataset of a scenario: the exact truth trajectory, every "
                    "configured sensor's stream and the events table, as Parquet files with a "
                    "manifest.json (docs/dataset-format.md). The directory is written under a "
                    "temporary name and renamed when complete; an existing one is kept unless "
                    "--force.")
    p.add_argument("scenario", metavar="SCENARIO", help="YAML scenario file")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="dataset directory")
    p.add_argument("--force", action="store_true", help="overwrite an existing DIR")
    add_scenario_options(p)
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from simulator.dataset.generate import generate_dataset
    from simulator.scenario import load_scenario

    scenario = load_scenario(args.scenario, args.overrides, args.seed)
    start = time.perf_counter()
    out = generate_dataset(scenario, args.output, force=args.force)
    print(f"wrote {out} ({scenario.name}, seed {scenario.seed}) in "
          f"{time.perf_counter() - start:.2f} s")
    return 0
