"""The statistics of a campaign's rows (``summary.json``): per label and sweep point, the mean,
median and 95th percentile (linear interpolation between order statistics) of every score over
the runs that succeeded and have it, how many runs there were and how many failed.

Public names
------------
SUMMARY_FORMAT, score_columns, summarise.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from simulator.campaign.worker import RUN_COLUMNS, STATUS_FAILED, STATUS_OK

SUMMARY_FORMAT = "landnav-campaign-summary/1"


def score_columns(runs: pd.DataFrame, sweep_keys: list[str]) -> list[str]:
    """The flattened score columns of a runs table, in its order."""
    return [c for c in runs.columns if c not in (*RUN_COLUMNS, *sweep_keys, "error")]


def _stats(values: np.ndarray) -> dict[str, float | int | None]:
    values = values[np.isfinite(values)]
    if not values.size:
        return {"mean": None, "median": None, "p95": None, "count": 0}
    return {"mean": float(values.mean()), "median": float(np.median(values)),
            "p95": float(np.percentile(values, 95.0)), "count": int(values.size)}


def _plain(value: Any) -> Any:
    """A sweep value as JSON: numpy scalars as Python numbers."""
    return value.item() if isinstance(value, np.generic) else value


def summarise(runs: pd.DataFrame, labels: list[str], points: list[dict[str, Any]],
              header: dict) -> dict:
    """The summary of a campaign.

    Parameters
    ----------
    runs : the rows of ``runs.parquet``.
    labels : the solution labels, in the scenario's order.
    points : the column values of each sweep point, in order (``[{}]`` without a sweep).
    header : what to put before the groups (scenario, runs, base seed, sweep).

    Returns
    -------
    ``header`` plus ``groups``: one entry per label and sweep point with ``label``, ``sweep``
    (the swept values), ``runs``, ``ok``, ``failed`` and ``scores`` {column: {mean, median,
    p95, count}} (None where no run has the score).
    """
    keys = list(points[0]) if points else []
    scores = score_columns(runs, keys)
    groups = []
    for point in points:
        at = np.ones(len(runs), dtype=bool)
        for key, value in point.items():
            at &= (runs[key] == value).to_numpy()
        for label in labels:
            rows = runs[at & (runs["label"] == label).to_numpy()]
            ok = rows[rows["status"] == STATUS_OK]
            groups.append({
                "label": label, "sweep": {k: _plain(v) for k, v in point.items()},
                "runs": len(rows), "ok": len(ok),
                "failed": int((rows["status"] == STATUS_FAILED).sum()),
                "scores": {c: _stats(ok[c].to_numpy(dtype=float)) for c in scores},
            })
    return {"format": SUMMARY_FORMAT, **header, "groups": groups}
