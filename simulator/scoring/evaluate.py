"""Several solutions on one dataset: read the truth and events once, score each solution, and
write the scores as JSON (docs/scores.md, keyed by label).

Public names
------------
Scored, Evaluation, score_solutions, canyon_zones, write_scores.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from simulator import columns as col
from simulator.dataset.io import Dataset
from simulator.outputs import atomic_output_file
from simulator.scoring.align import SolutionErrors, solution_errors
from simulator.scoring.metrics import score_errors


@dataclass
class Scored:
    """One scored solution: its table, its per-sample errors and its scores."""

    label: str
    solution: pd.DataFrame
    errors: SolutionErrors
    scores: dict


@dataclass
class Evaluation:
    """The truth and events of a dataset and every scored solution, by label."""

    truth: pd.DataFrame
    events: pd.DataFrame
    results: dict[str, Scored]
    canyon_zones: frozenset[str] = frozenset()
    dataset: Dataset | None = None  # for the report's GNSS plots

    def scores(self) -> dict[str, dict]:
        """The JSON-ready scores keyed by label."""
        return {label: r.scores for label, r in self.results.items()}

    def warnings(self) -> list[str]:
        """One line per solution with rows that could not be scored."""
        out = []
        for label, r in self.results.items():
            rows = r.scores["rows"]
            if rows["outside_truth"]:
                out.append(f"{label}: {rows['outside_truth']} of {rows['total']} solution rows "
                           "lie outside the truth's time span and were ignored")
            if rows["position"] < rows["total"] - rows["outside_truth"]:
                out.append(f"{label}: {rows['total'] - rows['outside_truth'] - rows['position']}"
                           " rows without a finite position were skipped")
        return out


def canyon_zones(manifest: dict) -> frozenset[str]:
    """Names of the zones whose sky is an urban canyon in a dataset's resolved scenario."""
    zones = ((manifest.get("scenario") or {}).get("environment") or {}).get("zones") or {}
    return frozenset(name for name, zone in zones.items() if (zone or {}).get("sky") == "canyon")


def score_solutions(dataset: Dataset,
                    solutions: dict[str, tuple[pd.DataFrame, dict | None]]) -> Evaluation:
    """Score solutions against a dataset's truth.

    Parameters
    ----------
    dataset : the opened dataset (must have ``truth``; ``events``, ``truth_sensors`` and
        ``gnss_fix`` are used when present).
    solutions : label -> (solution table, info or None). ``info`` of an estimator run inside
        landnav (``simulator.replay.run_estimator``) gives ``runtime_s``, ``realtime_factor``
        and ``uses_gnss``; a solution file gives ``{"uses_gnss": ...}`` as its reader found
        (``simulator.scoring.readers``), and None is taken to use GNSS, so its outages are
        scored.
    """
    truth = dataset.read("truth")
    events = (dataset.read("events") if dataset.has("events")
              else pd.DataFrame(columns=list(col.EVENTS)))
    truth_sensors = dataset.read("truth_sensors") if dataset.has("truth_sensors") else None
    gnss_fix = (dataset.read("gnss_fix", ["t", "num_sats"]) if dataset.has("gnss_fix")
                else None)
    canyons = canyon_zones(dataset.manifest)
    results = {}
    for label, (frame, info) in solutions.items():
        errors = solution_errors(truth, frame, truth_sensors)
        info = info or {}
        runtime = info if "runtime_s" in info else None
        scores = score_errors(errors, truth, events, runtime,
                              uses_gnss=info.get("uses_gnss", True),
                              canyon_zones=canyons, gnss_fix=gnss_fix)
        results[label] = Scored(label, frame, errors, scores)
    return Evaluation(truth, events, results, canyons, dataset)


def write_scores(scores: dict, path: Path, force: bool = False,
                 inputs: Iterable[Path | str] = ()) -> None:
    """Write scores as JSON (no NaN: missing values are null) under a temporary name, then
    move it into place; an existing file is replaced only with ``force``, a path inside one of
    ``inputs`` is refused."""
    text = json.dumps(scores, indent=2, allow_nan=False) + "\n"
    with atomic_output_file(path, force, inputs, "json") as tmp:
        tmp.write_text(text, encoding="utf-8")
