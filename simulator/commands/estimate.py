"""``landnav estimate DATASET -e NAME -o SOLUTION.parquet``: run one estimator over a dataset."""

from __future__ import annotations

import argparse

from simulator.commands import SUMMARIES
from simulator.errors import InputError, Problem


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "estimate", help=SUMMARIES["estimate"],
        description="Replay a dataset into one estimator, message by message in time order "
                    "(the estimator never sees the truth), and write its solution as Parquet "
                    "(docs/solution-format.md). The estimator starts from the truth at its first "
                    "message, perturbed by --init errors (unless it initialises itself).")
    p.add_argument("dataset", metavar="DATASET", help="dataset directory (landnav generate)")
    p.add_argument("-e", "--estimator", required=True, metavar="NAME",
                   help="registered name (see `landnav estimators`) or module:Class")
    p.add_argument("-o", "--output", required=True, metavar="SOLUTION.parquet",
                   help="solution file to write")
    p.add_argument("--set", dest="config", action="append", default=[], metavar="KEY=VALUE",
                   help="estimator config key, value read as YAML, e.g. --set nhc=true "
                        "(repeatable)")
    p.add_argument("--init", action="append", default=[], metavar="KEY=VALUE",
                   help="initial error: position_error=[n,e,d] (m), velocity_error=[n,e,d] "
                        "(m/s), attitude_error=[roll,pitch,yaw] (deg), heading_error=DEG")
    p.add_argument("--label", default=None, help="solution label (default: the name)")
    p.add_argument("--force", action="store_true", help="overwrite an existing SOLUTION file")
    p.add_argument("--time-limit", type=float, default=None, metavar="SECONDS",
                   help="stop the estimator after this long (it then runs in its own process, "
                        "as every estimator that is not a built-in does) and exit 2; also the "
                        "bound on importing and checking a plug-in (default 120 s)")
    p.set_defaults(run=run)


def _pairs(items: list[str], option: str) -> dict:
    from simulator.scenario.yamlio import load_value

    out: dict = {}
    problems = []
    for text in items:
        key, sep, raw = text.partition("=")
        if not sep or not key.strip():
            problems.append(Problem(option, None, text, "expected key=value"))
            continue
        out[key.strip()] = load_value(raw, f"{option} {key.strip()}")
    if problems:
        raise InputError(problems)
    return out


def _entry(args: argparse.Namespace) -> dict:
    """The command-line options as a scenario estimator entry, validated like one (a plug-in
    imported and checked in a child process, within ``--time-limit``)."""
    from simulator.isolated import check_entries
    from simulator.scenario.spec import ESTIMATOR_ENTRY_FIELD
    from simulator.schema import INVALID, Context

    given = {"name": args.estimator, "label": args.label,
             "init": _pairs(args.init, "--init") or None,
             "config": _pairs(args.config, "--set") or None}
    entry = {k: v for k, v in given.items() if v is not None}
    ctx = Context("command line")
    resolved = ESTIMATOR_ENTRY_FIELD.check(entry, ("estimator",), ctx)
    if ctx.problems or resolved is INVALID:
        raise InputError(ctx.problems)
    problems = [Problem("command line", None, f"estimator.{key}", message)
                for key, message in check_entries([resolved], args.time_limit)[0]]
    if problems:
        raise InputError(problems)
    return resolved


def run(args: argparse.Namespace) -> int:
    from simulator import pipeline
    from simulator.commands.options import check_time_limit
    from simulator.dataset.io import open_dataset
    from simulator.replay import write_solution

    check_time_limit(args.time_limit, "estimate")
    entry = _entry(args)
    dataset = open_dataset(args.dataset)
    solution, info = pipeline.estimate(dataset, entry, show_progress=True,
                                       time_limit_s=args.time_limit)
    write_solution(solution, args.output, args.force, [dataset.path],
                   uses_gnss=info["uses_gnss"])
    compiled = (f" (and {info['compile_s']:.1f} s compiling numba kernels, not counted)"
                if info["compile_s"] > 0 else "")
    print(f"wrote {args.output} ({info['label']}: {len(solution)} rows) in "
          f"{info['runtime_s']:.2f} s, {info['realtime_factor']:.0f} x real time{compiled}")
    return 0
