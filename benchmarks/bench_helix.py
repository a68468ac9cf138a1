"""Benchmark: generating a one-hour drive with 28 parking-garage helix ramps (issue 12).

Run:  python benchmarks/bench_helix.py   (prints the figures recorded in BENCHMARKS.md)

``helix_hour.yaml`` drives fourteen times down a three-turn helix into a garage and back up
(28 helices), truth and ideal IMU at 100 Hz, 3600 s. A helix's grade is solved so that the
ramp meets its ``rise`` exactly, which makes its road profile the costly part of the drive.
Two figures: the library in-process (``landnav generate`` through ``simulator.cli.main``, the
imports done beforehand), best of five after a warm-up run, and one whole ``landnav generate``
process (best of three), beside the same figures for the no-helix hour of ``bench_truth.py``.
A third drive gives each of the 28 helices its own rise (9.01 m, 9.02 m, ...), so that no
grade solve is reused (a helix's solve is kept for the identical helices met again).
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

import yaml
from bench_truth import hour_scenario, time_generate

from simulator.cli import main as landnav

HERE = Path(__file__).resolve().parent


def time_in_process(scenario: Path, out: Path, runs: int = 5) -> list[float]:
    """Wall times of ``landnav generate`` called in this process, after one warm-up."""
    argv = ["generate", str(scenario), "-o", str(out), "--force"]
    assert landnav(argv) == 0
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        assert landnav(argv) == 0
        times.append(time.perf_counter() - start)
    return times


def distinct_helices(path: Path) -> None:
    """``helix_hour.yaml`` with every helix's rise changed by a different centimetre count."""
    data = yaml.safe_load((HERE / "helix_hour.yaml").read_text())
    helices = [item["helix"] for item in data["trajectory"]["segments"] if "helix" in item]
    for k, helix in enumerate(helices, start=1):
        helix["rise"] += 0.01 * k if helix["rise"] > 0 else -0.01 * k
    path.write_text(yaml.safe_dump(data))


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp, open(os.devnull, "w") as quiet:
        plain = Path(tmp) / "hour.yaml"
        hour_scenario(plain)
        distinct = Path(tmp) / "distinct.yaml"
        distinct_helices(distinct)
        drives = (("no-helix hour", plain), ("28-helix hour", HERE / "helix_hour.yaml"),
                  ("28 distinct helices", distinct))
        for name, scenario in drives:
            stdout, sys.stdout = sys.stdout, quiet
            try:
                inside = time_in_process(scenario, Path(tmp) / "out")
            finally:
                sys.stdout = stdout
            whole, cpu = time_generate(scenario, Path(tmp) / "out", runs=3)
            print(f"{name}: in-process best {min(inside):.3f} s of "
                  f"{[round(x, 3) for x in inside]}; whole process best {min(whole):.2f} s "
                  f"(CPU {min(cpu):.2f} s)")


if __name__ == "__main__":
    main()
