"""Speed of the Cho & Choi 2006 estimators (dr2d_drm1_ekf, dr2d_drm2_ekf, dr2d_drm2_spkf) on a
one-hour drive with a 100 Hz IMU and 1 Hz GNSS fixes (goal: 300x real time each), timed
in-process beside FilterPy running the same DRM2 model as the peer.

The drive is the situation II road of scenarios/cho2006_situation2.yaml repeated to an hour.
Our estimators run inside ``simulator.replay.run_estimator`` (every IMU message handed one at a
time, 10 Hz output). The peers are FilterPy's
``ExtendedKalmanFilter`` (``predict_x`` replaced by the same DRM2 transition, F its Jacobian)
and ``UnscentedKalmanFilter`` with its ``SimplexSigmaPoints`` (one Python call per sigma point,
additive Q), fed the same 10 Hz mean IMU inputs and 1 Hz fixes precomputed as arrays, so they
pay no replay overhead. Times are process CPU seconds (``time.process_time``; the machine is
shared, so wall time varies several-fold), ours including the replay's reading of the streams.

    PYTHONPATH=. python benchmarks/bench_estimators_cho.py [--hours 1] [--repeat 3]
"""

from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.arguments import hours_and_repeat
from benchmarks.timing import best_replay
from estimators.builtin.cho2006 import DR_STEP_S, drm2_jacobian, drm2_transition
from estimators.builtin.cho2006_tuning import PAPER_P0, PAPER_Q, PAPER_R
from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import Dataset, open_dataset
from simulator.earth import normal_gravity, radii_of_curvature
from simulator.scenario import Scenario, load_scenario, validate_data

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "cho2006_situation2.yaml"
NAMES = ("dr2d_drm1_ekf", "dr2d_drm2_ekf", "dr2d_drm2_spkf")


def peer_inputs(ds: Dataset) -> tuple[np.ndarray, np.ndarray, dict]:
    """10 Hz mean [f_x, w_y, w_z] and the fixes as [t, north, east, speed] rows."""
    imu = ds.read("imu")
    n = (len(imu) - 1) // 10 * 10
    u = imu[["accel_x", "gyro_y", "gyro_z"]].to_numpy()[1:n + 1].reshape(-1, 10, 3).mean(axis=1)
    fix = ds.read("gnss_fix")
    fix = fix[fix["fix"] > 0]
    lat0, lon0 = math.radians(fix["lat"].iloc[0]), math.radians(fix["lon"].iloc[0])
    rn, re = (float(r) for r in radii_of_curvature(lat0))
    z = np.column_stack([fix["t"], (np.radians(fix["lat"]) - lat0) * rn,
                         (np.radians(fix["lon"]) - lon0) * re * math.cos(lat0),
                         np.hypot(fix["vn"], fix["ve"])])
    return u, z, {"g": float(normal_gravity(lat0, 0.0))}


def run_peer(kind: str, u: np.ndarray, z: np.ndarray, g: float) -> float:
    """Seconds FilterPy takes over the inputs (10 Hz predictions, 1 Hz updates)."""
    from filterpy.kalman import ExtendedKalmanFilter, SimplexSigmaPoints, UnscentedKalmanFilter

    h = np.eye(3, 8)
    x0 = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    fix_step = np.rint(z[:, 0] / DR_STEP_S).astype(int)
    fixes = dict(zip(fix_step.tolist(), range(len(z)), strict=True))
    if kind == "ekf":
        f = ExtendedKalmanFilter(8, 3)
        f.x, f.P, f.R = x0.copy(), PAPER_P0["drm2"].copy(), PAPER_R
        f.Q = PAPER_Q["drm2"] * DR_STEP_S
        start = time.process_time()
        for k in range(len(u)):
            f.F = drm2_jacobian(f.x, u[k], DR_STEP_S, g)
            f.x = drm2_transition(f.x[None, :], None, u[k], DR_STEP_S, g)[0]
            f.P = f.F @ f.P @ f.F.T + f.Q
            j = fixes.get(k + 1)
            if j is not None:
                f.update(z[j, 1:], lambda x: h, lambda x: h @ x)
        return time.process_time() - start
    points = SimplexSigmaPoints(8, alpha=0.3)
    uk = [u[0]]

    def fx(x, dt):
        return drm2_transition(x[None, :], None, uk[0], dt, g)[0]

    f = UnscentedKalmanFilter(8, 3, DR_STEP_S, lambda x: x[:3], fx, points)
    f.x, f.P, f.R, f.Q = x0.copy(), PAPER_P0["drm2"].copy(), PAPER_R, PAPER_Q["drm2"] * DR_STEP_S
    start = time.process_time()
    for k in range(len(u)):
        uk[0] = u[k]
        f.predict()
        j = fixes.get(k + 1)
        if j is not None:
            f.update(z[j, 1:])
    return time.process_time() - start


def main() -> None:
    args = hours_and_repeat(__doc__)
    with tempfile.TemporaryDirectory() as tmp:
        base = load_scenario(SCENARIO)
        data = {k: v for k, v in base.data.items() if k in ("name", "seed", "start", "limits")}
        data["sensors"] = {"imu": {"preset": "crossbow-dmu300cc", "rate": 100},
                           "gnss": {"preset": "automotive", "rate": 1, "outputs": ["fix"]}}
        segments = base.data["trajectory"]["segments"]
        repeats = math.ceil(args.hours * 3600 / 160.0)
        data["trajectory"] = {"kind": "segments",
                              "segments": [segments[0], *segments[1:] * repeats]}
        scenario = Scenario(Path("hour.yaml"), validate_data(data, "hour.yaml"), [])
        out = generate_dataset(scenario, Path(tmp) / "hour", show_progress=False)
        ds = open_dataset(out)
        t = ds.read("imu")["t"]
        duration = float(t.iloc[-1] - t.iloc[0])
        print(f"drive {duration:.0f} s, {len(t)} IMU rows at 100 Hz, 1 Hz fixes")
        for name in NAMES:
            best = best_replay(ds, name, args.repeat)[1]
            print(f"{name:16s} {best:6.2f} s (best of {args.repeat}), "
                  f"{duration / best:7.0f}x real time")
        u, z, extra = peer_inputs(ds)
        for kind, label in (("ekf", "FilterPy EKF"), ("ukf", "FilterPy UKF")):
            best = min(run_peer(kind, u, z, extra["g"]) for _ in range(args.repeat))
            print(f"{label:16s} {best:6.2f} s (best of {args.repeat}), "
                  f"{duration / best:7.0f}x real time (same DRM2 model, no replay)")


if __name__ == "__main__":
    main()
