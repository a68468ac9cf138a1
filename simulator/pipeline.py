"""The library's entry points: the main job, scenario -> dataset -> solutions -> scores ->
report, as the functions a script or a notebook calls. ``landnav run``, ``landnav generate``,
``landnav estimate``, ``landnav score`` and the campaign worker are thin layers over these.

A notebook session::

    from simulator import pipeline

    scenario = pipeline.load_scenario("scenarios/quickstart.yaml", seed=3)
    dataset = pipeline.generate(scenario, "out/quick", force=True)
    solutions = pipeline.run_estimators(dataset, scenario.data["estimators"])
    evaluation = pipeline.score(dataset, solutions)
    evaluation.scores()                                  # keyed by label (SPEC section 8)
    pipeline.write_report("out/quick-report", evaluation, "quickstart")

or the whole job into one directory: ``pipeline.run(scenario, "runs/quick")``.

Public names
------------
load_scenario, check_estimators, estimator_problems, generate, estimate, run_estimators, score,
write_report, run, RunResult, Solutions.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from estimators.registry import entry_problems, name_problems
from simulator import scenario as scenarios
from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import Dataset, open_dataset
from simulator.errors import InputError, Problem
from simulator.html_report import write_html_report
from simulator.isolated import check_entries, needs_isolation, run_isolated
from simulator.outputs import atomic_output_dir
from simulator.replay import run_estimator, write_solution
from simulator.scenario import Scenario
from simulator.scoring import report
from simulator.scoring.evaluate import Evaluation, score_solutions, write_scores

__all__ = ["NO_ESTIMATOR", "RunResult", "Solutions", "check_estimators", "estimate",
           "estimator_problems", "generate",
           "load_scenario",
           "run", "run_estimators", "score", "write_report"]

# label -> (solution table, run information: label, name, runtime_s, realtime_factor; None for
# a solution read from a file)
Solutions = dict[str, tuple[pd.DataFrame, dict | None]]

NO_ESTIMATOR = ("No estimator was named in the scenario (its `estimators:` list is empty): the "
                "dataset was generated and nothing was scored.")


def load_scenario(path: str | Path, overrides: list[str] | None = None,
                  seed: int | None = None, import_plugins: bool = False,
                  time_limit_s: float | None = None) -> Scenario:
    """Read, override and validate a scenario file (``simulator.scenario.load_scenario``), then
    check each estimator entry against its class (``check_estimators``). An estimator that is
    not a built-in (the user's or a third party's code) is checked for its name only, and
    imported only with ``import_plugins`` (``run``, a campaign, ``validate --import-plugins``),
    then in a child process bounded by ``time_limit_s``: validating a scenario runs no code it
    names. Every problem is raised in one InputError."""
    scenario = scenarios.load_scenario(path, overrides, seed)
    check_estimators(scenario, import_plugins, time_limit_s)
    return scenario


def estimator_problems(scenario_list: Sequence[Scenario], import_plugins: bool = True,
                       time_limit_s: float | None = None) -> list[list[Problem]]:
    """The problems of each scenario's estimator entries: the class imports and its
    ``config`` fits the class's defaults. An entry that is not a built-in is imported only with
    ``import_plugins``, and then in one child process for all of them (equal entries checked
    once), which may take ``time_limit_s`` (``simulator.isolated.check_entries``); without,
    only its name is checked."""
    where = [(k, str(s.path), i) for k, s in enumerate(scenario_list)
             for i in range(len(s.data["estimators"]))]
    entries = [entry for s in scenario_list for entry in s.data["estimators"]]
    if import_plugins:
        checked = check_entries(entries, time_limit_s)
    else:
        checked = [name_problems(entry) if needs_isolation(entry, None)
                   else entry_problems(entry) for entry in entries]
    out: list[list[Problem]] = [[] for _ in scenario_list]
    for (k, path, i), found in zip(where, checked, strict=True):
        out[k] += [Problem(path, None, f"estimators.{i}.{key}", message)
                   for key, message in found]
    return out


def check_estimators(scenario: Scenario, import_plugins: bool = True,
                     time_limit_s: float | None = None) -> None:
    """Raise InputError with the problems of the scenario's estimator entries
    (``estimator_problems``)."""
    problems = estimator_problems([scenario], import_plugins, time_limit_s)[0]
    if problems:
        raise InputError(problems)


def generate(scenario: Scenario, out_dir: str | Path, force: bool = False,
             show_progress: bool = False, honour_lock: bool = True) -> Dataset:
    """Write a scenario's dataset into ``out_dir`` (atomically; an existing directory only with
    ``force``, and only one landnav wrote) and open it. ``honour_lock=False`` only for a
    campaign's run writing into the campaign's own folder."""
    return open_dataset(generate_dataset(scenario, Path(out_dir), force=force,
                                         show_progress=show_progress, honour_lock=honour_lock))


def estimate(dataset: Dataset, entry: Mapping[str, Any] | str,
             show_progress: bool = False, time_limit_s: float | None = None,
             isolate: bool = True) -> tuple[pd.DataFrame, dict]:
    """Replay ``dataset`` causally into one estimator (a scenario ``estimators:`` entry: a name,
    ``module:Class``, or a mapping with ``name``, ``label``, ``init`` and ``config``); its
    solution table and run information (``simulator.replay.run_estimator``).

    An estimator that is not a built-in, or any with ``time_limit_s``, runs in a child process
    (``simulator.isolated``): one that exits, crashes or runs past the limit is an InputError.
    ``isolate=False`` runs it here: a local campaign worker, itself a process of its own whose
    death fails only its run, bounds it with its own timer (``simulator.campaign.worker``)."""
    if isolate and needs_isolation(entry, time_limit_s):
        return run_isolated(dataset.path, entry, time_limit_s)
    return run_estimator(dataset, entry, show_progress=show_progress)


def run_estimators(dataset: Dataset, entries: Iterable[Mapping[str, Any] | str],
                   show_progress: bool = False, time_limit_s: float | None = None
                   ) -> Solutions:
    """Every estimator entry over ``dataset``, keyed by label; two entries with one label are
    refused (give a label)."""
    out: Solutions = {}
    for i, entry in enumerate(entries):
        frame, info = estimate(dataset, entry, show_progress, time_limit_s)
        if info["label"] in out:
            raise InputError(f"estimators.{i}: label {info['label']!r} is used twice; give a "
                             "label")
        out[info["label"]] = (frame, info)
    return out


def score(dataset: Dataset, solutions: Solutions) -> Evaluation:
    """Score solutions against the dataset's truth (SPEC section 8)."""
    return score_solutions(dataset, solutions)


