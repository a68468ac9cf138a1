"""Shared code of the Chan et al. claim tests and benchmark: run the filters on a dataset and
measure the 3-D position error, per window of the events table."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd

from simulator.dataset.io import Dataset
from simulator.earth import geodetic_to_ecef
from simulator.replay import run_estimator

LEVER_ARM = [0.5, 0.0, -1.2]  # the shipped scenarios' antenna lever arm, m


def error_3d(solution: pd.DataFrame, truth: pd.DataFrame) -> np.ndarray:
    """3-D position error (m) of each solution row against the truth at its time."""
    t = solution["t"].to_numpy()
    tr = {c: np.interp(t, truth["t"], truth[c]) for c in ("lat", "lon", "alt")}
    est = geodetic_to_ecef(np.radians(solution["lat"].to_numpy()),
                           np.radians(solution["lon"].to_numpy()), solution["alt"].to_numpy())
    ref = geodetic_to_ecef(np.radians(tr["lat"]), np.radians(tr["lon"]), tr["alt"])
    return np.linalg.norm(est - ref, axis=1)


def run(dataset: Dataset, name: str, **config) -> tuple[pd.DataFrame, np.ndarray]:
    """Solution and its 3-D error of estimator ``name`` with ``config`` over the lever arm
    (``init``, if given, is the entry's initial errors rather than a config key)."""
    init = config.pop("init", None)
    entry = {"name": name, "init": init, "config": {"lever_arm": LEVER_ARM, **config}}
    solution, _ = run_estimator(dataset, entry, show_progress=False)
    return solution, error_3d(solution, dataset.read("truth"))


def window_means(dataset: Dataset, solution: pd.DataFrame, error: np.ndarray
                 ) -> list[tuple[int, float]]:
    """(satellites left, mean 3-D error over the window) of each satellite-limit window and
    each complete outage of the events table (an outage inside a satellite-limit window with
    count 0 is that window, counted once)."""
    events = dataset.read("events")
    limits = events[events["kind"] == "gnss_satellite_limit"]
    t = solution["t"].to_numpy()
    out = []
    for row in events.itertuples():
        if row.kind == "gnss_satellite_limit":
            count = int(json.loads(row.detail)["count"])
        elif row.kind == "gnss_outage" and not (
                (limits["t_start"] < row.t_end) & (limits["t_end"] > row.t_start)).any():
            count = 0
        else:
            continue
        inside = (t >= row.t_start) & (t <= row.t_end)
        out.append((count, float(error[inside].mean())))
    return out
