"""The baselines: dead reckoning against the exact truth of flat drives, gnss_only against the
fixes it was handed."""

from __future__ import annotations

import numpy as np
import pymap3d
import pytest

from simulator.dataset.io import open_dataset
from simulator.earth import radii_of_curvature
from simulator.replay import run_estimator
from simulator.scenario import validate_data
from tests.scoring_helpers import horizontal_error
from tests.synthetic import FLAT_LOOP, scenario, write_synthetic


def _flat(roll_gradient: float | None, output: str) -> dict:
    data = scenario(imu_output=output)
    if roll_gradient is None:
        return data
    raw = {k: data[k] for k in ("name", "seed", "start", "sensors", "vehicle")}
    raw["limits"] = {"roll_gradient": roll_gradient}
    raw["trajectory"] = {"kind": "segments", "segments": FLAT_LOOP}
    return validate_data(raw, "flat")


@pytest.mark.parametrize("roll_gradient, output, bound_m", [
    (0.0, "rate", 0.005),  # level body: only integration error remains (1.4 mm measured)
    (0.0, "increment", 0.005),
    (None, "rate", 0.5),  # default body roll in turns (up to 2 deg): 0.37 m measured
])
def test_dead_reckoning_follows_a_flat_drive(tmp_path, roll_gradient, output, bound_m):
    """Ideal IMU, exact odometer speed, 2.16 km flat loop with four turns, 3.6 min."""
    ds = open_dataset(write_synthetic(tmp_path / "ds", _flat(roll_gradient, output),
                                      streams=("imu", "odometer")))
    truth = ds.read("truth")
    solution, _ = run_estimator(ds, "dead_reckoning", show_progress=False)
    assert truth["distance"].iloc[-1] > 2000.0
    assert horizontal_error(solution, truth).max() < bound_m
    assert np.all(solution["alt"] == truth["alt"].iloc[0])  # height held


def test_dead_reckoning_without_earth_rate_drifts_as_predicted(tmp_path):
    """Uncompensated, the yaw drifts by the rotation of the level NED frame (Groves eqs. 5.41,
    5.44): -(Omega_ie sin L t + tan L / (R_E + h) x east distance), about -9.1 deg/h of Earth
    rate at 37.6 deg N, 0.5 deg after the 198 s drive."""
    data = _flat(0.0, "rate")
    ds = open_dataset(write_synthetic(tmp_path / "ds", data, streams=("imu", "odometer")))
    entry = {"name": "dead_reckoning", "label": None, "init": None,
             "config": {"earth_rate": False, "standstill": False}}
    solution, _ = run_estimator(ds, entry, show_progress=False)
    truth = ds.read("truth")
    t = solution["t"].to_numpy()
    yaw_true = np.interp(t, truth["t"], np.unwrap(truth["yaw"]))
    drift = np.angle(np.exp(1j * (solution["yaw"].to_numpy() - yaw_true)))
    lat = np.radians(data["start"]["lat"])
    _, r_e = radii_of_curvature(lat)
    east = np.radians(np.interp(t, truth["t"], truth["lon"]) - data["start"]["lon"]) * (
        r_e * np.cos(lat))
    expected = -7.292115e-5 * np.sin(lat) * (t - t[0]) - np.tan(lat) / r_e * east
    assert np.abs(expected).max() > np.radians(0.45)
    np.testing.assert_allclose(drift, expected, atol=2e-6)


def test_dead_reckoning_starts_from_the_perturbed_state(tmp_path):
    ds = open_dataset(write_synthetic(tmp_path / "ds", _flat(0.0, "rate"),
                                      streams=("imu", "odometer")))
    entry = {"name": "dead_reckoning", "label": "dr", "config": None,
             "init": {"position_error": [3.0, 4.0, 0.0], "velocity_error": None,
                      "attitude_error": None, "heading_error": None}}
    solution, _ = run_estimator(ds, entry, show_progress=False)
    error = horizontal_error(solution, ds.read("truth"))
    assert error[0] == pytest.approx(5.0, abs=1e-4)
    # a pure offset with the exact heading stays an offset
    assert np.abs(error - 5.0).max() < 0.005


