"""``landnav twin DATASET -o SCENARIO.yaml``: a scenario that drives the simulator along a
dataset's reference trajectory with matching sensors and sky (``simulator.recordings.twin``)."""

from __future__ import annotations

import argparse

from simulator.commands import SUMMARIES


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "twin", help=SUMMARIES["twin"],
        description="Write a scenario that drives the simulator along DATASET's reference "
                    "(or truth) trajectory, at its date and place, with the sensor presets "
                    "and rates of its datasheet; the trajectory goes beside the scenario as "
                    "STEM.drive.parquet. Example: landnav import comma2k19 SEGMENT -o real && "
                    "landnav twin real -o twin.yaml && landnav generate twin.yaml -o sim && "
                    "landnav compare real sim --report cmp")
    p.add_argument("dataset", metavar="DATASET", help="dataset directory (a real recording)")
    p.add_argument("-o", "--output", metavar="SCENARIO.yaml", required=True,
                   help="the twin scenario to write")
    p.add_argument("--force", action="store_true", help="replace existing files")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from simulator.dataset.io import open_dataset
    from simulator.recordings.twin import write_twin

    out = write_twin(open_dataset(args.dataset), args.output, args.force)
    print(f"wrote {out} and {out.with_name(out.stem + '.drive.parquet')}")
    return 0
