"""Speed of the INS filters (issue 14): ``ins_odo_ekf`` and ``ins_lkf`` on a one-hour drive with a
100 Hz IMU (Bosch SMI130), 10 Hz odometer, 10 Hz magnetometer and 1 Hz GNSS fixes, with a 60 s
outage every 10 minutes; target at least 300 times real time. The peer, timed in the same run:
FilterPy's ``ExtendedKalmanFilter`` running the same INS/odometer model as ``ins_odo_ekf`` (the
same nominal strapdown, error model, measurements and schedule; only the Kalman filter is
FilterPy's), whose solution must equal ours (the largest position difference is printed).

    PYTHONPATH=. python benchmarks/bench_estimators_ins.py [--hours 1] [--repeat 3]

Times are best of ``--repeat`` after a warm-up run (numba compilation and cache loading are not
counted): the wall time of the replay loop (``run_estimator``'s ``runtime_s``) and the process CPU
time of the whole ``run_estimator`` call (reading the streams included), which is steadier on a
shared machine.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter

from benchmarks.arguments import hours_and_repeat
from benchmarks.timing import best_replay
from estimators.builtin.park2019_ins import ParkInsOdometer
from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import open_dataset
from simulator.replay import run_estimator
from simulator.scenario import Scenario, validate_data

LOOP = [  # about 184 s of city driving (the quickstart loop without its tunnel)
    {"accelerate": {"to_speed": 12.0, "accel": 1.5}},
    {"straight": {"length": 300}},
    {"turn": {"angle": 90, "radius": 30}},
    {"slope": {"grade": 0.06, "length": 250}},
    {"straight": {"length": 200}},
    {"lane_change": {"offset": 3.5, "length": 60}},
    {"turn": {"angle": 90, "radius": 30}},
    {"straight": {"duration": 20}},
    {"slope": {"grade": -0.06, "length": 250}},
    {"turn": {"angle": 90, "radius": 30}},
    {"straight": {"length": 300}},
    {"accelerate": {"to_speed": 0.0, "accel": 2.0}},
    {"stop": {"duration": 10}},
]


def scenario(hours: float) -> dict:
    loops = int(np.ceil(hours * 3600 / 183))  # each loop takes about 183.7 s
    return {
        "name": "bench-ins", "seed": 1,
        "start": {"utc": "2024-05-01T03:00:00Z", "lat": 37.5665, "lon": 126.978, "alt": 40.0,
                  "heading": 90.0},
        "trajectory": {"kind": "segments", "segments": [{"stop": {"duration": 10}}]
                       + LOOP * loops},
        "sensors": {"imu": {"preset": "bosch-smi130", "rate": 100},
                    "odometer": {"preset": "abs-wheel-speed"},
                    "mag": {"preset": "automotive"},
                    "gnss": {"preset": "automotive", "rate": 1, "outputs": ["fix"]}},
        "faults": [{"kind": "gnss_outage", "start": 600.0 * (k + 1), "duration": 60.0}
                   for k in range(int(hours * 6) - 1)],
    }


class FilterPyErrorState:
    """``kalman.ErrorState``'s interface over FilterPy's ExtendedKalmanFilter (the peer)."""

    def __init__(self, p0: np.ndarray, closed_loop: bool = True):
        self.ekf = ExtendedKalmanFilter(dim_x=p0.shape[0], dim_z=1)
        self.ekf.P = np.array(p0, dtype=float)
        self.closed_loop = closed_loop

    @property
    def estimate(self) -> np.ndarray:
        return self.ekf.x[:, 0]

    @property
    def x(self) -> np.ndarray:
        return self.ekf.x[:, 0]

    @property
    def p(self) -> np.ndarray:
        return self.ekf.P

    def predict(self, phi: np.ndarray, q_d: np.ndarray) -> None:
        self.ekf.F, self.ekf.Q = phi, q_d
        self.ekf.predict()

    def update(self, dz: np.ndarray, h: np.ndarray, r: np.ndarray) -> None:
        h = np.atleast_2d(h)
        self.ekf.update(np.asarray(dz, float).reshape(-1, 1), lambda x: h, lambda x: h @ x,
                        R=np.atleast_2d(r))

    def feedback(self) -> np.ndarray:
        dx = self.ekf.x[:, 0].copy()
        self.ekf.x[:] = 0.0
        return dx


class FilterPyInsOdometer(ParkInsOdometer):
    """``ins_odo_ekf`` with FilterPy's EKF doing the Kalman filter."""

    name = "ins_odo_ekf_filterpy"

    def setup(self) -> None:
        super().setup()
        self.ins.kf = FilterPyErrorState(self.ins.kf.p)


def main() -> None:
    args = hours_and_repeat(__doc__)
    with tempfile.TemporaryDirectory() as tmp:
        data = validate_data(scenario(args.hours), "bench-ins")
        generate_dataset(Scenario(Path(tmp) / "bench.yaml", data, []), Path(tmp) / "d",
                         show_progress=False)
        dataset = open_dataset(Path(tmp) / "d")
        duration = float(dataset.read("imu")["t"].iloc[-1])
        print(f"drive {duration:.0f} s, 100 Hz IMU ({int(duration * 100)} samples)")
        frames = {}
        for entry in ("ins_odo_ekf", "ins_lkf",
                      "benchmarks.bench_estimators_ins:FilterPyInsOdometer"):
            run_estimator(dataset, entry, show_progress=False)  # warm-up
            wall, cpu, frames[entry] = best_replay(dataset, entry, args.repeat)
            print(f"{entry.split(':')[-1]:22s} wall {wall:6.2f} s ({duration / wall:5.0f} x real "
                  f"time)  CPU {cpu:6.2f} s ({duration / cpu:5.0f} x)")
        ours, peer = frames["ins_odo_ekf"], frames[
            "benchmarks.bench_estimators_ins:FilterPyInsOdometer"]
        diff = np.abs(ours[["lat", "lon"]].to_numpy() - peer[["lat", "lon"]].to_numpy()).max()
        print(f"largest lat/lon difference, ins_odo_ekf vs FilterPy peer: {diff * 111e3:.2e} m")


if __name__ == "__main__":
    main()
