"""riss3d_tc_ekf speed on a one-hour drive (target: 300 times real time), with FilterPy's
KalmanFilter running the same model as the peer, timed side by side in the same run.

The drive is the shipped ``karamat2015_partial_outages`` scenario cut to its first eight loops
(70 min, the 24 partial-outage windows of its first hour): 100 Hz reduced IMU, 10 Hz odometer,
1 Hz raw GNSS from 6-9 satellites. The peer gets exactly the filter algebra riss3d_tc_ekf did
in its run (each transition matrix and process noise, each measurement matrix, innovation and
noise, recorded while it ran) and redoes it with ``filterpy.kalman.KalmanFilter`` predict /
update; its time is the filter algebra alone, riss3d_tc_ekf's the whole estimator (mechanisation,
measurement models, replay calls); landnav's own ``toolbox.kalman`` is timed on the same calls.

    PYTHONPATH=. python benchmarks/bench_estimators_karamat.py [--model enhanced] [--repeat 3]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from estimators.toolbox import kalman
from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import open_dataset
from simulator.replay import run_estimator
from simulator.reproduce import karamat2015
from simulator.reproduce.paper import scenario_path
from simulator.scenario import load_scenario


def record_filter_calls(dataset, config: dict) -> tuple[float, float, float, list]:
    """Run riss3d_tc_ekf once while recording its filter calls; returns the data duration, the
    run's wall time, its CPU time and the calls [("p", phi, q) | ("u", dz, h, r)] (on a loaded
    machine the CPU time is the steadier figure)."""
    calls: list = []
    predict, update = kalman.ErrorState.predict, kalman.ErrorState.update

    def rec_predict(self, phi, q_d):
        calls.append(("p", phi, q_d))
        predict(self, phi, q_d)

    def rec_update(self, dz, h, r):
        calls.append(("u", np.asarray(dz, float), np.atleast_2d(h), np.atleast_2d(r)))
        return update(self, dz, h, r)

    kalman.ErrorState.predict, kalman.ErrorState.update = rec_predict, rec_update
    cpu = time.process_time()
    try:
        _, info = run_estimator(dataset, {"name": "riss3d_tc_ekf", "label": None, "init": None,
                                          "config": config}, show_progress=False)
    finally:
        kalman.ErrorState.predict, kalman.ErrorState.update = predict, update
    cpu = time.process_time() - cpu
    duration = info["runtime_s"] * info["realtime_factor"]
    return duration, info["runtime_s"], cpu, calls


def filterpy_time(calls: list, n: int) -> float:
    """Seconds FilterPy's KalmanFilter takes for the same predict/update sequence."""
    from filterpy.kalman import KalmanFilter

    kf = KalmanFilter(dim_x=n, dim_z=1)
    kf.P = np.eye(n)
    start = time.perf_counter()
    for call in calls:
        if call[0] == "p":
            kf.predict(F=call[1], Q=call[2])
        else:
            _, dz, h, r = call
            kf.dim_z = len(dz)
            kf.update(dz, R=r, H=h)
            kf.x = np.zeros((n, 1))  # closed loop: the errors were fed back
    return time.perf_counter() - start


def toolbox_time(calls: list, n: int) -> float:
    """Seconds landnav's own ``estimators.toolbox.kalman`` takes for the same sequence (the
    like-for-like figure beside FilterPy's)."""
    state = kalman.ErrorState(np.eye(n))
    start = time.perf_counter()
    for call in calls:
        if call[0] == "p":
            state.predict(call[1], call[2])
        else:
            state.update(call[1], call[2], call[3])
            state.feedback()
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="enhanced", choices=["enhanced", "simplified"])
    parser.add_argument("--coupling", default="tight", choices=["tight", "loose"])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    config = {"model": args.model, "coupling": args.coupling}
    with tempfile.TemporaryDirectory() as tmp:
        # the claim tests' rigid body (issue 13), the windows of the first eight loops
        scenario = load_scenario(scenario_path(karamat2015.SCENARIO),
                                 [*karamat2015.protocol_overrides(8), "vehicle=rigid",
                                  "estimators=[]"], 2015)
        dataset = open_dataset(generate_dataset(scenario, Path(tmp) / "hour",
                                                show_progress=False))
        ours, cpus, peer, algebra = [], [], [], []
        for _ in range(args.repeat):
            duration, runtime, cpu, calls = record_filter_calls(dataset, config)
            ours.append(runtime)
            cpus.append(cpu)
            n = next(c[1].shape[0] for c in calls if c[0] == "p")
            peer.append(filterpy_time(calls, n))
            algebra.append(toolbox_time(calls, n))
    runs = ", ".join(f"{r:.2f}" for r in ours)
    print(f"drive {duration:.0f} s, riss3d_tc_ekf {config}: median {np.median(ours):.2f} s "
          f"({duration / np.median(ours):.0f}x real time, runs {runs}); CPU time "
          f"{np.median(cpus):.2f} s ({duration / np.median(cpus):.0f}x)")
    print(f"FilterPy KalmanFilter, the same {len(calls)} predict/update calls: median "
          f"{np.median(peer):.2f} s ({duration / np.median(peer):.0f}x real time); landnav's "
          f"toolbox kalman on the same calls: {np.median(algebra):.2f} s")


if __name__ == "__main__":
    main()
