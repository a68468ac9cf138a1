"""``landnav reproduce [PAPER...] -o DIR``: run the seed papers' experiments over seeds, judge
every claim, write report.md and a self-contained report.html (``simulator.reproduce``)."""

from __future__ import annotations

import argparse
import os
import textwrap
from pathlib import Path

from simulator.commands import SUMMARIES
from simulator.commands.options import worker_problems
from simulator.errors import InputError, Problem
from simulator.reproduce import FULL_SEEDS, QUICK_SEEDS
from simulator.reproduce.papers import load_paper, paper_keys

MAX_RUNS = 1000  # seeds per experiment


def _papers_help() -> str:
    lines = []
    for key in paper_keys():
        try:
            paper = load_paper(key)
        except InputError:  # an installation without the shipped scenarios: named, not listed
            lines.append(f"  {key:12s} (its scenarios are not installed: run from a checkout)")
            continue
        scenarios = sorted({e.scenario for e in paper.experiments})
        lines.append(f"  {key:12s} {paper.title}")
        for name, items in (("claims", [c.key for c in paper.claims]),
                            ("scenarios", scenarios)):
            lines.append(textwrap.fill(f"{name}: {', '.join(items)}", 78,
                                       initial_indent=" " * 15, subsequent_indent=" " * 17))
    return "\n".join(lines)


class _ListPapers(argparse.Action):
    """``--list``: print every paper's title, claims and scenarios and exit, as ``--help``
    does (it imports the paper modules, so it is not part of ``--help``)."""

    def __init__(self, option_strings: list[str], dest: str, **kwargs) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser: argparse.ArgumentParser, *args) -> None:
        print(_papers_help())
        parser.exit()


def _wrap(text: str) -> str:
    """Each paragraph of ``text`` filled to 78 columns; indented lines kept as they are."""
    return "\n\n".join(p if p.startswith(("  ", "Examples")) else textwrap.fill(p, 78)
                       for p in text.split("\n\n"))


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "reproduce", help=SUMMARIES["reproduce"],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=_wrap(
            "Reproduce the seed papers' claims. Each paper's experiments (a shipped scenario "
            "and the estimators the paper compares) run over seeds 1..N; every estimator "
            "replays the same dataset of a seed, so comparisons are paired per seed. Every "
            "claim is then judged from the figures over seeds with one word (shown, partly, "
            "not shown) and the reason, beside the paper's own figure and the conditions that "
            "differ.\n\n"
            "Each word follows from the per-seed values by one rule: shown when the "
            "one-sided sign test in the paper's direction gives p < 0.05 and the magnitude "
            "the paper prints (if any) is met, partly when only the magnitude is not, not "
            "shown otherwise; the papers' claims and landnav's own checks are counted apart."
            "\n\n"
            "Writes DIR/report.md (with DIR/plots/), DIR/report.html (self-contained: plots "
            "embedded), DIR/results.json (every claim's per-seed values, evidence and word; "
            "tools/recompute_verdicts.py recomputes the words from it), "
            "DIR/figures/PAPER/EXPERIMENT.parquet (index seed, one column per "
            "figure) and DIR/failures.parquet when a run failed (the others go on; the report "
            "names the seed and the error). Nothing is written until the run is complete.\n\n"
            f"Papers (all when none is named): {', '.join(paper_keys())}; `landnav "
            "reproduce --list` shows each one's claims and scenarios.\n\n"
            "Examples:\n"
            "  landnav reproduce --quick -o out/repro          every paper, 3 seeds, short "
            "drives\n"
            "  landnav reproduce cho2006 tan2008 --runs 10 --workers 2 -o out/repro-ct\n"
            "  landnav reproduce park2019 --scheduler tcp://10.0.0.5:8786 -o out/park"))
    p.add_argument("--list", action=_ListPapers,
                   help="list every paper with its title, claims and scenarios, and exit")
    p.add_argument("papers", nargs="*", metavar="PAPER",
                   help="paper keys (default: every registered paper)")
    p.add_argument("--runs", type=int, default=None, metavar="N",
                   help=f"seeds 1..N per experiment (default {FULL_SEEDS}; {QUICK_SEEDS} with "
                        "--quick); without --quick an experiment whose verdicts sit at an "
                        "edge runs more (its full_runs, e.g. 20), and a claim whose sign-test "
                        "p after N seeds lies in [0.05, 0.2) has the experiments it reads run "
                        "again up to 2N seeds")
    p.add_argument("--quick", action="store_true",
                   help="shortened drives (each experiment's quick overrides) and 3 seeds "
                        "unless --runs says otherwise, and no variant (a claim judged again "
                        "under another value of a deciding condition) nor the experiments "
                        "only variants read, nor the checks of entries left to the full run "
                        "(Karamat's ablation variants): a check in minutes, not the paper's "
                        "full protocol")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="report folder")
    p.add_argument("--workers", type=int, default=None, metavar="W",
                   help="local worker processes (default: the CPU count)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on the Dask cluster of this scheduler (tcp://host:port) instead of "
                        "local processes; its workers need landnav and its scenarios/")
    p.add_argument("--force", action="store_true",
                   help="replace DIR if it exists and is not empty")
    p.set_defaults(run=run)


def _check(args: argparse.Namespace) -> int:
    """The number of local workers; refuses unknown papers, N and W out of range, --workers
    with --scheduler."""
    problems = []
    known = paper_keys()
    for key in args.papers:
        if key not in known:
            problems.append(Problem("landnav reproduce", None, "PAPER",
                                    f"unknown paper {key!r}; known: {', '.join(known)}"))
    if args.runs is not None and not 1 <= args.runs <= MAX_RUNS:
        problems.append(Problem("landnav reproduce", None, "--runs",
                                f"must be between 1 and {MAX_RUNS}, got {args.runs}"))
    problems += worker_problems("reproduce", args.workers, args.scheduler)
    if problems:
        raise InputError(problems)
    return args.workers or os.cpu_count() or 1


def run(args: argparse.Namespace) -> int:
    from simulator.reproduce.paper import STATUSES
    from simulator.reproduce.results import UNTESTABLE
    from simulator.reproduce.runner import reproduce

    workers = _check(args)
    out = Path(args.output)
    empty_dir = out.is_dir() and not out.is_symlink() and not any(out.iterdir())
    results = reproduce(args.papers, args.runs, args.quick, out, workers, args.scheduler,
                        show_progress=True, force=args.force or empty_dir)
    for r in results:
        failed = sum(len(e.failures) for e in r.experiments.values())
        parts = []
        for kind, name in (("paper", "paper claims"), ("check", "checks")):
            words = [UNTESTABLE if c.untestable else r.verdicts[c.key].status
                     for c in r.paper.claims if c.kind == kind and not c.variant_of]
            counts = ", ".join(f"{words.count(w)} {w}" for w in (*STATUSES, UNTESTABLE)
                               if words.count(w))
            parts.append(f"{len(words)} {name}" + (f" ({counts})" if counts else ""))
        print(f"{r.paper.key}: {'; '.join(parts)}"
              + (f"; {failed} run(s) failed" if failed else ""))
    print(f"report: {out / 'report.md'}, {out / 'report.html'} and {out / 'results.json'}")
    return 0
