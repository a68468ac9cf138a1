"""Benchmark: the whole `landnav generate` of a one-hour drive, truth and ideal IMU at 100 Hz.

Run:  python benchmarks/bench_truth.py   (prints the figures recorded in BENCHMARKS.md)

The drive repeats a city loop (turns, a hill, a lane change, a stop) until it lasts an hour;
the timing covers the whole command line process (interpreter start, imports, scenario loading,
kinematics, ideal IMU increments and Parquet writing), measured best of five after one warm-up
run. The child processes run with ``PYTHONDONTWRITEBYTECODE`` removed from their environment,
as on an ordinary installation: the warm-up run writes the byte-code caches (with the variable
set, every run recompiles about sixty modules, 0.05-0.07 s).
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

HERE = Path(__file__).resolve().parent
LOOP = [
    {"accelerate": {"to_speed": 13.0, "accel": 1.5}},
    {"straight": {"length": 400}},
    {"turn": {"angle": 90, "radius": 30}},
    {"slope": {"grade": 0.06, "length": 300}},
    {"lane_change": {"offset": 3.5, "length": 60}},
    {"turn": {"angle": 90, "radius": 30}},
    {"straight": {"length": 400}},
    {"turn": {"angle": 90, "radius": 30}},
    {"slope": {"grade": -0.06, "length": 300}},
    {"turn": {"angle": 90, "radius": 30}},
    {"accelerate": {"to_speed": 0.0, "accel": 2.0}},
    {"stop": {"duration": 15}},
]


# twenty loops (3476.14 s) and a stop to make the hour
HOUR_SEGMENTS = LOOP * 20 + [{"stop": {"duration": 123.86}}]


def hour_scenario(path: Path) -> None:
    data = yaml.safe_load((HERE / "hour_drive.yaml").read_text())
    data["trajectory"]["segments"] = HOUR_SEGMENTS
    path.write_text(yaml.safe_dump(data))


def time_generate(scenario: Path, out: Path, runs: int = 5) -> tuple[list[float], list[float]]:
    """Wall and CPU times of ``runs`` whole ``landnav generate`` processes after one warm-up."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    command = [sys.executable, "-m", "simulator.cli", "generate", str(scenario), "-o", str(out),
               "--force"]
    subprocess.run(command, check=True, capture_output=True, env=env)
    times, cpu = [], []
    for _ in range(runs):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True, env=env)
        times.append(time.perf_counter() - start)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
    return times, cpu


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        scenario = Path(tmp) / "hour.yaml"
        hour_scenario(scenario)
        times, cpu = time_generate(scenario, Path(tmp) / "out")
        manifest = yaml.safe_load((Path(tmp) / "out" / "manifest.json").read_text())
        duration = manifest["duration"]
        best = min(times)
        print(f"drive {duration:.0f} s, imu rows {manifest['streams']['imu']['rows']}")
        print(f"landnav generate (whole process): best {best:.2f} s wall of "
              f"{[round(x, 2) for x in times]}, CPU {min(cpu):.2f} s")
        print(f"real-time factor: {duration / best:.0f}x")


if __name__ == "__main__":
    main()
