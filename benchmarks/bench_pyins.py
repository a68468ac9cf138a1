"""``ins_odo_ekf`` against pyins (python-ins, Mayorov's INS library), side by side in one run on
the drive of ``bench_estimators_ins``: speed (whole process, and in-process) and horizontal RMS
against the truth, both solutions scored by ``landnav score``.

    python -m benchmarks.bench_pyins [--hours 1] [--repeat 1]

pyins 1.0 (``pip install -e ".[bench]"``) runs its own EKF, ``filters.run_feedback_filter``, on
the same dataset's streams: the IMU samples turned into increments by its
``strapdown.compute_increments_from_imu``, the receiver's 3-D fixes as ``Position`` and
``NedVelocity`` measurements, and every odometer sample as a ``BodyVelocity`` measurement
[speed, 0, 0] (the odometer and the non-holonomic constraint, at the IMU: pyins has no lever
arm for it), with covariance propagation at the odometer's 10 Hz. Its noise is what the
dataset's datasheet says, as ``ins_odo_ekf`` reads it (``toolbox.datasheet``): the IMU's noise
densities, turn-on biases and in-run bias instability (a random walk reaching the instability
in its correlation time), the fix's white and correlated error in one sigma (pyins has no
correlated-error state), the odometer's quantisation and scale error at a typical speed. Both
filters start from the truth's first row, as the replay gives every built-in estimator.

Each side is timed as a whole process (``landnav estimate`` and a child running pyins: the
interpreter's start, the imports, reading the streams, the filter, writing the solution; the
best user + system CPU of ``--repeat`` runs, landnav's after one warm-up run that fills numba's
caches; pyins compiles its numba functions in every process) and as the filter alone
(``run_estimator``, reading the streams included; pyins' ``run_feedback_filter`` call). The
machine is shared: CPU time is the figure, not wall time.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ENTRY = "ins_odo_ekf"
TIME_STEP_S = 0.1  # pyins' covariance propagation step: the odometer's interval


def _child(command: list[str]) -> tuple[float, str]:
    """User + system CPU seconds of one child process running ``command``, and what it
    printed."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(command, capture_output=True, text=True, env=env)
    if done.returncode:
        raise SystemExit(f"{' '.join(command)} failed:\n{done.stderr}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, done.stdout


def run_pyins(dataset_dir: Path, out: Path) -> float:
    """pyins' feedback filter on the dataset (see the module doc), its solution written to
    ``out`` (a landnav solution file); returns the CPU seconds of the filter call."""
    import pandas as pd
    from pyins import filters, inertial_sensor, measurements, strapdown

    from estimators.toolbox.datasheet import (
        fix_error_model,
        imu_error_model,
        odometer_speed_sigma,
    )
    from simulator.dataset.io import open_dataset

    dataset = open_dataset(dataset_dir)
    sheet = dataset.manifest["datasheet"]
    imu = dataset.read("imu")
    truth = dataset.read("truth")
    fixes = dataset.read("gnss_fix")
    odometer = dataset.read("odometer")
    kind = dataset.manifest["sensors"]["imu"].get("output", "rate")
    imu_frame = imu.set_index("t")
    increments = strapdown.compute_increments_from_imu(imu_frame, kind)
    start = truth.iloc[int(np.searchsorted(truth.t, imu.t.iloc[0]))]
    pva = pd.Series({"lat": start.lat, "lon": start.lon, "alt": start.alt, "VN": start.vn,
                     "VE": start.ve, "VD": start.vd, "roll": np.degrees(start.roll),
                     "pitch": np.degrees(start.pitch), "heading": np.degrees(start.yaw)},
                    name=imu.t.iloc[0])
    model = imu_error_model(sheet)
    gyro = inertial_sensor.EstimationModel(
        bias_sd=model.gyro_bias_initial, noise=model.gyro_noise,
        bias_walk=model.gyro_bias_sigma / np.sqrt(model.gyro_bias_tau))
    accel = inertial_sensor.EstimationModel(
        bias_sd=model.accel_bias_initial, noise=model.accel_noise,
        bias_walk=model.accel_bias_sigma / np.sqrt(model.accel_bias_tau))
    fix = fix_error_model(sheet)
    good = fixes[(fixes.fix >= 2) & np.isfinite(fixes.lat)].set_index("t")
    hdop, vdop = float(good.hdop.median()), float(good.vdop.median())
    position_sd = float(np.hypot(fix.white_sigma(hdop, vdop),
                                 fix.correlated_sigma(hdop, vdop))[0])
    velocity_sd = float(fix.velocity_sigma(hdop, vdop)[0])
    speed_sd = float(np.hypot(odometer_speed_sigma(sheet), 0.03 * 10.0))  # 3 % at 10 m/s
    body = pd.DataFrame({"VX": odometer.speed.to_numpy(), "VY": 0.0, "VZ": 0.0},
                        index=odometer.t.to_numpy())
    aiding = [measurements.Position(good[["lat", "lon", "alt"]], position_sd),
              measurements.NedVelocity(good[["vn", "ve", "vd"]].set_axis(
                  ["VN", "VE", "VD"], axis=1), velocity_sd),
              measurements.BodyVelocity(body, speed_sd)]
    cpu = time.process_time()
    result = filters.run_feedback_filter(
        pva, 5.0, 0.5, 2.0, 5.0, increments, gyro, accel, aiding, time_step=TIME_STEP_S)
    cpu = time.process_time() - cpu
    trajectory = result.trajectory
    trajectory = trajectory.iloc[np.searchsorted(trajectory.index, odometer.t.to_numpy())
                                 .clip(0, len(trajectory) - 1)]
    pd.DataFrame({"t": trajectory.index, "lat": trajectory.lat, "lon": trajectory.lon,
                  "alt": trajectory.alt, "vn": trajectory.VN, "ve": trajectory.VE,
                  "vd": trajectory.VD, "roll": np.radians(trajectory.roll),
                  "pitch": np.radians(trajectory.pitch),
                  "yaw": np.radians(trajectory.heading)}).to_parquet(out, index=False)
    return cpu


def _landnav_in_process(dataset_dir: Path) -> float:
    """CPU seconds of ``run_estimator`` (reading the streams included), after a warm-up."""
    from simulator.dataset.io import open_dataset
    from simulator.replay import run_estimator

    dataset = open_dataset(dataset_dir)
    run_estimator(dataset, ENTRY, show_progress=False)
    cpu = time.process_time()
    run_estimator(dataset, ENTRY, show_progress=False)
    return time.process_time() - cpu


def _horizontal_rms(dataset_dir: Path, solutions: list[Path], work: Path) -> dict[str, float]:
    """Horizontal RMS (m) of each solution, from ``landnav score --json``."""
    scores = work / "scores.json"
    subprocess.run([sys.executable, "-m", "simulator.cli", "score", str(dataset_dir),
                    "--solution", *map(str, solutions), "--json", str(scores)],
                   check=True, capture_output=True)
    data = json.loads(scores.read_text())
    return {path.stem: data[path.stem]["horizontal"]["rms"] for path in solutions}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--hours", type=float, default=1.0, help="drive length, h")
    parser.add_argument("--repeat", type=int, default=1, help="timed runs (best reported)")
    parser.add_argument("--pyins-child", nargs=2, metavar=("DATASET", "OUT"),
                        help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.pyins_child:  # the filter's own CPU, for the in-process figure
        print(run_pyins(Path(args.pyins_child[0]), Path(args.pyins_child[1])))
        return
    from benchmarks.bench_estimators_ins import scenario
    from simulator.dataset.generate import generate_dataset
    from simulator.scenario import Scenario, validate_data

    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        data = validate_data(scenario(args.hours), "bench-ins")
        dataset = work / "d"
        generate_dataset(Scenario(work / "bench.yaml", data, []), dataset, show_progress=False)
        duration = json.loads((dataset / "manifest.json").read_text())["duration"]
        ours, theirs = work / f"{ENTRY}.parquet", work / "pyins.parquet"
        commands = {
            ENTRY: [sys.executable, "-m", "simulator.cli", "estimate", str(dataset), "-e",
                    ENTRY, "-o", str(ours), "--force"],
            "pyins": [sys.executable, "-m", "benchmarks.bench_pyins", "--pyins-child",
                      str(dataset), str(theirs)],
        }
        _child(commands[ENTRY])  # warm-up: numba's caches (pyins compiles in every process)
        best = {name: np.inf for name in commands}
        in_process = {ENTRY: _landnav_in_process(dataset), "pyins": np.inf}
        for _ in range(args.repeat):  # interleaved: a load on the machine hits both alike
            for name, command in commands.items():
                cpu, printed = _child(command)
                best[name] = min(best[name], cpu)
                if name == "pyins":
                    in_process[name] = min(in_process[name], float(printed.split()[-1]))
        rms = _horizontal_rms(dataset, [ours, theirs], work)
        print(f"drive {duration:.0f} s")
        for name in commands:
            print(f"{name:12s} whole process CPU {best[name]:7.2f} s "
                  f"({duration / best[name]:5.0f} x real time)  filter CPU "
                  f"{in_process[name]:7.2f} s  horizontal RMS {rms[name]:.2f} m")
        print(f"speed ratio pyins / {ENTRY}: whole process {best['pyins'] / best[ENTRY]:.1f}x, "
              f"filter {in_process['pyins'] / in_process[ENTRY]:.1f}x")


if __name__ == "__main__":
    main()
