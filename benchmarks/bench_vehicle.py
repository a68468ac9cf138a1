"""Benchmark: the one-hour drive of ``bench_truth`` generated with the full vehicle model (the
default, ``automotive``) against the rigid body (``vehicle: rigid``). Issue 13's goal: at most 1.5
times the rigid time.

Run:  python benchmarks/bench_vehicle.py [increment|rate] [ROUNDS]   (figures in BENCHMARKS.md)

Side by side in one process: each round loads the scenario (the drive) and generates the dataset
(truth, the ideal 100 Hz IMU as increments by default or as rate samples, Parquet), rigid then
automotive, after one warm-up round; the CPU time of the process over each generation (all
threads) and its wall time, best of ROUNDS (default 5). Interleaving the two runs round by round
makes a load on the shared machine hit both alike; the CPU time is the steadier figure.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_truth import hour_scenario  # noqa: E402

from simulator import pipeline  # noqa: E402

VEHICLES = ("rigid", "automotive")


def main(output: str = "increment", rounds: int = 5) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        paths = {}
        for vehicle in VEHICLES:
            path = Path(tmp) / f"hour_{vehicle}.yaml"
            hour_scenario(path)
            data = yaml.safe_load(path.read_text())
            data["vehicle"] = vehicle
            data["sensors"]["imu"]["output"] = output
            path.write_text(yaml.safe_dump(data))
            paths[vehicle] = path
        wall: dict[str, list[float]] = {v: [] for v in VEHICLES}
        cpu: dict[str, list[float]] = {v: [] for v in VEHICLES}
        for round_ in range(rounds + 1):  # the first round warms up
            for vehicle, path in paths.items():
                start_cpu, start_wall = time.process_time(), time.perf_counter()
                pipeline.generate(pipeline.load_scenario(path), Path(tmp) / vehicle, force=True)
                if round_:
                    cpu[vehicle].append(time.process_time() - start_cpu)
                    wall[vehicle].append(time.perf_counter() - start_wall)
        for vehicle in VEHICLES:
            print(f"{vehicle:>10}: CPU best {min(cpu[vehicle]):.2f} s of "
                  f"{[round(x, 2) for x in cpu[vehicle]]}, wall best {min(wall[vehicle]):.2f} s")
        print(f"ratio (best CPU): {min(cpu['automotive']) / min(cpu['rigid']):.2f}, "
              f"(best wall): {min(wall['automotive']) / min(wall['rigid']):.2f}")


if __name__ == "__main__":
    main(*sys.argv[1:2], *(int(x) for x in sys.argv[2:3]))
