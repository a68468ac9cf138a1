"""Benchmark: the whole `landnav generate` of a 30-minute SUMO drive among 50 other vehicles,
from the scenario to the written dataset (truth and ideal IMU at 100 Hz).

Run:  python benchmarks/bench_sumo.py   (prints the figures recorded in BENCHMARKS.md)

The network is a netgenerate grid (8 x 8 junctions, 200 m streets, two lanes each way, traffic
lights); the ego car drives a random trip, cut at 30 minutes of SUMO time. "cold" runs start with
an empty SUMO cache (netgenerate, the SUMO run, the fit, truth, IMU and Parquet writing all
counted); "warm" runs find the network and the SUMO run cached (what `generate` costs after
`validate`). Each figure is the best of three whole command-line processes.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

SCENARIO = {
    "name": "sumo-30-minutes",
    "seed": 1,
    "start": {"utc": "2024-05-01T08:00:00Z", "lat": 48.1372, "lon": 11.5756, "alt": 520.0},
    "trajectory": {
        "kind": "sumo",
        "network": {"netgenerate": {"type": "grid", "number": 8, "length": 200, "lanes": 2}},
        "route": {"length": 60000},
        "traffic": {"vehicles": 50},
        "max_duration": 1800,
        "seed": 2,
    },
    "sensors": {"imu": {"preset": "ideal", "rate": 100, "output": "increment"}},
}


def _generate(scenario: Path, out: Path, cache: Path) -> float:
    env = {**os.environ, "LANDNAV_CACHE": str(cache)}
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "simulator.cli", "generate", str(scenario), "-o",
                    str(out), "--force"], check=True, capture_output=True, env=env)
    return time.perf_counter() - start


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        scenario = tmp / "sumo30.yaml"
        scenario.write_text(yaml.safe_dump(SCENARIO))
        cold = [_generate(scenario, tmp / "out", tmp / f"cache{i}") for i in range(3)]
        warm = [_generate(scenario, tmp / "out", tmp / "cache0") for _ in range(3)]
        manifest = json.loads((tmp / "out" / "manifest.json").read_text())
        print(f"drive {manifest['duration']:.0f} s, imu rows {manifest['streams']['imu']['rows']}")
        print(f"cold (empty SUMO cache): best {min(cold):.2f} s of "
              f"{[round(x, 2) for x in cold]}")
        print(f"warm (network and run cached): best {min(warm):.2f} s of "
              f"{[round(x, 2) for x in warm]}")


if __name__ == "__main__":
    main()
