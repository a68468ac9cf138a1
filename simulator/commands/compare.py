"""``landnav compare DATASET DATASET [--report DIR]``: the statistics of two datasets' streams
side by side, a real recording and its twin (``simulator.comparison``)."""

from __future__ import annotations

import argparse
from pathlib import Path

from simulator.commands import SUMMARIES


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "compare", help=SUMMARIES["compare"],
        description="Compute the same statistics on two datasets, each against its own "
                    "reference or truth, and print them side by side with the ratio second / "
                    "first: IMU noise and vibration while driving, odometer speed error, "
                    "satellites tracked, C/N0, fix error, and one estimator's error on both. "
                    "--report DIR adds the plots and names the largest mismatches with the "
                    "model to look at first. Example: landnav compare real sim --report cmp")
    p.add_argument("first", metavar="DATASET", help="the first dataset (a real recording)")
    p.add_argument("second", metavar="DATASET", help="the second dataset (its twin)")
    p.add_argument("-e", "--estimator", default="ins_odo_ekf", metavar="NAME",
                   help="estimator run on both (default ins_odo_ekf; 'none' for none)")
    p.add_argument("--report", metavar="DIR", help="write report.md and its plots into DIR")
    p.add_argument("--force", action="store_true", help="replace an existing report folder")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from simulator.dataset.io import open_dataset
    from simulator.outputs import atomic_output_dir
    from simulator.comparison import compare_datasets, write_comparison

    first, second = open_dataset(args.first), open_dataset(args.second)
    estimator = None if args.estimator == "none" else args.estimator
    result = compare_datasets(first, second, estimator)
    labels = (Path(args.first).resolve().name, Path(args.second).resolve().name)
    width = max(len(r["statistic"]) for r in result["rows"])
    print(f"{'statistic':{width}s}  {labels[0]:>12s}  {labels[1]:>12s}  ratio")
    for row in result["rows"]:
        print(f"{row['statistic']:{width}s}  {row['first']:12.4g}  {row['second']:12.4g}  "
              f"{row['ratio']:.3g}")
    if args.report:
        with atomic_output_dir(Path(args.report), args.force, [first.path, second.path]) as tmp:
            write_comparison(result, Path(tmp), labels)
        print(f"wrote {Path(args.report) / 'report.md'}")
    return 0
