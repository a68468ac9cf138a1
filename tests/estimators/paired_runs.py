"""Paired per-seed runs of estimator entries on a shipped scenario, for the paper-claim tests:
each seed's dataset is generated once and every entry replays the same dataset."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import open_dataset
from simulator.replay import run_estimator
from simulator.scenario import load_scenario
from simulator.scoring.evaluate import Scored, score_solutions

REPO = Path(__file__).resolve().parents[2]


def paired_scores(scenario: str, entries: dict[str, dict], seeds: Sequence[int],
                  work: Path, overrides: Sequence[str],
                  metric: Callable[[Scored, pd.DataFrame], float | tuple[float, ...]]
                  ) -> dict[str, np.ndarray]:
    """A figure of each entry (label -> estimator entry) on each seed.

    Returns label -> array over seeds of ``metric(scored, events)`` (a scored solution: its
    table, per-sample errors and scores; the dataset's events)."""
    out: dict[str, list] = {label: [] for label in entries}
    for seed in seeds:
        data_dir = work / f"seed{seed}"
        generate_dataset(load_scenario(REPO / scenario, list(overrides), seed), data_dir,
                         force=True, show_progress=False)
        dataset = open_dataset(data_dir)
        runs = {label: run_estimator(dataset, {"name": e["name"], "label": label,
                                               "config": e.get("config")},
                                     show_progress=False)
                for label, e in entries.items()}
        evaluation = score_solutions(dataset, runs)
        for label in entries:
            out[label].append(metric(evaluation.results[label], evaluation.events))
    return {label: np.array(v) for label, v in out.items()}


def spread(x: np.ndarray) -> str:
    """Median and range of a per-seed figure, for assertion messages and docs."""
    return f"median {np.median(x):.3g} (min {np.min(x):.3g}, max {np.max(x):.3g})"
