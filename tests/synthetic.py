"""Test datasets written directly with ``simulator.dataset.io``: the exact truth and ideal IMU of
a scenario from the generator, plus odometer, GNSS-fix and barometer streams made here from the
truth (the real sensor models are built elsewhere; these are exact or Gaussian-noise copies)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from simulator.dataset.generate import build_truth
from simulator.dataset.io import write_dataset
from simulator.outputs import atomic_output_dir
from simulator.scenario import validate_data
from simulator.sensors.imu import Imu

FLAT_LOOP = [  # a flat drive with left and right turns, about 2.2 km in 4 minutes
    {"stop": {"duration": 5}},
    {"accelerate": {"to_speed": 12.0, "accel": 1.5}},
    {"straight": {"length": 400}},
    {"turn": {"angle": 90, "radius": 40}},
    {"straight": {"length": 300}},
    {"turn": {"angle": -120, "radius": 30}},
    {"straight": {"length": 500}},
    {"lane_change": {"offset": 3.5, "length": 60}},
    {"turn": {"angle": 90, "radius": 50}},
    {"straight": {"length": 400}},
    {"accelerate": {"to_speed": 0.0, "accel": 2.0}},
    {"stop": {"duration": 5}},
]


def scenario(segments: list[dict] | None = None, imu_output: str = "rate",
             vehicle: str | dict = "rigid") -> dict:
    """A resolved scenario; a rigid body by default, since the estimator tests built on it
    check integration against a body that follows the road exactly (NHC exactly true). Rates
    are point samples for the same reason (the exact truth at each stamp; the default interval
    mean lags half a sample, tested in tests/trajectory/test_kinematics.py)."""
    imu = {"preset": "ideal", "rate": 100, "output": imu_output}
    if imu_output == "rate":
        imu["rate_sampling"] = "point"
    data = {"name": "synthetic", "seed": 3, "vehicle": vehicle,
            "start": {"utc": "2024-05-01T03:00:00Z", "lat": 37.5665, "lon": 126.978,
                      "alt": 40.0, "heading": 30.0},
            "trajectory": {"kind": "segments", "segments": segments or FLAT_LOOP},
            "sensors": {"imu": imu}}
    return validate_data(data, "synthetic")


def gnss_fix_from_truth(truth: pd.DataFrame, rate_hz: float, sigma_m: float,
                        rng: np.random.Generator) -> pd.DataFrame:
    """Fixes at ``rate_hz`` on the truth grid with Gaussian position noise of ``sigma_m``."""
    step = int(round(1.0 / (rate_hz * (truth["t"].iloc[1] - truth["t"].iloc[0]))))
    rows = truth.iloc[::step].reset_index(drop=True)
    n = len(rows)
    lat0 = np.radians(rows["lat"].to_numpy())
    noise = rng.normal(0.0, sigma_m, (n, 3))
    r_earth = 6378137.0
    speed = np.hypot(rows["vn"], rows["ve"])
    return pd.DataFrame({
        "t": rows["t"],
        "lat": rows["lat"] + np.degrees(noise[:, 0] / r_earth),
        "lon": rows["lon"] + np.degrees(noise[:, 1] / (r_earth * np.cos(lat0))),
        "alt": rows["alt"] - noise[:, 2],
        "vn": rows["vn"], "ve": rows["ve"], "vd": rows["vd"], "speed": speed,
        "course": np.arctan2(rows["ve"], rows["vn"]),
        "num_sats": np.full(n, 8), "hdop": np.full(n, 1.0), "vdop": np.full(n, 1.5),
        "fix": np.full(n, 2),
    })


def odometer_from_truth(truth: pd.DataFrame, rate_hz: float) -> pd.DataFrame:
    step = int(round(1.0 / (rate_hz * (truth["t"].iloc[1] - truth["t"].iloc[0]))))
    rows = truth.iloc[::step]
    return pd.DataFrame({"t": rows["t"].to_numpy(), "speed": rows["speed"].to_numpy()})


def baro_from_truth(truth: pd.DataFrame, rate_hz: float) -> pd.DataFrame:
    """Pressure of the ISA troposphere at the true height (ICAO Doc 7488 eq. for h < 11 km)."""
    step = int(round(1.0 / (rate_hz * (truth["t"].iloc[1] - truth["t"].iloc[0]))))
    rows = truth.iloc[::step]
    alt = rows["alt"].to_numpy()
    return pd.DataFrame({"t": rows["t"].to_numpy(),
                         "pressure": 101325.0 * (1.0 - 2.25577e-5 * alt) ** 5.25588,
                         "altitude": alt})


def write_synthetic(out: Path, data: dict | None = None, *, gnss_sigma: float = 2.0,
                    streams: tuple[str, ...] = ("imu", "odometer", "gnss_fix", "baro"),
                    seed: int = 0) -> Path:
    """Write a dataset of ``data`` (default: the flat loop) with the requested streams."""
    data = data or scenario()
    truth_k = build_truth(data)
    truth = truth_k.table()
    rng = np.random.default_rng(seed)
    made = {"truth": truth}
    if "imu" in streams:
        made.update(Imu(data["sensors"]["imu"]).generate(truth_k, rng))
    if "odometer" in streams:
        made["odometer"] = odometer_from_truth(truth, 10.0)
    if "gnss_fix" in streams:
        made["gnss_fix"] = gnss_fix_from_truth(truth, 1.0, gnss_sigma, rng)
    if "baro" in streams:
        made["baro"] = baro_from_truth(truth, 20.0)
    made["events"] = pd.DataFrame({"t_start": [0.0], "t_end": [1.0], "kind": ["zone"],
                                   "detail": ["test"]})
    manifest = {"scenario": data, "seed": data["seed"], "duration": truth_k.duration_s,
                "origin": {k: data["start"][k] for k in ("lat", "lon", "alt")}}
    with atomic_output_dir(Path(out), force=True) as tmp:
        write_dataset(tmp, manifest, made)
    return Path(out)