def write_report(directory: str | Path, evaluation: Evaluation, title: str,
                 note: str | None = None, plots: bool = True) -> Path:
    """Write ``report.md`` (metrics, per-outage table) and its ``plots/`` (unless ``plots`` is
    false) into ``directory`` (made if missing), and ``report.html``, the same page with every
    plot embedded (``simulator.html_report``); the path of ``report.md``."""
    Path(directory).mkdir(parents=True, exist_ok=True)
    path = report.write_report(Path(directory), evaluation, title, note, plots)
    write_html_report(path)
    return path


@dataclass
class RunResult:
    """What ``run`` wrote into its directory: ``dataset/``, ``solutions/LABEL.parquet``,
    ``scores.json`` and ``report.md`` with ``plots/``."""

    directory: Path
    evaluation: Evaluation


def run(scenario: Scenario, out_dir: str | Path, force: bool = False,
        show_progress: bool = False, time_limit_s: float | None = None,
        plots: bool = True) -> RunResult:
    """The main job into one directory, written under a temporary name and renamed when
    complete: the dataset, every estimator the scenario names, their solutions, the scores and
    the report (with its plots unless ``plots`` is false). A label that cannot name a file is
    refused before anything is written; each estimator (its import and check, then its
    replay) may take ``time_limit_s`` (``estimate``).
    """
    out = Path(out_dir)
    entries = scenario.data["estimators"]
    # the run imports them anyway: before anything is written
    check_estimators(scenario, time_limit_s=time_limit_s)
    with atomic_output_dir(out, force, scenario.input_files) as tmp:
        dataset = generate(scenario, tmp / "dataset", show_progress=show_progress)
        (tmp / "solutions").mkdir()
        solutions = run_estimators(dataset, entries, show_progress, time_limit_s)
        for i, label in enumerate(solutions):
            if Path(label).name != label or label.startswith("."):
                raise InputError([Problem(str(scenario.path), None, f"estimators.{i}.label",
                                          f"{label!r} cannot name a file; give a plain label")])
            write_solution(solutions[label][0], tmp / "solutions" / f"{label}.parquet",
                           uses_gnss=solutions[label][1]["uses_gnss"])
        evaluation = score(dataset, solutions)
        write_scores(evaluation.scores(), tmp / "scores.json")
        write_report(tmp, evaluation, f"{scenario.name} (seed {scenario.seed})",
                     note=None if entries else NO_ESTIMATOR, plots=plots)
    return RunResult(out, evaluation)
