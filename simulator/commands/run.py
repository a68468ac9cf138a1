"""``landnav run SCENARIO [-o DIR]``: the main job. Generate the dataset, run every estimator the
scenario names, score them and write the report, all into one directory written atomically:
``DIR/dataset/``, ``DIR/solutions/LABEL.parquet``, ``DIR/scores.json``, ``DIR/report.md`` with
``DIR/plots/``, and ``DIR/report.html`` (the same report, plots embedded)."""

from __future__ import annotations

import argparse
from pathlib import Path

from simulator.commands import SUMMARIES
from simulator.commands.options import add_scenario_options


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run", help=SUMMARIES["run"],
        description="The main job: generate the scenario's dataset into DIR/dataset/, run every "
                    "estimator the scenario names over it (causally), write their solutions to "
                    "DIR/solutions/LABEL.parquet, the scores to DIR/scores.json (keyed by label)"
                    ", DIR/report.md with its plots and DIR/report.html (the same report in "
                    "one self-contained page, plots embedded: open it in a browser). DIR is "
                    "written under a temporary name "
                    "and renamed when complete; an existing DIR is kept unless --force.")
    p.add_argument("scenario", metavar="SCENARIO", help="YAML scenario file")
    p.add_argument("-o", "--output", metavar="DIR",
                   help="run directory (default: runs/<scenario name>)")
    p.add_argument("--force", action="store_true", help="overwrite an existing DIR")
    p.add_argument("--time-limit", type=float, default=None, metavar="SECONDS",
                   help="how long each estimator may take to run (default: no limit; it "
                        "then runs in its own process, as every estimator that is not a "
                        "built-in does), and the plug-ins to be imported and checked "
                        "(default 120 s); past it the run stops with exit 2 and writes nothing")
    p.add_argument("--no-plots", dest="plots", action="store_false",
                   help="write the report's tables without its plots (drawing them is about "
                        "a third of a short run; for batches of runs read by scripts)")
    add_scenario_options(p)
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from simulator import pipeline
    from simulator.commands.options import check_time_limit
    from simulator.scoring.report import print_scores

    check_time_limit(args.time_limit, "run")
    scenario = pipeline.load_scenario(args.scenario, args.overrides, args.seed)
    out = Path(args.output) if args.output else Path("runs") / scenario.name
    result = pipeline.run(scenario, out, args.force, show_progress=True,
                          time_limit_s=args.time_limit, plots=args.plots)
    if scenario.data["estimators"]:
        print_scores(result.evaluation)
    else:
        print("no estimator was named in the scenario; the dataset and report were written")
    print(f"wrote {out} ({scenario.name}, seed {scenario.seed}): dataset/, "
          f"{len(result.evaluation.results)} solution(s), scores.json, report.md, "
          "report.html")
    return 0
