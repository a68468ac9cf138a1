"""Reproduce papers: every experiment of every paper over seeds, on the campaign executor (local
processes or a Dask scheduler, ``simulator.campaign.execute``), then every claim judged and the
report written.

One task is one (paper, experiment, seed): the seed's dataset is generated in a temporary folder,
every entry of the experiment replays it (``simulator.pipeline.estimate``), the experiment's
``measure`` turns the solutions into that seed's figures, and the dataset is deleted. A task that
raises is recorded with its seed and error and the others go on; a claim whose figures are
missing is judged on the seeds that have them (and says so).

A full run (not ``--quick``) is made in two stages, by a rule fixed before any figure is seen:
after the run's seeds every claim is judged, and a claim whose sign-test p lies in
[``ALPHA``, ``EDGE_P``) sits at an edge (at ten seeds: 7 or 8 in the paper's direction); the
experiments it reads are run again on further seeds, up to ``EDGE_SEEDS_FACTOR`` times the run's
(twenty at ten), and every claim is judged on all of them. A verdict is never read at a stage
and then kept from it: the words are those of the final tables.

The output folder (written under a temporary name and renamed when complete,
``simulator.outputs.atomic_output_dir``)::

    DIR/report.md, DIR/report.html
    DIR/results.json                        every claim: kind, statement, conditions, per-seed
                                            values, evidence, verdict (simulator.reproduce.results)
    DIR/figures/PAPER/EXPERIMENT.parquet   index seed, one column per figure
    DIR/figures/PAPER/EXPERIMENT.history.parquet   the first seed's time histories
    DIR/failures.parquet                    paper, experiment, seed, error (failed tasks only)

Public names
------------
Settings, ExperimentResult, PaperResult, run_experiment, reproduce, judge, ruled, seeds_of,
edge_experiments, QUICK_SEEDS, FULL_SEEDS, EDGE_P, EDGE_SEEDS_FACTOR.
"""

from __future__ import annotations

import math
import platform
import subprocess
import tempfile
import time
import traceback
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as dist_version
from pathlib import Path

import pandas as pd

from simulator.campaign.execute import completed, open_executor
from simulator.outputs import atomic_output_dir
from simulator.pipeline import estimate, generate, load_scenario
from simulator.progress import progress
from simulator.reproduce import FULL_SEEDS, QUICK_SEEDS
from simulator.reproduce.evidence import ALPHA, verdict_word
from simulator.reproduce.paper import SCENARIO_DIR, Experiment, Paper, Verdict, scenario_path
from simulator.reproduce.papers import load_paper, paper_keys
from simulator.reproduce.report import write_report
from simulator.reproduce.results import RESULTS_FILE, write_results

__all__ = ["EDGE_P", "EDGE_SEEDS_FACTOR", "FULL_SEEDS", "QUICK_SEEDS", "ExperimentResult",
           "PaperResult", "Settings", "edge_experiments", "judge", "on_common_seeds", "reproduce",
           "ruled", "run_experiment", "seeds_of"]

SCHEDULER_TIMEOUT_S = 10.0
EDGE_P = 0.2  # a verdict with ALPHA <= sign-test p < EDGE_P after the run's seeds is at an edge
EDGE_SEEDS_FACTOR = 2  # an edge claim's experiments run again up to this times the run's seeds


def seeds_of(runs: int) -> list[int]:
    """The seeds of a run: 1..runs."""
    return list(range(1, runs + 1))


def experiment_seeds(experiment: Experiment, seeds: Sequence[int], quick: bool) -> list[int]:
    """The seeds an experiment runs: the run's, or 1..``experiment.full_runs`` without
    ``quick`` when that is more (an experiment whose verdicts sit at an edge)."""
    if quick or not experiment.full_runs or experiment.full_runs <= len(seeds):
        return list(seeds)
    return seeds_of(experiment.full_runs)


