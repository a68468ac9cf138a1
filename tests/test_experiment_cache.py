"""The session's store of estimator solutions (tests/experiment_cache.py): an entry replayed once
over a dataset's files whatever its label, again for another entry or other files."""

from __future__ import annotations

import pandas as pd

from simulator.dataset.io import open_dataset
from tests.experiment_cache import cached_estimate
from tests.synthetic import write_synthetic


def test_an_entry_is_replayed_once_per_dataset_files(tmp_path):
    calls = []

    def estimate(dataset, entry):
        calls.append((dataset.path, entry["name"]))
        return pd.DataFrame({"t": [float(len(calls))]}), {"label": entry["label"]}

    cached = cached_estimate(tmp_path / "store", estimate)
    (tmp_path / "store").mkdir()
    first = open_dataset(write_synthetic(tmp_path / "a", streams=("imu",), seed=1))
    same = open_dataset(write_synthetic(tmp_path / "b", streams=("imu",), seed=1))
    other = open_dataset(write_synthetic(tmp_path / "c", streams=("imu", "odometer"), seed=1))
    solution, info = cached(first, {"name": "x", "label": "one"})
    again, named = cached(same, {"name": "x", "label": "two"})  # same files, another folder
    pd.testing.assert_frame_equal(again, solution)
    assert info == {"label": "one"} and named == {"label": "two"} and len(calls) == 1
    cached(first, {"name": "y", "label": "one"})
    cached(other, {"name": "x", "label": "one"})
    assert calls == [(first.path, "x"), (first.path, "y"), (other.path, "x")]
