"""Benchmark: one hour of GNSS raw measurements and fixes from the default sky (the real
almanac's 31 satellites), in open sky and all in an urban canyon (the path tracing of
``simulator.environment.sky``), at 1 Hz and 10 Hz.

Run:  PYTHONPATH=. python benchmarks/bench_canyon.py   (figures in BENCHMARKS.md, "Sky")

A straight street driven at 10 m/s for an hour (truth at 10 Hz), the automotive receiver; the
canyon is the Berlin street of ``scenarios/urban_canyon.yaml`` (eaves 20 m above the antenna with
a 3 m spread per building, 22 m wide, 110 m blocks between 22 m cross streets), with and without
the facades' diffuse scattering. Timed:
``Gnss.generate`` in-process, CPU time, best of two; the truth trajectory is built beforehand.
"""

from __future__ import annotations

import sys
from functools import partial
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.timing import timed_runs  # noqa: E402
from simulator.drive import build_drive  # noqa: E402
from simulator.scenario import validate_data  # noqa: E402
from simulator.schema import Context  # noqa: E402
from simulator.sensors.gnss import GNSS_FIELD, Gnss  # noqa: E402

CANYON = {"street": {"sky": "canyon", "building_height": 20.0, "building_height_spread": 3.0,
                     "street_width": 22.0, "block_length": 110.0, "cross_street_width": 22.0,
                     "facade_length": 20.0, "building_gap": 0.0}}


def _truth(zones: dict):
    data = validate_data({
        "name": "bench-canyon",
        "start": {"utc": "2026-05-04T03:00:00Z", "lat": 37.5665, "lon": 126.978, "alt": 40.0,
                  "heading": 0.0},
        "trajectory": {"kind": "segments", "rate": 10, "segments": [
            {"accelerate": {"to_speed": 10.0, "accel": 1.0}},
            {"straight": {"duration": 3590, "zone": "street"}}]},
        "environment": {"zones": zones}, "vehicle": "rigid"}, "bench.yaml")
    return build_drive(data).truth


def _generate(config, truth, seed: int) -> dict:
    return Gnss(config).generate(truth, np.random.default_rng(seed))


def main() -> None:
    for rate in (1, 10):
        config = GNSS_FIELD.check({"rate": rate}, ("gnss",), Context("bench"))
        no_scattering = {"street": {**CANYON["street"], "scattering_coefficient": 0.0}}
        for label, zones in (("open sky", {}), ("canyon, no scattering", no_scattering),
                             ("canyon", CANYON)):
            truth = _truth(zones)
            cpu, _, out = timed_runs(partial(_generate, config, truth), 2)
            print(f"{rate:2d} Hz {label:21s}: CPU {min(cpu):.2f} s, "
                  f"{len(out['gnss_raw'])} raw rows, "
                  f"{len(out['gnss_raw']) / len(out['gnss_fix']):.1f} satellites per epoch")


if __name__ == "__main__":
    main()
