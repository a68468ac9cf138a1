"""``landnav score DATASET [--solution FILE...] [-e NAME...]``: truth-referenced metrics of one
or more solutions (docs/scores.md), optionally as JSON and as a markdown report with plots."""

from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from simulator.commands import SUMMARIES
from simulator.errors import InputError, Problem

if TYPE_CHECKING:
    from simulator import pipeline
    from simulator.dataset.io import Dataset


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "score", help=SUMMARIES["score"],
        description="Score navigation solutions against the truth of a dataset: horizontal, "
                    "vertical, velocity and attitude errors, coverage, drift in each GNSS outage "
                    "and degraded window, estimated sensor errors, NEES when the solution has "
                    "standard deviations (docs/scores.md). Solutions are files (--solution, "
                    "labelled by file stem: Parquet or CSV with the columns of "
                    "docs/solution-format.md, RTKLIB .pos, NMEA GGA/RMC) and/or estimators run "
                    "here (-e, a registered name or module:Class, labelled by name). Prints a "
                    "compact table; --json writes the scores keyed by label; --report writes "
                    "report.md with plots and report.html (the same, plots embedded) into DIR "
                    "(atomically; an existing DIR needs --force).")
    p.add_argument("dataset", metavar="DATASET", help="dataset directory")
    p.add_argument("--solution", nargs="+", action="extend", metavar="FILE", default=[],
                   help="solution file(s): .parquet, .csv, RTKLIB .pos, NMEA")
    p.add_argument("-e", "--estimator", nargs="+", action="extend", metavar="NAME", default=[],
                   help="estimator(s) to run over the dataset and score (registered name or "
                        "module:Class, found from the current directory as python -m does)")
    p.add_argument("--json", metavar="OUT", help="write the scores as JSON")
    p.add_argument("--report", metavar="DIR",
                   help="write report.md, plots/ and report.html into DIR")
    p.add_argument("--force", action="store_true",
                   help="overwrite an existing --json file or report DIR")
    p.set_defaults(run=run)


def _from_files(paths: list[str], dataset: Dataset) -> pipeline.Solutions:
    """Read and check each solution file (any format of docs/solution-format.md); the notes
    on what was converted go to stderr."""
    from simulator.scoring.readers import check_solution, read_solution_file

    gps = dataset.manifest.get("gps_time_start") or {"week": 0, "tow": 0.0}
    truth = dataset.read("truth")
    out: pipeline.Solutions = {}
    for path in paths:
        label = Path(path).stem
        if label in out:
            raise InputError([Problem(path, None, "", f"another solution file is also labelled "
                                      f"{label!r} (labels are file stems); rename one")])
        frame, notes, uses_gnss = read_solution_file(path, (gps["week"], gps["tow"]))
        check_solution(path, frame, truth)
        for note in notes:
            print(f"note: {note}", file=sys.stderr)
        out[label] = (frame, {"uses_gnss": uses_gnss})
    return out


def run(args: argparse.Namespace) -> int:
    from simulator import pipeline
    from simulator.dataset.io import open_dataset
    from simulator.outputs import atomic_output_dir
    from simulator.scoring.evaluate import write_scores
    from simulator.scoring.report import print_scores

    if not args.solution and not args.estimator:
        raise InputError([Problem(args.dataset, None, "", "nothing to score: give --solution "
                                  "FILE... and/or -e NAME...")])
    dataset = open_dataset(args.dataset)
    inputs = [dataset.path, *args.solution]
    with contextlib.ExitStack() as stack:
        report_dir = (stack.enter_context(atomic_output_dir(Path(args.report), args.force,
                                                            inputs))
                      if args.report else None)
        solutions = _from_files(args.solution, dataset)
        for label, solved in pipeline.run_estimators(dataset, dict.fromkeys(args.estimator),
                                                     show_progress=True).items():
            if label in solutions:
                raise InputError([Problem(args.dataset, None, "", f"label {label!r} is both a "
                                          "solution file's stem and an estimator's name")])
            solutions[label] = solved
        ev = pipeline.score(dataset, solutions)
        if dataset.manifest.get("reference") is True:
            print(f"scored against a reference, not an exact truth: "
                  f"{dataset.manifest.get('reference_source', 'the recording reference')}")
        print_scores(ev)
        if report_dir is not None:  # first: a report that fails (a full disk) leaves no JSON
            pipeline.write_report(report_dir, ev, f"Scores on {dataset.path.name}")
        if args.json:
            write_scores(ev.scores(), Path(args.json), args.force, inputs)
            print(f"wrote {args.json}")
    if args.report:
        print(f"wrote {Path(args.report) / 'report.md'} and report.html")
    return 0
