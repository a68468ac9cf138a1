"""One computation of each (experiment, seed) per test session, shared by the claim tests
(tests/estimators/) and the quick reproduction (tests/reproduce/test_reproduce_cli.py).

``cached_measure_seed`` stands in for ``simulator.reproduce.runner.measure_seed`` (the
``shared_experiments`` fixture of tests/conftest.py puts it there for the session): a seed of an
experiment is computed once, its figures and time histories stored in a folder that the
session's processes share (pytest-xdist's workers), and every later request for the same drive
(scenario, ``--set`` overrides, seed), estimator entries and measure reads them. A scenario and a
seed give identical files (the simulator's contract), so a stored seed is the seed recomputed.
A seed that raises is not stored. While one process computes a seed, another that needs it
waits for it (a lock file per seed) instead of computing it twice.

``cached_estimate`` stands in for the runner's ``estimate`` the same way, one level down: an
estimator entry's solution over a dataset is kept under a digest of the dataset's files and the
entry, so that experiments differing only in their entries (a claim test's three of a paper's
eight) replay each shared entry once."""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import hashlib
import json
import os
import pickle
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from simulator.dataset.io import Dataset
from simulator.reproduce.paper import Experiment

try:
    import fcntl
except ImportError:  # no POSIX file locks: a seed two processes need at once is computed twice
    fcntl = None

MeasureSeed = Callable[..., tuple[dict[str, float], pd.DataFrame | None]]
Estimate = Callable[..., tuple[pd.DataFrame, dict]]


def seed_key(experiment: Experiment, seed: int, overrides: Sequence[str]) -> str:
    """What decides a seed's figures, hashed: the drive, the entries and the measure (the
    experiment's key is only a name)."""
    text = json.dumps([experiment.scenario, list(overrides), seed, experiment.entries,
                       f"{experiment.measure.__module__}.{experiment.measure.__qualname__}",
                       None if experiment.history is None
                       else f"{experiment.history.__module__}.{experiment.history.__qualname__}"],
                      sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:32]


@contextlib.contextmanager
def _locked(path: Path) -> Iterator[None]:
    if fcntl is None:
        yield
        return
    with open(path, "a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _once(folder: Path, key: str, compute: Callable[[], object]) -> object:
    """``compute()``'s result stored in ``folder`` under ``key`` by the first process that asks,
    read by every later request (one at a time per key: a lock file)."""
    stored = folder / f"{key}.pickle"
    with _locked(folder / f"{key}.lock"):
        if not stored.exists():
            partial = stored.with_name(f"{key}.{os.getpid()}.part")
            partial.write_bytes(pickle.dumps(compute()))
            partial.replace(stored)
        return pickle.loads(stored.read_bytes())


def cached_measure_seed(folder: Path, measure_seed: MeasureSeed) -> MeasureSeed:
    """``measure_seed`` with its results kept in ``folder``: the figures and, when the
    experiment has them, the time histories (computed with the first request of a seed, so that
    the reproduction's first seed finds them whichever test asked first)."""

    def measured(experiment: Experiment, seed: int, overrides: Sequence[str], work: Path,
                 with_history: bool = False) -> tuple[dict[str, float], pd.DataFrame | None]:
        figures, history = _once(folder, seed_key(experiment, seed, overrides), lambda: (
            measure_seed(experiment, seed, overrides, work, experiment.history is not None)))
        return dict(figures), history if with_history else None

    return measured


def dataset_digest(dataset: Dataset) -> str:
    """A digest of every file of ``dataset`` (a scenario and a seed give identical files)."""
    digest = hashlib.sha256()
    for path in sorted(p for p in dataset.path.rglob("*") if p.is_file()):
        digest.update(path.relative_to(dataset.path).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def cached_estimate(folder: Path, estimate: Estimate) -> Estimate:
    """``simulator.pipeline.estimate`` with its results kept in ``folder``: one estimator entry
    replayed once over a dataset's files, so that two experiments that run an entry over the
    same drive and seed (a claim test's subset of a paper's entries, the reproduction's whole
    set, one filter under two labels) replay it once. An estimator's solution depends on the
    dataset and the entry only (SPEC: causal, deterministic replay); the label names it."""

    def estimated(dataset: Dataset, entry: Mapping[str, Any] | str, *args: Any, **kwargs: Any
                  ) -> tuple[pd.DataFrame, dict]:
        label = entry.get("label") if isinstance(entry, Mapping) else None
        unlabelled = ({k: v for k, v in entry.items() if k != "label"}
                      if isinstance(entry, Mapping) else entry)
        text = json.dumps([dataset_digest(dataset), unlabelled, args, kwargs], sort_keys=True,
                          default=repr)
        key = "solution-" + hashlib.sha256(text.encode()).hexdigest()[:32]
        solution, info = _once(folder, key, lambda: estimate(dataset, entry, *args, **kwargs))
        return solution, {**info, "label": label or info["label"]}

    return estimated


@contextlib.contextmanager
def in_this_process(workers: int, scheduler: str | None, timeout_s: float
                    ) -> Iterator[tuple[cf.Executor, int]]:
    """Stands in for ``simulator.campaign.execute.open_executor``: the reproduction's tasks on
    one thread of this process, where the session's shared experiments are."""
    with cf.ThreadPoolExecutor(1) as executor:
        yield executor, 1