def experiment_overrides(experiment: Experiment, quick: bool,
                         extra: Sequence[str] = ()) -> list[str]:
    """The --set overrides of an experiment: its own, then the quick ones, then ``extra``."""
    return [*experiment.overrides, *(experiment.quick_overrides if quick else ()), *extra]


def measure_seed(experiment: Experiment, seed: int, overrides: Sequence[str],
                 work: Path, with_history: bool = False
                 ) -> tuple[dict[str, float], pd.DataFrame | None]:
    """One seed of an experiment in-process: generate the dataset under ``work``, replay every
    entry, measure, delete the dataset; the seed's figures and, when ``with_history`` and the
    experiment has one, its time histories (``Experiment.history``)."""
    scenario = load_scenario(scenario_path(experiment.scenario), list(overrides), seed)
    with tempfile.TemporaryDirectory(dir=work, prefix=f"{experiment.key}-{seed}-") as tmp:
        dataset = generate(scenario, Path(tmp) / "dataset")
        solutions = {label: estimate(dataset, {**entry, "label": label})[0]
                     for label, entry in experiment.entries.items()}
        figures = {name: math.nan if value is None else float(value)  # None: scorer's "none"
                   for name, value in experiment.measure(dataset, solutions).items()}
        history = (experiment.history(dataset, solutions)
                   if with_history and experiment.history is not None else None)
        return figures, history


def run_experiment(experiment: Experiment, seeds: Sequence[int], work: Path,
                   quick: bool = False, extra_overrides: Sequence[str] = ()) -> pd.DataFrame:
    """An experiment over ``seeds`` in this process (the claim tests use it): a table with index
    ``seed`` and one column per figure. Errors propagate."""
    overrides = experiment_overrides(experiment, quick, extra_overrides)
    rows = {seed: measure_seed(experiment, seed, overrides, work)[0] for seed in seeds}
    return _table(rows)


def _table(rows: Mapping[int, Mapping[str, float]]) -> pd.DataFrame:
    table = pd.DataFrame.from_dict(dict(rows), orient="index").sort_index()
    table.index.name = "seed"
    return table


@dataclass(frozen=True)
class _Task:
    paper: str
    experiment: str
    seed: int
    overrides: tuple[str, ...]
    with_history: bool = False
    quick: bool = False  # the experiment as --quick runs it (``Paper.quick``)


def _execute(task: _Task) -> tuple[tuple[dict[str, float], pd.DataFrame | None] | None,
                                   str | None, float]:
    """A task on a worker: ((figures, history), None, CPU seconds) or (None, the error's
    traceback, CPU seconds)."""
    start = time.process_time()
    try:
        paper = load_paper(task.paper).quick() if task.quick else load_paper(task.paper)
        experiment = next(e for e in paper.experiments if e.key == task.experiment)
        with tempfile.TemporaryDirectory(prefix="landnav-reproduce-") as work:
            result = measure_seed(experiment, task.seed, task.overrides, Path(work),
                                  task.with_history)
        return result, None, time.process_time() - start
    except Exception:  # reported per seed in the report, the run goes on
        return None, traceback.format_exc(limit=8), time.process_time() - start


@dataclass
class ExperimentResult:
    """An experiment's figures over seeds and its failed seeds (seed -> error)."""

    experiment: Experiment
    table: pd.DataFrame
    failures: dict[int, str] = field(default_factory=dict)
    history: pd.DataFrame | None = None  # the first seed's time histories (Experiment.history)


@dataclass
class PaperResult:
    """A paper, its experiments' results and the verdict on each claim (claim key ->; an
    untestable claim has none)."""

    paper: Paper
    experiments: dict[str, ExperimentResult]
    verdicts: dict[str, Verdict]


@dataclass(frozen=True)
class Settings:
    """What the report says about the run."""

    seeds: tuple[int, ...]
    quick: bool
    workers: int | None
    scheduler: str | None
    wall_time_s: float
    cpu_time_s: float
    version: str


