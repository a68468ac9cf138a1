"""The statistics of a campaign's rows (``summary.json``): per label and sweep point, the mean,
median and 95th percentile (linear interpolation between order statistics) of every score over
the runs that succeeded and have it, how many of the runs scored on its group lack it
(``missing``: an outage end where the solution was silent; counted, never dropped; a run with
no score of the group, such as the outages of a solution without GNSS, is not scored on it),
how many runs there were and how
many failed, and the average NEES over the runs of each consistency block with its chi-square
95 % band (``anees``, ``simulator.scoring.consistency.anees``), and every pair of labels
compared seed by seed (``paired``, ``simulator.campaign.paired``).

Public names
------------
SUMMARY_FORMAT, score_columns, summarise.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from simulator.campaign.paired import paired_comparisons
from simulator.campaign.worker import RUN_COLUMNS, STATUS_FAILED, STATUS_OK
from simulator.scoring.consistency import AXIS_BLOCKS, BLOCKS, PLANAR_BLOCKS, anees

SUMMARY_FORMAT = "landnav-campaign-summary/1"
# every consistency block a solution can have, and the dimension of its NEES
_BLOCK_DIMS = {b.name: b.dim for b in (*BLOCKS, *PLANAR_BLOCKS.values(), *AXIS_BLOCKS.values())}


def score_columns(runs: pd.DataFrame, sweep_keys: list[str]) -> list[str]:
    """The flattened score columns of a runs table, in its order."""
    return [c for c in runs.columns if c not in (*RUN_COLUMNS, *sweep_keys, "error")]


def _scored(runs: pd.DataFrame, columns: list[str], column: str) -> np.ndarray:
    """Which runs are scored on ``column``'s group (its name without the last part:
    ``outages`` for ``outages.end_horizontal``, ``consistency.position`` for
    ``consistency.position.nees``): those with any finite score in the group. A run without
    any (the outages of a solution that uses no GNSS, the position block of a 2-D solution) is
    not missing the score, it is not scored on it."""
    prefix = column.rpartition(".")[0] + "."
    members = [c for c in columns if c.startswith(prefix)]
    return np.isfinite(runs[members].to_numpy(dtype=float)).any(axis=1)


def _stats(values: np.ndarray) -> dict[str, float | int | None]:
    """mean, median, p95 and count of the finite ``values``; ``missing`` the others."""
    finite = values[np.isfinite(values)]
    missing = int(values.size - finite.size)
    if not finite.size:
        return {"mean": None, "median": None, "p95": None, "count": 0, "missing": missing}
    return {"mean": float(finite.mean()), "median": float(np.median(finite)),
            "p95": float(np.percentile(finite, 95.0)), "count": int(finite.size),
            "missing": missing}


def _anees(ok: pd.DataFrame) -> dict[str, dict]:
    """ANEES of each consistency block that at least one of the runs ``ok`` has."""
    out = {}
    for block, dim in _BLOCK_DIMS.items():
        column = f"consistency.{block}.nees"
        if column in ok and np.isfinite(ok[column].to_numpy(float)).any():
            out[block] = anees(ok[column].to_numpy(float), dim)
    return out


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
    (the swept values), ``runs``, ``ok``, ``failed``, ``scores`` {column: {mean, median, p95,
    count, missing}} (the statistics None where no run has the score; ``missing`` the runs that
    succeeded and have another score of its group but not this one) and ``anees`` {block:
    {anees, expected, lower, upper, runs, missing}} for each consistency block some run has;
    and ``paired``, the pairs of labels compared seed by seed (``paired_comparisons``).
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
                "scores": {c: _stats(ok[c].to_numpy(dtype=float)[_scored(ok, scores, c)])
                           for c in scores},
                "anees": _anees(ok),
            })
    plain = [{k: _plain(v) for k, v in point.items()} for point in points]
    return {"format": SUMMARY_FORMAT, **header, "groups": groups,
            "paired": paired_comparisons(runs, labels, plain)}
