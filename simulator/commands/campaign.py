"""``landnav campaign SCENARIO --runs N -o DIR``: Monte Carlo over seeds (and sweep points) of
the scenario's estimators, in local processes or on a Dask cluster; resumable.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from simulator.commands import SUMMARIES
from simulator.commands.options import add_scenario_options, check_time_limit, worker_problems
from simulator.errors import InputError, Problem


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "campaign", help=SUMMARIES["campaign"],
        description="Monte Carlo campaign: for run i = 0..N-1 (seed BASE + i) and every sweep "
                    "point, generate the dataset in a temporary folder, run every estimator the "
                    "scenario names and score it. Writes DIR/runs.parquet (one row per run and "
                    "estimator: run_id, seed, label, status, the swept keys, the flattened "
                    "scores, error), DIR/summary.json (mean, median, p95 of each score and the "
                    "failure count per label and sweep point) and DIR/report.md with plots. "
                    "Each finished run is recorded in DIR/parts/ at once: rerunning the same "
                    "command (or with a larger --runs) resumes, computing only what is missing. "
                    "A failing run is recorded as failed with its traceback and the campaign "
                    "goes on.")
    p.add_argument("scenario", metavar="SCENARIO", help="YAML scenario file")
    p.add_argument("--runs", type=int, required=True, metavar="N", help="number of seeds")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="campaign directory")
    p.add_argument("--workers", type=int, default=None, metavar="K",
                   help="local worker processes (default: the CPU count)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on the Dask cluster of this scheduler (tcp://host:port) instead of "
                        "local processes; its workers need landnav, any module:Class estimator "
                        "and the files the scenario refers to")
    p.add_argument("--scheduler-timeout", type=float, default=10.0, metavar="SECONDS",
                   help="how long to try to reach the scheduler (default 10)")
    p.add_argument("--sweep", action="append", default=[], metavar="KEY.PATH=V1,V2,...",
                   help="also vary a scenario value (the key paths of --set); repeat for the "
                        "cartesian product. Run i has the same seed at every sweep point.")
    p.add_argument("--force", action="store_true",
                   help="start over: replace the campaign in DIR even if it is another one "
                        "(a folder that is not a campaign is never replaced)")
    p.add_argument("--keep-datasets", action="store_true",
                   help="keep each run's dataset in DIR/datasets/ (deleted after scoring "
                        "otherwise)")
    p.add_argument("--retry-failed", action="store_true",
                   help="when resuming, compute the failed runs again")
    p.add_argument("--time-limit", type=float, default=None, metavar="SECONDS",
                   help="how long each estimator of a run may take; past it the run's row "
                        "fails and the campaign goes on (default: no limit); also the bound on "
                        "importing and checking the plug-ins before the runs (default 120 s)")
    add_scenario_options(p)
    p.set_defaults(run=run)


MAX_RUNS = 1_000_000  # seeds per sweep point one campaign plans (its task list is in memory)
MAX_SCHEDULER_TIMEOUT_S = 3600.0


def _check_counts(args: argparse.Namespace) -> int:
    """The number of local workers; refuses N < 1, K < 1 and --workers with --scheduler."""
    problems = []
    if not 1 <= args.runs <= MAX_RUNS:
        problems.append(Problem("landnav campaign", None, "--runs",
                                f"must be between 1 and {MAX_RUNS:,}, got {args.runs:,}; "
                                "split a larger study into campaigns"))
    problems += worker_problems("campaign", args.workers, args.scheduler)
    if not 0 < args.scheduler_timeout <= MAX_SCHEDULER_TIMEOUT_S:  # nan and inf included
        problems.append(Problem("landnav campaign", None, "--scheduler-timeout",
                                f"must be a number of seconds in (0, "
                                f"{MAX_SCHEDULER_TIMEOUT_S:g}], got {args.scheduler_timeout}"))
    if problems:
        raise InputError(problems)
    return args.workers or os.cpu_count() or 1


def run(args: argparse.Namespace) -> int:
    from simulator.campaign.campaign import CampaignOptions, run_campaign
    from simulator.campaign.plan import plan_campaign

    workers = _check_counts(args)
    check_time_limit(args.time_limit, "campaign")
    plan = plan_campaign(args.scenario, args.overrides, args.seed, args.sweep, args.time_limit)
    options = CampaignOptions(
        runs=args.runs, workers=workers, scheduler=args.scheduler,
        scheduler_timeout_s=args.scheduler_timeout, force=args.force,
        keep_datasets=args.keep_datasets, retry_failed=args.retry_failed,
        time_limit_s=args.time_limit)
    out = Path(args.output)
    result = run_campaign(plan, out, options)  # SIGTERM and Ctrl-C: the CLI's handlers
    n_runs = len(result.runs) // max(1, len(plan.labels))
    print(f"campaign {plan.base.name}: {n_runs} run(s) x {len(plan.labels)} estimator(s): "
          f"{result.ok} result(s) ok, {result.failed} failed "
          f"({result.computed} run(s) computed now, "
          f"{result.skipped} already done); results in {out}/ (runs.parquet, summary.json, "
          "report.md)")
    return 0
