"""Benchmark: rtk_ins_ekf (tightly coupled RTK/INS) beside RTKLIB's rnx2rtkp on the same
measurements, the shipped scenarios/rtk_open_road.yaml (20 minutes, 100 Hz IMU, 10 Hz dual-band
GPS rover and base with carrier phase, two 30 s tunnels).

Run:  python benchmarks/bench_rtk_ins.py [--seed 1] [--short] [--systems gps,galileo,beidou]

rtk_ins_ekf is timed inside the causal replay (``time.process_time`` around ``run_estimator``:
every message handed, a solution row at 10 Hz), after a short warm-up run that loads the numba
kernels; rnx2rtkp (Debian ``rtklib``, kinematic L1+L2, fix-and-hold) by the CPU time of its
process on the RINEX export of the same dataset. Both solutions' rtk scores (fixed epochs,
wrong fixes, fixed RMS, first fix, re-fix after each tunnel) and rtk_ins_ekf's position
(error/sigma)^2 are printed beside the times (``tests/rtk_drive.py`` does the work, as the
tests do).
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
    for name in ("rtk_ins_ekf", "rtklib"):
        rtk = fig[name]
        print(f"{name:12s} fixed {rtk['fix_rate']:.4f}, wrong {rtk['wrong_fix_rate']}, fixed "
              f"3-D RMS {rtk['fixed_rms']:.4f} m, first fix {rtk['time_to_first_fix']:.1f} s, "
              f"re-fix {[None if x is None else round(x, 1) for x in rtk['refix_times']]} s")
    nse = fig["consistency"]["position"]["nse"]
    print(f"rtk_ins_ekf position (error/sigma)^2 n / e / d: "
          f"{nse['n']:.2f} / {nse['e']:.2f} / {nse['d']:.2f}")


if __name__ == "__main__":
    main()