def judge(paper: Paper, tables: Mapping[str, pd.DataFrame]) -> dict[str, Verdict]:
    """Every testable claim of a paper judged on the tables of the experiments it reads
    (``Claim.experiments``); a judge that raises
    (figures missing because seeds failed) gives ``not shown`` with the error as its reason,
    and a word that does not follow from its evidence by the rule is replaced by the rule's
    (``ruled``)."""
    out = {}
    for claim in paper.claims:
        if claim.judge is None:
            continue
        try:
            verdict = claim.judge(on_common_seeds({e.key: tables[e.key]
                                                   for e in paper.read_by(claim)
                                                   if e.key in tables}))
            # an untestable claim's judge gives landnav's figure only: no evidence, no word
            out[claim.key] = (replace(verdict, status="not shown", evidence=None,
                                      magnitude=None, compared=())
                              if claim.untestable else ruled(verdict))
        except Exception as exc:  # noqa: BLE001 - the report says why, the others are judged
            out[claim.key] = Verdict("not shown", "no figure",
                                     f"could not be judged: {type(exc).__name__}: {exc}")
    return out


def on_common_seeds(tables: Mapping[str, pd.DataFrame]) -> dict[str, pd.DataFrame]:
    """``tables`` (index: seed) restricted to the seeds they all have: a claim that pairs the
    figures of two experiments pairs them seed by seed, and the second stage may have run one of
    them on further seeds (``edge_experiments``)."""
    if len(tables) < 2:
        return dict(tables)
    indexes = [table.index for table in tables.values()]
    common = indexes[0]
    for index in indexes[1:]:
        common = common.intersection(index)
    return {key: table[table.index.isin(common)] for key, table in tables.items()}


def edge_experiments(paper: Paper, verdicts: Mapping[str, Verdict]) -> set[str]:
    """The keys of ``paper``'s experiments read by a claim whose verdict sits at an edge: its
    one-sided sign test's p in [``ALPHA``, ``EDGE_P``), where more seeds can decide the word."""
    keys: set[str] = set()
    for claim in paper.claims:
        verdict = verdicts.get(claim.key)
        evidence = verdict.evidence if verdict is not None else None
        if evidence is not None and ALPHA <= evidence.p_sign < EDGE_P:
            keys.update(e.key for e in paper.read_by(claim))
    return keys


def ruled(verdict: Verdict) -> Verdict:
    """``verdict`` if its word is the one the documented rule gives on its evidence
    (``evidence.verdict_word``; without evidence only "not shown" follows), else the rule's
    word with the judge's in the reason."""
    e, magnitude = verdict.evidence, verdict.magnitude
    word = verdict_word(e, magnitude_ok=magnitude.holds(e) if e and magnitude else None)
    if word == verdict.status:
        return verdict
    why = ("it has no per-seed evidence" if e is None
           else "it does not follow from its evidence")
    return replace(verdict, status=word, reason=f"{verdict.reason} [the judge's word "
                                                f"'{verdict.status}' is not the rule's: {why}]")


def version() -> str:
    """landnav's version and, in a git checkout, its commit."""
    try:
        text = f"landnav {dist_version('landnav')}"
    except PackageNotFoundError:
        text = "landnav (not installed)"
    try:
        commit = subprocess.run(["git", "-C", str(SCENARIO_DIR.parent), "rev-parse", "--short",
                                 "HEAD"], capture_output=True, text=True, timeout=10,
                                check=True).stdout.strip()
        text += f", commit {commit}"
    except (OSError, subprocess.SubprocessError):
        pass
    return f"{text}, Python {platform.python_version()}"


