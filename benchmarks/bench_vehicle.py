"""Benchmark: the one-hour drive of ``bench_truth`` generated with the full vehicle model (the
default, ``automotive``) against the rigid body (``vehicle: rigid``). Goal: at most 1.3 times the
rigid time, whole process (``process``).

Run:  python benchmarks/bench_vehicle.py [increment|rate] [ROUNDS] [process]
(figures in BENCHMARKS.md)

Two datasets of the same drive, side by side in one process:

* ``imu``: truth and the ideal 100 Hz IMU (increments by default, or rate samples), Parquet;
  the part of generation the body makes dearer;
* ``dataset``: the whole ``landnav generate`` of a dataset with quickstart's sensors (IMU
  ``bosch-smi130`` at 100 Hz, odometer ``abs-wheel-speed``, barometer ``bosch-bmp280``, GNSS
  ``automotive`` at 1 Hz with fixes and raw measurements), Parquet: what "generation" of a
  one-hour drive means to a user.

Each round loads the scenario (the drive) and generates the dataset, every case rigid then
automotive, after one warm-up round; the CPU time of the process over each generation (all
threads) and its wall time, best of ROUNDS (default 5). Interleaving the runs round by round
makes a load on the shared machine hit them alike; the CPU time is the steadier figure.

With ``process``: each case as whole ``landnav generate`` processes instead
(``bench_truth.time_generate``: one warm-up, then ROUNDS runs; the best CPU time of the child
processes), interpreter start and imports included.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_truth import hour_scenario, time_generate  # noqa: E402

from simulator import pipeline  # noqa: E402

VEHICLES = ("rigid", "automotive")
ROOT = Path(__file__).resolve().parent.parent


def case_sensors(case: str, output: str) -> dict:
    """The ``sensors`` block of a case (see the module doc)."""
    if case == "imu":
        return {"imu": {"preset": "ideal", "rate": 100, "output": output}}
    sensors = yaml.safe_load((ROOT / "scenarios" / "quickstart.yaml").read_text())["sensors"]
    sensors["imu"]["output"] = output
    return sensors


def write_scenarios(tmp: str, output: str) -> dict[tuple[str, str], Path]:
    """The hour drive's scenario for each case and vehicle, written into ``tmp``."""
    paths = {}
    for case in ("imu", "dataset"):
        for vehicle in VEHICLES:
            path = Path(tmp) / f"hour_{case}_{vehicle}.yaml"
            hour_scenario(path)
            data = yaml.safe_load(path.read_text())
            data["vehicle"] = vehicle
            data["sensors"] = case_sensors(case, output)
            path.write_text(yaml.safe_dump(data))
            paths[case, vehicle] = path
    return paths


def processes(output: str, rounds: int) -> None:
    """Each case as whole ``landnav generate`` processes (see the module doc)."""
    with tempfile.TemporaryDirectory() as tmp:
        best = {}
        for key, path in write_scenarios(tmp, output).items():
            _, cpu = time_generate(path, Path(tmp) / "_".join(key), runs=rounds)
            best[key] = min(cpu)
            print(f"{key[0]:>8} {key[1]:>10}: process CPU best {best[key]:.2f} s of "
                  f"{[round(x, 2) for x in cpu]}")
        for case in ("imu", "dataset"):
            print(f"{case:>8} ratio (best process CPU): "
                  f"{best[case, 'automotive'] / best[case, 'rigid']:.2f}")


def main(output: str = "increment", rounds: int = 5, mode: str = "in-process") -> None:
    if mode == "process":
        processes(output, rounds)
        return
    with tempfile.TemporaryDirectory() as tmp:
        paths = write_scenarios(tmp, output)
        wall: dict[tuple[str, str], list[float]] = {key: [] for key in paths}
        cpu: dict[tuple[str, str], list[float]] = {key: [] for key in paths}
        for round_ in range(rounds + 1):  # the first round warms up
            for key, path in paths.items():
                start_cpu, start_wall = time.process_time(), time.perf_counter()
                pipeline.generate(pipeline.load_scenario(path), Path(tmp) / "_".join(key),
                                  force=True)
                if round_:
                    cpu[key].append(time.process_time() - start_cpu)
                    wall[key].append(time.perf_counter() - start_wall)
        for case in ("imu", "dataset"):
            for vehicle in VEHICLES:
                key = (case, vehicle)
                print(f"{case:>8} {vehicle:>10}: CPU best {min(cpu[key]):.2f} s of "
                      f"{[round(x, 2) for x in cpu[key]]}, wall best {min(wall[key]):.2f} s")
            ratio_cpu = min(cpu[case, "automotive"]) / min(cpu[case, "rigid"])
            ratio_wall = min(wall[case, "automotive"]) / min(wall[case, "rigid"])
            print(f"{case:>8} ratio (best CPU): {ratio_cpu:.2f}, (best wall): {ratio_wall:.2f}")


if __name__ == "__main__":
    main(*sys.argv[1:2], *(int(x) for x in sys.argv[2:3]), *sys.argv[3:4])
