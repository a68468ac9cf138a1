"""Benchmark: the one-hour drive of ``bench_truth`` generated with the full vehicle model (the
default, ``automotive``) against the rigid body (``vehicle: rigid``). Issue 13's goal: at most 1.5
times the rigid time.

Run:  python benchmarks/bench_vehicle.py [increment|rate]   (the figures in BENCHMARKS.md)

Both are whole ``landnav generate`` processes (truth and the ideal 100 Hz IMU, as increments by
default or as rate samples), best of five after a warm-up, as in ``bench_truth``; the two are
interleaved run by run, so that a load on the shared machine hits both alike.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_truth import hour_scenario, time_generate  # noqa: E402


def main(output: str = "increment", rounds: int = 5) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        paths = {}
        for vehicle in ("rigid", "automotive"):
            path = Path(tmp) / f"hour_{vehicle}.yaml"
            hour_scenario(path)
            data = yaml.safe_load(path.read_text())
            data["vehicle"] = vehicle
            data["sensors"]["imu"]["output"] = output
            path.write_text(yaml.safe_dump(data))
            paths[vehicle] = path
        best: dict[str, list[float]] = {"rigid": [], "automotive": []}
        cpu: dict[str, list[float]] = {"rigid": [], "automotive": []}
        for _ in range(rounds):
            for vehicle, path in paths.items():
                wall, used = time_generate(path, Path(tmp) / vehicle, runs=1)
                best[vehicle] += wall
                cpu[vehicle] += used
        for vehicle in paths:
            print(f"{vehicle:>10}: best {min(best[vehicle]):.2f} s wall of "
                  f"{[round(x, 2) for x in best[vehicle]]}, CPU {min(cpu[vehicle]):.2f} s")
        print(f"ratio (best wall): {min(best['automotive']) / min(best['rigid']):.2f}, "
              f"(best CPU): {min(cpu['automotive']) / min(cpu['rigid']):.2f}")


if __name__ == "__main__":
    main(*sys.argv[1:2])