def reproduce(papers: Sequence[str], runs: int | None, quick: bool, out: Path | str,
              workers: int, scheduler: str | None = None, show_progress: bool = False,
              force: bool = False) -> list[PaperResult]:
    """Reproduce ``papers`` (keys of ``simulator.reproduce.papers.PAPERS``; all when empty) over
    seeds 1..``runs`` (default 10, or 3 with ``quick``, which also shortens each experiment's
    drive by its ``quick_overrides`` and runs no variant claim, ``Paper.quick``), on
    ``workers`` local processes or the Dask ``scheduler``; write the figures and the report
    into ``out`` (module docstring).

    Raises
    ------
    InputError
        An unknown paper, ``out`` existing without ``force``, a scheduler that does not answer,
        an installation without the shipped scenarios.
    """
    loaded = [load_paper(key) for key in (papers or paper_keys())]
    if quick:
        loaded = [paper.quick() for paper in loaded]
    for paper in loaded:  # a missing scenario stops the run before any worker starts
        for experiment in paper.experiments:
            scenario_path(experiment.scenario)
    seeds = seeds_of(runs or (QUICK_SEEDS if quick else FULL_SEEDS))
    tasks = [_Task(p.key, e.key, seed, tuple(experiment_overrides(e, quick)),
                   seed == seeds[0] and e.history is not None, quick)
             for p in loaded for e in p.experiments for seed in experiment_seeds(e, seeds, quick)]
    figures: dict[tuple[str, str], dict[int, dict[str, float]]] = {}
    histories: dict[tuple[str, str], pd.DataFrame] = {}
    failures: dict[tuple[str, str], dict[int, str]] = {}
    start, cpu = time.monotonic(), 0.0
    software = version()  # the code the tasks run: read before they start
    with atomic_output_dir(Path(out), force) as tmp:
        with open_executor(workers, scheduler, SCHEDULER_TIMEOUT_S) as (executor, in_flight):
            def run(batch: list[_Task], label: str) -> None:
                nonlocal cpu
                for task, future in progress(completed(executor, in_flight, _execute, batch),
                                             label, show_progress, total=len(batch)):
                    key = (task.paper, task.experiment)
                    try:
                        result, error, task_cpu = future.result()
                    except Exception as exc:  # a worker that died: this seed failed
                        result, error, task_cpu = None, f"{type(exc).__name__}: {exc}", 0.0
                    cpu += task_cpu
                    if result is None:
                        failures.setdefault(key, {})[task.seed] = error or "unknown error"
                    else:
                        figures.setdefault(key, {})[task.seed] = result[0]
                        if result[1] is not None:
                            histories[key] = result[1]

            run(tasks, "reproduce")
            further = []
            for paper in loaded if not quick else ():
                verdicts = judge(paper, {e.key: _table(figures.get((paper.key, e.key), {}))
                                         for e in paper.experiments})
                at_edge = edge_experiments(paper, verdicts)
                further += [_Task(paper.key, e.key, seed, tuple(experiment_overrides(e, quick)))
                            for e in paper.experiments if e.key in at_edge
                            for seed in seeds_of(EDGE_SEEDS_FACTOR * len(seeds))
                            if seed not in experiment_seeds(e, seeds, quick)]
            if further:
                run(further, "reproduce, further seeds where a verdict is at an edge")
        results = []
        for paper in loaded:
            experiments = {}
            for experiment in paper.experiments:
                key = (paper.key, experiment.key)
                table = _table(figures.get(key, {}))
                experiments[experiment.key] = ExperimentResult(
                    experiment, table, failures.get(key, {}), histories.get(key))
                path = tmp / "figures" / paper.key / f"{experiment.key}.parquet"
                path.parent.mkdir(parents=True, exist_ok=True)
                table.to_parquet(path)
                if key in histories:
                    histories[key].to_parquet(path.with_suffix(".history.parquet"))
            verdicts = judge(paper, {k: r.table for k, r in experiments.items()})
            results.append(PaperResult(paper, experiments, verdicts))
        failed = [{"paper": p, "experiment": e, "seed": s, "error": err}
                  for (p, e), per_seed in failures.items() for s, err in per_seed.items()]
        if failed:
            pd.DataFrame(failed).to_parquet(tmp / "failures.parquet")
        settings = Settings(tuple(seeds), quick, None if scheduler else workers, scheduler,
                            time.monotonic() - start, cpu, software)
        write_results(tmp / RESULTS_FILE, results, settings)
        write_report(tmp, results, settings)
    return results
