"""One computation of each (experiment, seed) per test session, shared by the claim tests
(tests/estimators/) and the quick reproduction (tests/reproduce/test_reproduce_cli.py).

``cached_measure_seed`` stands in for ``simulator.reproduce.runner.measure_seed`` (the
``shared_experiments`` fixture of tests/conftest.py puts it there for the session): a seed of an
experiment is computed once, its figures and time histories stored in a folder that the
session's processes share (pytest-xdist's workers), and every later request for the same drive
(scenario, ``--set`` overrides, seed), estimator entries and measure reads them. A scenario and a
seed give identical files (the simulator's contract), so a stored seed is the seed recomputed.
A seed that raises is not stored. While one process computes a seed, another that needs it
waits for it (a lock file per seed) instead of computing it twice."""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import hashlib
import json
import os
import pickle
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import pandas as pd

from simulator.reproduce.paper import Experiment

try:
    import fcntl
except ImportError:  # no POSIX file locks: a seed two processes need at once is computed twice
    fcntl = None

MeasureSeed = Callable[..., tuple[dict[str, float], pd.DataFrame | None]]


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


def cached_measure_seed(folder: Path, measure_seed: MeasureSeed) -> MeasureSeed:
    """``measure_seed`` with its results kept in ``folder``: the figures and, when the
    experiment has them, the time histories (computed with the first request of a seed, so that
    the reproduction's first seed finds them whichever test asked first)."""

    def measured(experiment: Experiment, seed: int, overrides: Sequence[str], work: Path,
                 with_history: bool = False) -> tuple[dict[str, float], pd.DataFrame | None]:
        key = seed_key(experiment, seed, overrides)
        stored = folder / f"{key}.pickle"
        with _locked(folder / f"{key}.lock"):
            if not stored.exists():
                result = measure_seed(experiment, seed, overrides, work,
                                      experiment.history is not None)
                partial = stored.with_name(f"{key}.{os.getpid()}.part")
                partial.write_bytes(pickle.dumps(result))
                partial.replace(stored)
            figures, history = pickle.loads(stored.read_bytes())
        return dict(figures), history if with_history else None

    return measured


@contextlib.contextmanager
def in_this_process(workers: int, scheduler: str | None, timeout_s: float
                    ) -> Iterator[tuple[cf.Executor, int]]:
    """Stands in for ``simulator.campaign.execute.open_executor``: the reproduction's tasks on
    one thread of this process, where the session's shared experiments are."""
    with cf.ThreadPoolExecutor(1) as executor:
        yield executor, 1
