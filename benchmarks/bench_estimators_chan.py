"""Benchmark: tc_ekf and tc_ukf (Chan et al.) on a one-hour drive with a 100 Hz IMU and 1 Hz raw
GNSS from 9 satellites, and FilterPy's UnscentedKalmanFilter running the same model as the peer.

Run:  python benchmarks/bench_estimators_chan.py [--minutes 60]
      (prints the figures recorded in BENCHMARKS.md, "tc_ekf, tc_ukf")

The drive is the lap of scenarios/chan_partial_outages.yaml (850 m straights and double loops)
repeated for an hour, without outages (the automotive IMU and receiver presets, 27 satellite
slots, 5 deg mask: 9 satellites in view). Each landnav filter is timed inside the causal replay
(``run_estimator``'s own clock: every message handed, a solution row at 10 Hz and at each epoch),
after one short warm-up run that compiles the numba kernels.

The peer is FilterPy 1.4's ``UnscentedKalmanFilter`` with ``MerweScaledSigmaPoints(17, 0.99, 2,
0)`` (the same weights) on the same 17-dimensional tangent state around a reference state that
is propagated alongside (``TcUkf.boxplus``/``boxminus``), the same RK4 propagation kernel, the
same pseudorange, range-rate and NHC models and the same Q and R. It differs only in the driver:
FilterPy calls ``fx`` and ``hx`` once per sigma point in Python and updates with the propagated
points (landnav draws them again after adding Q), and it runs bare, with no replay and no 10 Hz
output. It is timed on the first ``--peer-minutes`` (default 10) and scaled to the hour.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from estimators.builtin.chan import (  # noqa: E402
    N_STATES,
    TcUkf,
    _antenna_ecef,
    _earth_rate_body,
    _propagate_points,
)
from estimators.toolbox import gnss_model  # noqa: E402
from simulator.dataset.generate import generate_dataset  # noqa: E402
from simulator.dataset.io import Dataset, open_dataset  # noqa: E402
from simulator.earth import quat_to_dcm  # noqa: E402
from simulator.replay import initial_state, run_estimator  # noqa: E402
from simulator.scenario import load_scenario  # noqa: E402

SCENARIO = HERE.parent / "scenarios" / "chan_partial_outages.yaml"
LEVER = [0.5, 0.0, -1.2]
LAP_S = 188.0  # one straight and one double loop


def drive(out: Path, minutes: float) -> Dataset:
    import yaml

    data = yaml.safe_load(SCENARIO.read_text())
    seg = data["trajectory"]["segments"]
    laps = int(np.ceil(minutes * 60.0 / LAP_S))
    body = [seg[7 + (k % 2) * 2 + j] for k in range(laps) for j in (0, 1)]
    sets = [f"trajectory.segments={json.dumps(seg[:2] + body + seg[-2:])}", "faults=[]",
            "estimators=[]"]
    return open_dataset(generate_dataset(load_scenario(SCENARIO, sets), out, force=True,
                                         show_progress=False))


def time_landnav(ds: Dataset, name: str) -> tuple[float, float, float]:
    """Wall time of the replay loop (s), its real-time factor, and the process CPU time of the
    whole run_estimator call (s; steadier than wall time on a shared machine)."""
    cpu = time.process_time()
    info = run_estimator(ds, {"name": name, "config": {"lever_arm": LEVER}},
                         show_progress=False)[1]
    return info["runtime_s"], info["realtime_factor"], time.process_time() - cpu


class FilterPyPeer:
    """The tc_ukf model run by FilterPy's UKF (see the module docstring)."""

    def __init__(self, ds: Dataset):
        from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

        imu = ds.read("imu")
        self.t_imu = imu["t"].to_numpy()
        self.w = imu[["gyro_x", "gyro_y", "gyro_z"]].to_numpy()
        self.f = imu[["accel_x", "accel_y", "accel_z"]].to_numpy()
        raw = ds.read("gnss_raw")
        self.raw_cols = {c: i for i, c in enumerate(raw.columns)}
        self.raw = raw.to_numpy(dtype=float)
        init = initial_state(ds.read("truth"), float(self.t_imu[0]), None)
        # the landnav filter gives the configuration, P0, Q and R
        self.model = TcUkf({"lever_arm": LEVER}, init, {"imu": {"t": 0, "gyro_x": 1,
                                                                 "gyro_y": 2, "gyro_z": 3,
                                                                 "accel_x": 4, "accel_y": 5,
                                                                 "accel_z": 6},
                                                         "gnss_raw": self.raw_cols},
                           {"imu": {}, "gnss_raw": {}})
        self.ref = {k: np.array(v, dtype=float)[None] for k, v in self.model._mean.items()}
        points = MerweScaledSigmaPoints(N_STATES, alpha=0.99, beta=2.0, kappa=0.0)
        self.ukf = UnscentedKalmanFilter(N_STATES, 1, 1.0, self.hx, self.fx, points)
        self.ukf.x = np.zeros(N_STATES)
        self.ukf.P = self.model._p.copy()
        self.lever = np.asarray(LEVER)

    def fx(self, x: np.ndarray, dt: float, start: dict, end: dict, w: np.ndarray,
           f: np.ndarray, dts: np.ndarray) -> np.ndarray:
        pt = TcUkf.boxplus({k: v[0] for k, v in start.items()}, x[None])
        _propagate_points(pt["pos"], pt["v"], pt["q"], pt["ba"], pt["bg"], w, f, dts)
        pt["clock"][:, 0] += pt["clock"][:, 1] * dts.sum()
        both = {k: np.concatenate([end[k], pt[k]]) for k in pt}
        return TcUkf.boxminus(both)[1]

    def hx(self, x: np.ndarray, ep: gnss_model.RawEpoch, w_last: np.ndarray) -> np.ndarray:
        pt = TcUkf.boxplus({k: v[0] for k, v in self.ref.items()}, x[None])
        c_bn = quat_to_dcm(pt["q"])
        w_eb = w_last - pt["bg"] - _earth_rate_body(c_bn, pt["pos"][:, 0])
        r, v, _ = _antenna_ecef(pt["pos"], pt["v"], c_bn, self.lever, w_eb)
        pr, rate, _ = gnss_model.predict(ep.sat_pos, ep.sat_vel, r, v, pt["clock"][:, 0],
                                         pt["clock"][:, 1])
        nhc = np.einsum("kji,kj->ki", c_bn, pt["v"])[:, 1:3]
        return np.concatenate([pr[0], rate[0], nhc[0]])

    def run(self, seconds: float) -> float:
        t_raw = self.raw[:, self.raw_cols["t"]]
        epochs = np.unique(t_raw[t_raw <= self.t_imu[0] + seconds])
        start = time.perf_counter()
        t_prev = self.t_imu[0]
        for t in epochs:
            block = self.raw[t_raw == t]
            ep = gnss_model.raw_epoch(block, self.raw_cols)
            a, b = np.searchsorted(self.t_imu, [t_prev, t], side="left")
            w, f = self.w[a:b + 1], self.f[a:b + 1]
            dts = np.diff(self.t_imu[a:b + 1])
            if len(dts):
                end = {k: v.copy() for k, v in self.ref.items()}
                _propagate_points(end["pos"], end["v"], end["q"], end["ba"], end["bg"], w, f,
                                  dts)
                end["clock"][:, 0] += end["clock"][:, 1] * dts.sum()
                self.ukf.Q = self.model.process_noise(t - t_prev)
                self.ukf.predict(dt=t - t_prev, start=self.ref, end=end, w=w, f=f, dts=dts)
                self.ref = end
            z = np.concatenate([ep.pseudorange, ep.range_rate, np.zeros(2)])
            self.ukf.update(z, R=self.model._measurement_noise(ep, True), ep=ep, w_last=w[-1])
            moved = TcUkf.boxplus({k: v[0] for k, v in self.ref.items()}, self.ukf.x[None])
            self.ref = moved
            self.ukf.x = np.zeros(N_STATES)
            t_prev = t
        return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0)
    parser.add_argument("--peer-minutes", type=float, default=10.0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        warm = drive(Path(tmp) / "warm", 2.0)
        for name in ("tc_ekf", "tc_ukf"):
            time_landnav(warm, name)  # compiles the kernels
        ds = drive(Path(tmp) / "hour", args.minutes)
        duration = float(ds.read("truth")["t"].iloc[-1])
        sats = ds.read("gnss_raw").groupby("t").size()
        print(f"drive {duration:.0f} s, 100 Hz IMU, satellites per epoch "
              f"{sats.min()}-{sats.max()} (median {sats.median():.0f})")
        for name in ("tc_ekf", "tc_ukf"):
            runtime, factor, cpu = time_landnav(ds, name)
            print(f"landnav {name}: wall {runtime:.2f} s, {factor:.0f} x real time; CPU "
                  f"{cpu:.2f} s, {duration / cpu:.0f} x")
        peer_s = min(args.peer_minutes * 60.0, duration)
        cpu = time.process_time()
        runtime = FilterPyPeer(ds).run(peer_s)
        cpu = time.process_time() - cpu
        print(f"FilterPy UKF, same model: wall {runtime:.2f} s for {peer_s:.0f} s of data, "
              f"{peer_s / runtime:.0f} x real time; CPU {cpu:.2f} s, {peer_s / cpu:.0f} x")


if __name__ == "__main__":
    main()