def test_gnss_only_extrapolates_each_fix_with_its_velocity(tmp_path):
    ds = open_dataset(write_synthetic(tmp_path / "ds", streams=("gnss_fix",), gnss_sigma=3.0))
    fixes = ds.read("gnss_fix")
    fixes_t = fixes["t"].to_numpy()
    solution, _ = run_estimator(ds, "gnss_only", show_progress=False)
    assert np.allclose(np.diff(solution["t"])[:-1], 0.1)  # 10 Hz from 1 Hz fixes
    # each row is the latest fix at or before its time moved by its velocity (pymap3d's exact
    # NED -> geodetic conversion as the independent reference)
    t = solution["t"].to_numpy()
    latest = np.searchsorted(fixes_t, t + 1e-9, side="right") - 1
    f = fixes.iloc[latest]
    dt = t - f["t"].to_numpy()
    lat, lon, alt = pymap3d.ned2geodetic(f["vn"] * dt, f["ve"] * dt, f["vd"] * dt, f["lat"],
                                         f["lon"], f["alt"])
    assert dt.max() > 0.85 and np.abs(f["ve"]).max() > 5.0
    ned = pymap3d.geodetic2ned(solution["lat"], solution["lon"], solution["alt"], lat, lon, alt)
    assert np.abs(np.stack(ned)).max() < 1e-4
    for c in ("vn", "ve", "vd"):
        np.testing.assert_array_equal(solution[c].to_numpy(), f[c].to_numpy())
    assert solution[["roll", "pitch", "yaw"]].isna().all().all()  # it knows no attitude


def test_gnss_only_stops_reporting_after_max_extrapolation(tmp_path):
    ds = open_dataset(write_synthetic(tmp_path / "ds", streams=("gnss_fix",), gnss_sigma=3.0))
    fixes = ds.read("gnss_fix")
    fixes.loc[(fixes["t"] >= 10.0) & (fixes["t"] < 20.0), ["fix", "lat"]] = [0, np.nan]
    fixes.to_parquet(ds.path / ds.manifest["streams"]["gnss_fix"]["file"])
    entry = {"name": "gnss_only", "config": {"max_extrapolation": 1.5}}
    solution, _ = run_estimator(ds, entry, show_progress=False)
    t = solution["t"].to_numpy()
    # the last fix before the gap is at 9 s: rows up to 10.5 s, none again until 20 s
    assert not ((t > 10.5 + 1e-9) & (t < 20.0)).any()
    assert np.isclose(t, 10.5).any() and np.isclose(t, 20.0).any()


def test_dead_reckoning_learns_the_gyro_bias_at_standstill(tmp_path):
    """A constant yaw-gyro bias: without the standstill calibration the heading drifts by
    bias x time; with it, the bias learned during the first stop is removed (Groves 2013
    section 15.3.3)."""
    from simulator.dataset.generate import generate_dataset
    from simulator.scenario import Scenario
    from tests.conftest import scenario_data

    segments = [{"stop": {"duration": 20}}, {"accelerate": {"to_speed": 10.0, "accel": 1.0}},
                {"straight": {"length": 1000}}, {"turn": {"angle": 90, "radius": 50}},
                {"straight": {"length": 500}}]
    bias = 0.2  # deg/s
    data = scenario_data(segments, sensors={"imu": {"preset": "ideal", "rate": 100},
                                            "odometer": {"preset": "ideal", "rate": 10}})
    out = tmp_path / "ds"
    generate_dataset(Scenario(tmp_path / "s.yaml", data, []), out, show_progress=False)
    ds = open_dataset(out)
    imu = ds.read("imu")  # the ideal gyro with a known constant bias added
    imu["gyro_z"] = imu["gyro_z"] + np.radians(bias)
    imu.to_parquet(out / ds.manifest["streams"]["imu"]["file"])
    finals = {}
    for standstill in (False, True):
        entry = {"name": "dead_reckoning", "label": "dr", "init": None,
                 "config": {"standstill": standstill}}
        solution, _ = run_estimator(ds, entry, show_progress=False)
        truth = ds.read("truth")
        yaw_error = np.degrees(np.angle(np.exp(1j * (
            solution.yaw.to_numpy() - np.interp(solution.t, truth.t, np.unwrap(truth.yaw))))))
        finals[standstill] = yaw_error[-1]
    moving_time = float(ds.manifest["duration"]) - 20.0
    assert finals[False] == pytest.approx(bias * (moving_time + 20.0), rel=0.02)
    assert abs(finals[True]) < 0.01 * bias * moving_time
