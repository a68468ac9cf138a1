"""Benchmark: sensor generation for a one-hour drive, automotive IMU at 100 Hz with every error
term on, odometer, barometer and magnetometer.

Run:  PYTHONPATH=. python benchmarks/bench_sensors.py   (prints the figures in BENCHMARKS.md)

Two figures:

* in process, best of three: each sensor model's ``generate`` on the already built truth, one
  thread (the cost of the sensor models themselves);
* the whole ``landnav generate`` process (interpreter start, imports, scenario loading,
  kinematics, every sensor, Parquet writing, with its worker threads), best of five after a
  warm-up, as in ``bench_truth.py``.

Every IMU error term is on: the ``automotive`` preset's (turn-on bias, flicker bias instability,
white noise, random walk, scale factor, misalignment, g-sensitivity, range, resolution,
temperature coefficients) plus a Gauss-Markov bias, a rate ramp, a warm-up temperature profile,
a 40 Hz output low-pass, engine and road vibration, 20 us timestamp jitter, lever arm and
mounting. The drive is ``bench_truth.py``'s city loop repeated to an hour.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from simulator.cli import BLAS_THREADS

# the in-process figures with the BLAS threads the command line uses (set before numpy loads)
os.environ.update({k: os.environ.get(k, v) for k, v in BLAS_THREADS.items()})

import yaml  # noqa: E402
from bench_truth import HOUR_SEGMENTS, time_generate  # noqa: E402

from simulator.dataset.generate import build_truth, sensor_rng  # noqa: E402
from simulator.scenario import validate_data  # noqa: E402
from simulator.sensors import SENSOR_MODELS  # noqa: E402

HERE = Path(__file__).resolve().parent
# plain SI numbers: a unit string anywhere in a scenario loads pint, about 1 s once
SENSORS = {
    "imu": {"preset": "automotive", "rate": 100, "output": "increment",
            "lever_arm": [0.8, 0.2, -0.3], "mounting": [0.5, -0.3, 1.0],
            "timestamp_jitter": 2e-5, "temperature": {"offset": 2.0, "warmup": 8.0},
            "vibration": {"engine_accel": 0.05, "engine_gyro": 0.002, "road_accel": 0.3,
                          "road_gyro": 0.01},
            "gyro": {"bandwidth": 40.0, "ramp": 1e-8, "gauss_markov_sigma": 2e-5,
                     "gauss_markov_correlation_time": 300.0},
            "accel": {"bandwidth": 40.0, "ramp": 1e-6, "gauss_markov_sigma": 2e-3,
                      "gauss_markov_correlation_time": 200.0}},
    "odometer": {"preset": "abs-wheel-speed"},
    "baro": {"preset": "bosch-bmp280", "drift": -50.0 / 3600.0},
    "mag": {"preset": "automotive"},
}


def hour_data() -> dict:
    data = yaml.safe_load((HERE / "hour_drive.yaml").read_text())
    data["trajectory"]["segments"] = HOUR_SEGMENTS
    data["sensors"] = SENSORS
    return data


def best_of_three(run) -> float:
    times = []
    for _ in range(3):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return min(times)


# gnss-ins-sim configurations timed: (label, IMU axes, vibration model, write its results)
GNSS_INS_SIM_RUNS = (
    ("IMU error model only", 6, None, False),
    ("IMU error model and its random vibration", 6,
     {"acc": "[0.3 0.3 0.3]-random", "gyro": "[0.01 0.01 0.01]-random"}, False),
    ("IMU, vibration and magnetometer, results written", 9,
     {"acc": "[0.3 0.3 0.3]-random", "gyro": "[0.01 0.01 0.01]-random"}, True),
)


def time_gnss_ins_sim(checkout: Path, axes: int, env: dict | None,
                      save: bool) -> tuple[float, float]:
    """Real-time factors of gnss-ins-sim (a checkout of Aceinna/gnss-ins-sim, which is not on
    PyPI) generating its 966 s ``long_drive`` at 100 Hz with its ``mid-accuracy`` IMU error
    model, in fresh processes, best of three: of its ``sim.run`` (plus ``sim.results`` writing
    its CSV files when ``save``), and of the whole process (interpreter start to exit, like
    landnav's figure). The comparison issue 4 asks for, measured in the same run."""
    code = f"""
import sys, tempfile, time
sys.path.insert(0, {str(checkout)!r})
from gnss_ins_sim.sim import imu_model, ins_sim
motion = {str(checkout / "demo_motion_def_files" / "motion_def-long_drive.csv")!r}
imu = imu_model.IMU(accuracy="mid-accuracy", axis={axes}, gps=False)
sim = ins_sim.Sim([100.0, None, {100.0 if axes == 9 else None}], motion, ref_frame=0, imu=imu,
                  mode=None, env={env!r}, algorithm=None)
with tempfile.TemporaryDirectory() as out:
    start = time.perf_counter()
    sim.run(1)
    if {save}:
        sim.results(out + "/")
    elapsed = time.perf_counter() - start
print(len(sim.dmgr.get_data_all("time").data) / 100.0, elapsed)
"""
    in_run, whole = [], []
    for _ in range(3):
        start = time.perf_counter()
        result = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                                text=True)
        wall = time.perf_counter() - start
        duration, run_s = (float(x) for x in result.stdout.split()[-2:])
        in_run.append(duration / run_s)
        whole.append(duration / wall)
    return max(in_run), max(whole)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gnss-ins-sim", type=Path, metavar="CHECKOUT",
                        help="a checkout of Aceinna/gnss-ins-sim to time in the same run")
    args = parser.parse_args()
    data = hour_data()
    scenario = validate_data(data, "hour.yaml")
    truth = build_truth(scenario)
    total = 0.0
    for name, block in scenario["sensors"].items():
        if block is None:
            continue
        model = SENSOR_MODELS[name](block)
        best = best_of_three(lambda model=model, name=name:
                             model.generate(truth, sensor_rng(scenario["seed"], name)))
        total += best
        print(f"{name:9s} generate: {best:.3f} s")
    print(f"all sensors, in process: {total:.3f} s for a {truth.duration_s:.0f} s drive "
          f"({truth.duration_s / total:.0f}x real time)")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "hour.yaml"
        path.write_text(yaml.safe_dump(data))
        out = Path(tmp) / "out"
        times, cpu = time_generate(path, out)
        best = min(times)
        rows = json.loads((out / "manifest.json").read_text())["streams"]
        print(f"landnav generate (whole process): best {best:.2f} s wall of "
              f"{[round(x, 2) for x in times]}, CPU {min(cpu):.2f} s "
              f"({truth.duration_s / best:.0f}x real time); rows: "
              + ", ".join(f"{k} {v['rows']}" for k, v in rows.items()))
    if args.gnss_ins_sim is not None:
        ours = truth.duration_s / best
        for label, axes, env, save in GNSS_INS_SIM_RUNS:
            in_run, whole = time_gnss_ins_sim(args.gnss_ins_sim, axes, env, save)
            print(f"gnss-ins-sim long_drive, {label}: {in_run:.0f}x real time (simulation), "
                  f"{whole:.0f}x (whole process); landnav generate is {ours / in_run:.1f} and "
                  f"{ours / whole:.1f} times faster")


if __name__ == "__main__":
    main()
