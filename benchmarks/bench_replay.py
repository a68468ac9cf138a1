"""Replay benchmark: one hour of 100 Hz IMU, 10 Hz odometer, 20 Hz baro and 1 Hz GNSS fixes
replayed into an estimator that does nothing (target: under 3 s).

The streams are synthetic (random values with the SPEC section 5 columns; only their sizes and
times matter here), with a 100 Hz truth table for the initial state.

    PYTHONPATH=. python benchmarks/bench_replay.py [--hours 1] [--repeat 3]
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from benchmarks.arguments import hours_and_repeat
from estimators.base import Estimator
from simulator import columns as col
from simulator.dataset.io import open_dataset, write_dataset
from simulator.replay import run_estimator


class DoNothing(Estimator):
    """Takes every message of the four streams and reports a constant solution."""

    name = "do_nothing"
    needs = ("imu", "odometer", "baro", "gnss_fix")

    def on_imu(self, t, row):
        pass

    on_odometer = on_baro = on_gnss_fix = on_imu

    def solution(self, t):
        return (0.0,) * 9


def _table(columns: dict[str, str], rate_hz: float, hours: float,
           rng: np.random.Generator) -> pd.DataFrame:
    t = np.arange(int(hours * 3600 * rate_hz) + 1) / rate_hz
    frame = {"t": t}
    for name in columns:
        if name != "t":
            frame[name] = rng.normal(size=len(t))
    return pd.DataFrame(frame)


def make_dataset(path: Path, hours: float) -> None:
    rng = np.random.default_rng(0)
    truth = _table({c: u for c, u in col.TRUTH.items() if c != "zone"}, 100.0, hours, rng)
    truth["zone"] = ""
    streams = {
        "truth": truth,
        "imu": _table(col.IMU, 100.0, hours, rng),
        "odometer": _table({"t": "s", "speed": "m/s"}, 10.0, hours, rng),
        "baro": _table({"t": "s", "pressure": "Pa"}, 20.0, hours, rng),
        "gnss_fix": _table(col.GNSS_FIX, 1.0, hours, rng),
    }
    write_dataset(path, {}, streams)


def main() -> None:
    args = hours_and_repeat(__doc__)
    with tempfile.TemporaryDirectory() as tmp:
        make_dataset(Path(tmp), args.hours)
        dataset = open_dataset(tmp)
        messages = sum(dataset.manifest["streams"][s]["rows"]
                       for s in ("imu", "odometer", "baro", "gnss_fix"))
        for _ in range(args.repeat):
            start = time.perf_counter()
            solution, info = run_estimator(dataset, "benchmarks.bench_replay:DoNothing",
                                           show_progress=False)
            total = time.perf_counter() - start
            print(f"{messages} messages, {len(solution)} solution rows: replay {total:.2f} s "
                  f"(reading and merging included); estimator loop {info['runtime_s']:.2f} s, "
                  f"{info['realtime_factor']:.0f} x real time")


if __name__ == "__main__":
    main()
