"""Benchmark: one hour of 1 Hz (or 10 Hz) GNSS raw measurements and receiver fixes from 31
satellites.

Run:  python benchmarks/bench_gnss.py [--rate 10]   (prints the figures recorded in
BENCHMARKS.md, "GNSS")

The receiver (automotive preset, every error on) drives the city loop of ``bench_truth.py``
(21 rounds, about one hour) on 2010-07-01 with the IGS broadcast ephemeris brdc1820.10n of that
day (31 healthy satellites; ``shared/refdata/gnss/igs_2010-07-01_rtklib``). The timing covers
``Gnss.generate`` only (navigation file reading, ephemeris selection and evaluation with the
transmit-time iteration for all 31 satellites x 3601 epochs, atmosphere, error processes, the
environment, the raw table and the WLS fixes), best of three; the truth trajectory is built once
beforehand.
"""

from __future__ import annotations

import argparse
import datetime as dt
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from benchmarks.bench_truth import LOOP  # noqa: E402
from benchmarks.timing import timed_runs  # noqa: E402
from simulator.schema import Context  # noqa: E402
from simulator.sensors.gnss import GNSS_FIELD, Gnss  # noqa: E402
from simulator.trajectory.kinematics import kinematics_from_profile  # noqa: E402
from simulator.trajectory.segments import (  # noqa: E402
    LIMITS_FIELD,
    SEGMENT_FIELD,
    build_road_profile,
)

NAV = HERE.parents[1] / "shared" / "refdata" / "gnss" / "igs_2010-07-01_rtklib" / "brdc1820.10n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rate", type=float, default=1.0, help="epoch rate, Hz")
    args = parser.parse_args()
    if not NAV.exists():
        sys.exit(f"needs {NAV} (the shared reference data beside the checkout)")
    ctx = Context("bench")
    limits = LIMITS_FIELD.check({}, ("limits",), ctx)
    segs = [SEGMENT_FIELD.check(s, ("segments", i), ctx) for i, s in enumerate(LOOP * 21)]
    profile = build_road_profile(segs, limits, ctx)
    truth = kinematics_from_profile(profile, {"lat": 37.5665, "lon": 126.978, "alt": 40.0,
                                              "heading": 0.0}, 10.0, limits["roll_gradient"],
                                    dt.datetime(2010, 7, 1, 6, 0))
    config = GNSS_FIELD.check({"rate": args.rate, "constellation": str(NAV)}, ("gnss",), ctx)
    assert not ctx.problems, ctx.problems
    cpu, times, out = timed_runs(
        lambda seed: Gnss(config).generate(truth, np.random.default_rng(seed)), 3)
    fix, raw = out["gnss_fix"], out["gnss_raw"]
    print(f"drive {truth.duration_s:.0f} s, {len(fix)} epochs, "
          f"{out['truth_gnss']['sv'].nunique()} satellites above the horizon of "
          f"{len(np.unique(out['gnss_nav']['sv']))} with ephemeris, "
          f"{len(raw)} raw rows, {int((fix['fix'] == 2).sum())} 3D fixes")
    print(f"Gnss.generate: wall best {min(times):.2f} s of {[round(t, 2) for t in times]}, "
          f"CPU best {min(cpu):.2f} s")


if __name__ == "__main__":
    main()
