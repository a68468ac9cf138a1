"""Benchmark: `landnav run` of every shipped scenario, whole and as CI runs it (shortened with
the ``--set`` overrides of ``tests/test_shipped.py``), each in its own process with an empty
SUMO cache (``LANDNAV_CACHE``), as on a fresh machine.

Run:  python benchmarks/bench_shipped.py [--ci-only]   (prints the figures recorded in
BENCHMARKS.md, "Shipped scenarios")

Per scenario: the drive's length, the run's wall time and its CPU time (user + system of the
process; on a machine shared with other work the CPU time is the fairer figure), whole and
shortened. The sum of the shortened CPU times is what the parametrised CI test costs.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tests.test_shipped import SCENARIOS, SHORTENED  # noqa: E402


def _run(scenario: Path, sets: list[str], out: Path, cache: Path) -> tuple[float, float, float]:
    """Wall and CPU seconds of one ``landnav run`` process, and the drive's duration (s)."""
    env = {**os.environ, "LANDNAV_CACHE": str(cache), "PYTHONPATH": str(REPO)}
    args = [arg for override in sets for arg in ("--set", override)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "simulator.cli", "run", str(scenario), "-o", str(out),
                    "--force", *args], check=True, capture_output=True, env=env)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    manifest = json.loads((out / "dataset" / "manifest.json").read_text())
    return wall, cpu, manifest["duration"]


def main(ci_only: bool) -> None:
    total_ci = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        print(f"{'scenario':30s} {'drive s':>8s} {'wall s':>7s} {'cpu s':>7s}   whole: "
              f"{'drive s':>8s} {'wall s':>7s} {'cpu s':>7s}")
        for i, path in enumerate(SCENARIOS):
            sets = SHORTENED.get(path.stem, [])
            wall, cpu, drive = _run(path, sets, tmp / "ci", tmp / f"cache{i}")
            total_ci += cpu
            line = f"{path.stem:30s} {drive:8.0f} {wall:7.1f} {cpu:7.1f}"
            if sets and not ci_only:
                wall, cpu, drive = _run(path, [], tmp / "whole", tmp / f"cache{i}w")
                line += f"   whole: {drive:8.0f} {wall:7.1f} {cpu:7.1f}"
            print(line, flush=True)
    print(f"CI (shortened) total CPU: {total_ci:.1f} s over {len(SCENARIOS)} scenarios")


if __name__ == "__main__":
    main("--ci-only" in sys.argv[1:])
