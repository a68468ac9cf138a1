"""Benchmark: Park et al. 2019's dead-reckoning filters ``dr2d_odo_ekf`` and ``dr3d_ekf`` on one
hour of driving with a 100 Hz IMU (target: at least 300 x real time each), with FilterPy's
``ExtendedKalmanFilter`` as the peer running the same 10-state model (``dr3d_ekf`` with its
Kalman predict/update handed to FilterPy), timed side by side in the same run.

The drive is the garage scenario's open-road part and one garage visit (helices, ramps), repeated
to one hour: SMI130 at 100 Hz (rate samples), 10 Hz odometer, 20 Hz BMP280, 1 Hz GNSS fixes with
the garage outages. The time is ``run_estimator``'s message loop (``runtime_s``: handing every
message and collecting the 10 Hz solution), in-process, best of ``--repeat``; generation and
Parquet reading are excluded. Numba compilation is excluded by a warm-up run on a short drive.

    PYTHONPATH=. python benchmarks/bench_estimators_parkdr.py [--hours 1] [--repeat 3]

Needs ``filterpy`` (``pip install -e .[bench]``).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

from benchmarks.arguments import hours_and_repeat
from benchmarks.timing import best_replay
from estimators.builtin.park2019_dr import Dr3dEkf
from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import open_dataset
from simulator.replay import run_estimator
from simulator.scenario import load_scenario

HERE = Path(__file__).resolve().parent
GARAGE = HERE.parent / "scenarios" / "park2019_underground_garage.yaml"


class FilterPyErrorState:
    """The ``kalman.ErrorState`` interface (closed loop) on FilterPy's ExtendedKalmanFilter:
    ``predict`` sets F and Q and calls ``predict()``; ``update`` calls ``update(dz, H, Hx)``
    (FilterPy's Joseph-form update, as the toolbox's)."""

    def __init__(self, p0: np.ndarray):
        from filterpy.kalman import ExtendedKalmanFilter

        n = p0.shape[0]
        self.ekf = ExtendedKalmanFilter(dim_x=n, dim_z=1)
        self.ekf.P = p0.copy()
        self.ekf.x = np.zeros((n, 1))

    @property
    def p(self) -> np.ndarray:
        return self.ekf.P

    def predict(self, phi: np.ndarray, q_d: np.ndarray) -> None:
        self.ekf.F = phi
        self.ekf.Q = q_d
        self.ekf.predict()

    def update(self, dz: np.ndarray, h: np.ndarray, r: np.ndarray) -> None:
        self.ekf.update(np.asarray(dz, float).reshape(-1, 1), lambda x: h, lambda x: h @ x, R=r)

    def feedback(self) -> np.ndarray:
        dx = self.ekf.x[:, 0].copy()
        self.ekf.x[:] = 0.0
        return dx


class Dr3dEkfFilterPy(Dr3dEkf):
    """``dr3d_ekf`` with its Kalman steps done by FilterPy (the peer)."""

    name = "dr3d_ekf_filterpy"

    def setup(self) -> None:
        super().setup()
        self._kf = FilterPyErrorState(self._kf.p)


def hour_scenario(hours: float, out: Path) -> Path:
    """The garage scenario with a 100 Hz IMU, its drive repeated to ``hours``."""
    data = yaml.safe_load(GARAGE.read_text())
    segments = data["trajectory"]["segments"]
    visit = segments[1:-2]  # accelerate ... last straight: about 400 s
    repeats = max(1, round(hours * 3600 / 400))
    data["trajectory"]["segments"] = [segments[0], *visit * repeats, *segments[-2:]]
    data["sensors"]["imu"]["rate"] = 100
    path = out / "hour.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _time(ds, entry, repeat: int) -> tuple[float, float, float, object]:
    """Best wall time of the message loop, best CPU time of the whole call, data span, solution
    (the CPU time is what counts on a shared machine)."""
    best, best_cpu, sol = best_replay(ds, entry, repeat)
    return best, best_cpu, float(sol["t"].iloc[-1] - sol["t"].iloc[0]), sol


def main() -> None:
    args = hours_and_repeat(__doc__)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        warm = generate_dataset(load_scenario(GARAGE, [], 1), tmp / "warm")
        for name in ("dr2d_odo_ekf", "dr3d_ekf"):
            run_estimator(open_dataset(warm), name, show_progress=False)
        start = time.perf_counter()
        ds = open_dataset(generate_dataset(load_scenario(hour_scenario(args.hours, tmp), [], 1),
                                           tmp / "hour"))
        n_imu = len(ds.read("imu"))
        print(f"drive generated in {time.perf_counter() - start:.1f} s: {n_imu} IMU samples")
        peer = {"name": "benchmarks.bench_estimators_parkdr:Dr3dEkfFilterPy", "label": "peer",
                "init": None, "config": None}
        results = {}
        for label, entry in (("dr2d_odo_ekf", "dr2d_odo_ekf"), ("dr3d_ekf", "dr3d_ekf"),
                             ("dr3d_ekf on FilterPy EKF", peer)):
            runtime, cpu, duration, sol = _time(ds, entry, args.repeat)
            results[label] = sol
            print(f"{label:26s} loop {runtime:6.2f} s wall ({duration / runtime:5.0f} x real "
                  f"time), whole call {cpu:6.2f} s CPU ({duration / cpu:5.0f} x real time)")
        a, b = results["dr3d_ekf"], results["dr3d_ekf on FilterPy EKF"]
        diff = np.abs(a.to_numpy() - b.to_numpy()).max()
        print(f"largest difference of any solution column, toolbox vs FilterPy: {diff:.1e}")


if __name__ == "__main__":
    main()
