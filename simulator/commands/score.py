"""``landnav score DATASET (--solution FILE... | -e NAME...)``: truth-referenced metrics of one
or more solutions (SPEC section 8), optionally as JSON and as a markdown report with plots."""

from __future__ import annotations

import argparse
import contextlib
from pathlib import Path

from simulator import pipeline
from simulator.commands import SUMMARIES
from simulator.dataset.io import open_dataset
from simulator.errors import InputError, Problem
from simulator.outputs import atomic_output_dir
from simulator.replay import read_solution
from simulator.scoring.evaluate import write_scores
from simulator.scoring.report import print_scores, write_report


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "score", help=SUMMARIES["score"],
        description="Score navigation solutions against the truth of a dataset: horizontal, "
                    "vertical, velocity and attitude errors, per-GNSS-outage drift, NEES when "
                    "the solution has standard deviations (SPEC section 8). Solutions are files "
                    "(--solution, labelled by file stem; written by any program, SPEC section 7)"
                    " or registered estimators run here (-e, labelled by name). Prints a compact "
                    "table; --json writes the scores keyed by label; --report writes report.md "
                    "with plots into DIR (atomically; an existing DIR needs --force).")
    p.add_argument("dataset", metavar="DATASET", help="dataset directory")
    which = p.add_mutually_exclusive_group(required=True)
    which.add_argument("--solution", nargs="+", action="extend", metavar="FILE",
                       help="solution Parquet file(s)")
    which.add_argument("-e", "--estimator", nargs="+", action="extend", metavar="NAME",
                       help="registered estimator(s) to run over the dataset and score")
    p.add_argument("--json", metavar="OUT", help="write the scores as JSON")
    p.add_argument("--report", metavar="DIR", help="write report.md and plots/ into DIR")
    p.add_argument("--force", action="store_true",
                   help="overwrite an existing --json file or report DIR")
    p.set_defaults(run=run)


def _from_files(paths: list[str]) -> pipeline.Solutions:
    out: pipeline.Solutions = {}
    for path in paths:
        label = Path(path).stem
        if label in out:
            raise InputError([Problem(path, None, "", f"another solution file is also labelled "
                                      f"{label!r} (labels are file stems); rename one")])
        out[label] = (read_solution(path), None)
    return out


def run(args: argparse.Namespace) -> int:
    dataset = open_dataset(args.dataset)
    with contextlib.ExitStack() as stack:
        report_dir = (stack.enter_context(atomic_output_dir(Path(args.report), args.force,
                                                            [dataset.path]))
                      if args.report else None)
        solutions = (_from_files(args.solution) if args.solution
                     else pipeline.run_estimators(dataset, dict.fromkeys(args.estimator)))
        ev = pipeline.score(dataset, solutions)
        print_scores(ev)
        if args.json:
            write_scores(ev.scores(), Path(args.json), args.force, [dataset.path])
            print(f"wrote {args.json}")
        if report_dir is not None:
            write_report(report_dir, ev, f"Scores on {dataset.path.name}")
    if args.report:
        print(f"wrote {Path(args.report) / 'report.md'}")
    return 0
