"""Benchmark: an hour of four-system, dual-frequency GNSS with carrier phase for a rover and a
base station, at 1 Hz (or 10 Hz).

Run:  python benchmarks/bench_gnss_rtk.py [--rate 10] [--repeat 3] [--minutes 60]
      python benchmarks/bench_gnss_rtk.py --rate 10 --minutes 5 --scenario S.yaml
      /usr/bin/time -v landnav generate S.yaml -o DIR   # the whole job's peak memory

A 20 m/s straight drive of one hour (``--minutes``; after 10 s standing) near Seoul on
2024-05-01 03:00 UTC; the `dual-band` rover (GPS 1C 2L, Galileo 1C 7Q, BeiDou 2I 7I, GLONASS 1C
2C, carrier phase) and a `dual-band` base 5 km east, on the default sky (GPS almanac, nominal
Galileo, BeiDou and GLONASS: 111 satellites). The timing is the in-process CPU time
(``time.process_time``) of ``Gnss.generate`` with the base attached (both receivers' raw and
truth tables), the median and the best of ``--repeat`` runs (the machine's load moves single
runs by tens of percent), after one untimed run on the drive's first two minutes (what a
process pays once, the imports of its first generation, is not timed); the truth trajectory is
built once beforehand.
``--scenario`` writes the drive as a scenario file instead, for a whole ``landnav generate``
(its peak memory: the job-size estimate of ``simulator.scenario.spec``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from statistics import median

import yaml

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from benchmarks.timing import timed_runs  # noqa: E402
from simulator.dataset.generate import sensor_rng  # noqa: E402
from simulator.drive import build_drive  # noqa: E402
from simulator.scenario import validate_data  # noqa: E402
from simulator.sensors import SENSOR_MODELS  # noqa: E402

SYSTEMS = ["gps", "galileo", "beidou", "glonass"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rate", type=float, default=1.0, help="epoch rate, Hz")
    parser.add_argument("--repeat", type=int, default=3,
                        help="timed runs (their median and best reported)")
    parser.add_argument("--minutes", type=float, default=60.0, help="drive length, min")
    parser.add_argument("--scenario", type=Path, help="write the drive's scenario here and stop")
    args = parser.parse_args()
    data = _scenario(args.rate, args.minutes)
    if args.scenario is not None:
        args.scenario.write_text(yaml.safe_dump(data, sort_keys=False))
        return
    warm_up = validate_data(_scenario(args.rate, 2.0), "bench")
    _receiver(warm_up["sensors"]).generate(build_drive(warm_up).truth, sensor_rng(1, "gnss"))
    scenario = validate_data(data, "bench")
    truth = build_drive(scenario).truth
    rovers = [_receiver(scenario["sensors"]) for _ in range(args.repeat)]
    cpu, _, out = timed_runs(lambda k: rovers[k].generate(truth, sensor_rng(1, "gnss")),
                             args.repeat)
    print(f"{args.rate:g} Hz, {truth.duration_s:.0f} s: rover {len(out['gnss_raw'])} rows, base "
          f"{len(out['gnss_base_raw'])} rows; Gnss.generate CPU median {median(cpu):.2f} s, "
          f"best {min(cpu):.2f} s of {[round(c, 2) for c in cpu]}")


def _receiver(blocks: dict):
    """The rover with its base attached."""
    rover = SENSOR_MODELS["gnss"](blocks["gnss"])
    rover.attach(SENSOR_MODELS["gnss_base"](blocks["gnss_base"]))
    return rover


def _scenario(rate_hz: float, minutes: float) -> dict:
    """The benchmark's drive (module docstring) at ``rate_hz`` for ``minutes``."""
    return {"name": "bench", "seed": 1,
            "start": {"utc": "2024-05-01T03:00:00Z", "lat": 37.5, "lon": 127.0, "alt": 40.0,
                      "heading": 30.0},
            "trajectory": {"kind": "segments", "rate": 10, "segments": [
                {"stop": {"duration": 10}}, {"accelerate": {"to_speed": 20.0, "accel": 1.0}},
                {"straight": {"duration": 60.0 * minutes - 40.0}}]},
            "sensors": {"gnss": {"rate": rate_hz, "preset": "dual-band", "outputs": ["raw"],
                                 "systems": SYSTEMS},
                        "gnss_base": {"offset": {"east": 5000.0}, "rate": rate_hz,
                                      "preset": "dual-band", "systems": SYSTEMS}}}


if __name__ == "__main__":
    main()
