"""``landnav run SCENARIO [-o DIR]``: the main job. Generate the dataset, run every estimator the
scenario names, score them and write the report, all into one directory written atomically:
``DIR/dataset/``, ``DIR/solutions/LABEL.parquet``, ``DIR/scores.json``, ``DIR/report.md`` and
``DIR/plots/``."""

from __future__ import annotations

import argparse
from pathlib import Path

from simulator.commands import SUMMARIES
from simulator.commands.options import add_scenario_options
from simulator.commands.score import print_scores
from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import open_dataset
from simulator.errors import InputError, Problem
from simulator.outputs import atomic_output_dir
from simulator.replay import run_estimator, write_solution
from simulator.scenario import load_scenario
from simulator.scoring.evaluate import score_solutions, write_scores
from simulator.scoring.report import write_report

NO_ESTIMATOR = ("No estimator was named in the scenario (its `estimators:` list is empty): the "
                "dataset was generated and nothing was scored.")


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run", help=SUMMARIES["run"],
        description="The main job: generate the scenario's dataset into DIR/dataset/, run every "
                    "estimator the scenario names over it (causally), write their solutions to "
                    "DIR/solutions/LABEL.parquet, the scores to DIR/scores.json (keyed by label)"
                    " and DIR/report.md with its plots. DIR is written under a temporary name "
                    "and renamed when complete; an existing DIR is kept unless --force.")
    p.add_argument("scenario", metavar="SCENARIO", help="YAML scenario file")
    p.add_argument("-o", "--output", metavar="DIR",
                   help="run directory (default: runs/<scenario name>)")
    p.add_argument("--force", action="store_true", help="overwrite an existing DIR")
    add_scenario_options(p)
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    scenario = load_scenario(args.scenario, args.overrides, args.seed)
    out = Path(args.output) if args.output else Path("runs") / scenario.name
    entries = scenario.data["estimators"]
    with atomic_output_dir(out, args.force) as tmp:
        dataset = open_dataset(generate_dataset(scenario, tmp / "dataset"))
        (tmp / "solutions").mkdir()
        solutions = {}
        for i, entry in enumerate(entries):
            frame, info = run_estimator(dataset, entry)
            label = info["label"]
            if Path(label).name != label or label.startswith("."):
                raise InputError([Problem(str(scenario.path), None, f"estimators.{i}.label",
                                          f"{label!r} cannot name a file; give a plain label")])
            write_solution(frame, tmp / "solutions" / f"{label}.parquet",
                           uses_gnss=info["uses_gnss"])
            solutions[label] = (frame, info)
        ev = score_solutions(dataset, solutions)
        write_scores(ev.scores(), tmp / "scores.json")
        write_report(tmp, ev, f"{scenario.name} (seed {scenario.seed})",
                     note=None if entries else NO_ESTIMATOR)
    if entries:
        print_scores(ev)
    else:
        print("no estimator was named in the scenario; the dataset and report were written")
    print(f"wrote {out} ({scenario.name}, seed {scenario.seed}): dataset/, "
          f"{len(solutions)} solution(s), scores.json, report.md")
    return 0
