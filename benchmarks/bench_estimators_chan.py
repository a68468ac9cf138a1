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
    _propagate_points,
    boxminus,
    boxplus,
)
from estimators.toolbox import gnss_model  # noqa: E402
from simulator.dataset.generate import generate_dataset  # noqa: E402
from simulator.dataset.io import Dataset, open_dataset  # noqa: E402
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
        raw = ds.read("gnss_raw").select_dtypes("number")  # the signal names are text
        self.raw_cols = {c: i for i, c in enumerate(raw.columns)}
        self.raw = raw.to_numpy(dtype=float)
        init = initial_state(ds.read("truth"), float(self.t_imu[0]), None)
        # the landnav filter gives the configuration, P0, Q, R and the measurement model
        self.model = TcUkf({"lever_arm": LEVER}, init, {"imu": {"t": 0, "gyro_x": 1,
                                                                 "gyro_y": 2, "gyro_z": 3,
                                                                 "accel_x": 4, "accel_y": 5,
                                                                 "accel_z": 6},
                                                         "gnss_raw": self.raw_cols},
                           {"imu": {}, "gnss_raw": {}})
        points = MerweScaledSigmaPoints(N_STATES, alpha=0.99, beta=2.0, kappa=0.0)
        self.ukf = UnscentedKalmanFilter(N_STATES, 1, 1.0, self.hx, self.fx, points)
        self.ukf.x = np.zeros(N_STATES)
        self.ref = self.model.ukf.x.copy()  # the nominal state the tangent x is taken around

    @staticmethod
    def fx(x: np.ndarray, dt: float, start: np.ndarray, end: np.ndarray, w: np.ndarray,
           f: np.ndarray, dts: np.ndarray) -> np.ndarray:
        """One sigma point (tangent around ``start``) through the interval, as a tangent
        around ``end`` (the reference state propagated through the same interval)."""
        point = boxplus(start, x)[None].copy()
        _propagate_points(point, w, f, dts)
        return boxminus(point, end)[0]

    def hx(self, x: np.ndarray, ep: gnss_model.RawEpoch) -> np.ndarray:
        return self.model._observe(boxplus(self.ref, x)[None], ep, True)[0]

    def run(self, seconds: float) -> float:
        t_raw = self.raw[:, self.raw_cols["t"]]
        epochs = np.unique(t_raw[t_raw <= self.t_imu[0] + seconds])
        start = time.perf_counter()
        t_prev = self.t_imu[0]
        for i, t in enumerate(epochs):
            ep = gnss_model.raw_epoch(self.raw[t_raw == t], self.raw_cols)
            a, b = np.searchsorted(self.t_imu, [t_prev, t], side="left")
            w, f = self.w[a:b + 1], self.f[a:b + 1]
            dts = np.diff(self.t_imu[a:b + 1])
            if len(dts):
                end = self.ref[None].copy()
                _propagate_points(end, w, f, dts)
                self.ukf.Q = self.model.process_noise(t - t_prev)
                self.ukf.predict(dt=t - t_prev, start=self.ref, end=end[0], w=w, f=f, dts=dts)
                self.ref = end[0]
            if i == 0:  # the receiver clock from the first epoch, as tc_ukf starts it
                self.model.ukf.x = self.ref
                self.model.start_clock(t, ep)
                self.ref = self.model.ukf.x.copy()
                self.ukf.P = self.model.ukf.p.copy()
            self.model._w_prev, self.model._f_prev = w[-1], f[-1]
            self.model.ukf.x = self.ref
            z = np.concatenate([ep.pseudorange, ep.range_rate, np.zeros(2)])
            self.ukf.update(z, R=self.model.measurement_noise(ep, True), ep=ep)
            self.ref = boxplus(self.ref, self.ukf.x)
            self.ukf.x = np.zeros(N_STATES)
            t_prev = t
        self.t_end = float(epochs[-1])
        return time.perf_counter() - start

    def error_m(self, truth) -> float:
        """3-D distance of the final state from the truth (a check that the peer tracks)."""
        from simulator.earth import geodetic_to_ecef

        k = truth.iloc[(truth["t"] - self.t_end).abs().argmin()]
        est = geodetic_to_ecef(self.ref[0], self.ref[1], self.ref[2])
        ref = geodetic_to_ecef(np.radians(k["lat"]), np.radians(k["lon"]), k["alt"])
        return float(np.linalg.norm(est - ref))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0)
    parser.add_argument("--peer-minutes", type=float, default=10.0)
    parser.add_argument("--peer-only", action="store_true", help="time only the FilterPy peer")
    parser.add_argument("--no-peer", action="store_true", help="time only landnav's filters")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        warm = drive(Path(tmp) / "warm", 2.0)
        for name in ("tc_ekf", "tc_ukf"):
            time_landnav(warm, name)  # compiles the kernels
        if not args.no_peer:
            FilterPyPeer(warm).run(5.0)
        ds = drive(Path(tmp) / "hour", args.minutes)
        duration = float(ds.read("truth")["t"].iloc[-1])
        sats = ds.read("gnss_raw").groupby("t").size()
        print(f"drive {duration:.0f} s, 100 Hz IMU, satellites per epoch "
              f"{sats.min()}-{sats.max()} (median {sats.median():.0f})")
        for name in () if args.peer_only else ("tc_ekf", "tc_ukf"):
            runtime, factor, cpu = time_landnav(ds, name)
            print(f"landnav {name}: wall {runtime:.2f} s, {factor:.0f} x real time; CPU "
                  f"{cpu:.2f} s, {duration / cpu:.0f} x")
        if args.no_peer:
            return
        peer_s = min(args.peer_minutes * 60.0, duration)
        peer = FilterPyPeer(ds)
        cpu = time.process_time()
        runtime = peer.run(peer_s)
        cpu = time.process_time() - cpu
        print(f"FilterPy UKF, same model: wall {runtime:.2f} s for {peer_s:.0f} s of data, "
              f"{peer_s / runtime:.0f} x real time; CPU {cpu:.2f} s, {peer_s / cpu:.0f} x "
              f"(final position {peer.error_m(ds.read('truth')):.1f} m from the truth)")


if __name__ == "__main__":
    main()
