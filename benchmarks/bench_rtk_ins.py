"""Benchmark: rtk_ins_ekf (tightly coupled RTK/INS) beside RTKLIB's rnx2rtkp on the same
measurements, the shipped scenarios/rtk_open_road.yaml (20 minutes, 100 Hz IMU, 10 Hz dual-band
GPS rover and base with carrier phase, two 30 s tunnels).

Run:  python benchmarks/bench_rtk_ins.py [--seed 1] [--short] [--systems gps,galileo,beidou]

rtk_ins_ekf is timed inside the causal replay (``time.process_time`` around ``run_estimator``:
every message handed, a solution row at 10 Hz), after a short warm-up run that loads the numba
kernels; rnx2rtkp (Debian ``rtklib``, kinematic L1+L2, fix-and-hold) by the CPU time of its
process on the RINEX export of the same dataset. Both solutions' fix rates are printed beside
the times (``tests/rtk_drive.py`` does the work, as the tests do).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from tests.rtk_drive import process  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--short", action="store_true",
                        help="the test's few minutes of the same road instead of 20 minutes")
    parser.add_argument("--systems", default="gps",
                        help="rover and base systems, comma-separated (dual-band each)")
    args = parser.parse_args()
    systems = tuple(args.systems.split(","))
    with tempfile.TemporaryDirectory() as tmp:
        process(Path(tmp) / "warm", seed=args.seed, short=True)  # numba kernels loaded
        fig = process(Path(tmp) / "run", seed=args.seed, short=args.short, systems=systems)
    duration = fig["duration_s"]
    for name, cpu in fig["cpu_s"].items():
        print(f"{name:12s} {cpu:7.2f} s CPU for {duration:.0f} s of drive: "
              f"{duration / cpu:6.1f} x real time")
    print(f"fix rate: rtk_ins_ekf {fig['rtk_ins_ekf']['fix_rate']:.4f}, "
          f"rnx2rtkp {fig['rtklib']['fix_rate']:.4f}")


if __name__ == "__main__":
    main()
