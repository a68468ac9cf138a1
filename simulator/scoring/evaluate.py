"""Several solutions on one dataset: read the truth and events once, score each solution, and
write the scores as JSON (SPEC section 8, keyed by label).

Public names
------------
Scored, Evaluation, score_solutions, write_scores.
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


def score_solutions(dataset: Dataset,
                    solutions: dict[str, tuple[pd.DataFrame, dict | None]]) -> Evaluation:
    """Score solutions against a dataset's truth.

    Parameters
    ----------
    dataset : the opened dataset (must have ``truth``; ``events`` is optional).
    solutions : label -> (solution table, runtime info ``{"runtime_s", "realtime_factor"}`` or
        None).
    """
    truth = dataset.read("truth")
    events = (dataset.read("events") if dataset.has("events")
              else pd.DataFrame(columns=list(col.EVENTS)))
    results = {}
    for label, (frame, runtime) in solutions.items():
        errors = solution_errors(truth, frame)
        results[label] = Scored(label, frame, errors, score_errors(errors, truth, events, runtime))
    return Evaluation(truth, events, results)


def write_scores(scores: dict, path: Path, force: bool = False,
                 inputs: Iterable[Path | str] = ()) -> None:
    """Write scores as JSON (no NaN: missing values are null) under a temporary name, then
    move it into place; an existing file is replaced only with ``force``, a path inside one of
    ``inputs`` is refused."""
    text = json.dumps(scores, indent=2, allow_nan=False) + "\n"
    with atomic_output_file(path, force, inputs) as tmp:
        tmp.write_text(text, encoding="utf-8")
