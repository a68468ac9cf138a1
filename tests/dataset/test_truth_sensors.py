"""truth_sensors.parquet holds the errors the streams actually carry (SPEC section 5): each true
value is recovered independently from the sensor output and the truth (gyro - (1 + s) w = b for
a unit without noise and misalignment; measured / true odometer speed; the receiver clock in
truth_gnss), and with increment output the IMU's ``unit`` metadata says rad and m/s."""

from __future__ import annotations

import numpy as np
import pytest

from simulator import columns as col
from simulator.dataset.generate import generate_dataset, generate_streams
from simulator.dataset.io import open_dataset
from simulator.scenario import load_scenario
from simulator.sensors.base import TRUE_ERROR_RATE_HZ
from tests.conftest import scenario_data
from tests.scoring_helpers import QUICKSTART

DRIVE = [{"stop": {"duration": 5}}, {"accelerate": {"to_speed": 10.0, "accel": 1.0}},
         {"turn": {"angle": 90, "radius": 30}}, {"straight": {"duration": 20}}]
GROUP = {"bias": 0.01, "scale_factor": 0.002, "random_walk": 1e-4, "ramp": 1e-5,
         "noise_density": 0.0, "misalignment": 0.0}


def _generated(output: str = "rate", faults: list | None = None):
    data = scenario_data(DRIVE, sensors={
        "imu": {"preset": "ideal", "rate": 100, "output": output, "gyro": GROUP,
                "accel": GROUP, **({"rate_sampling": "point"} if output == "rate" else {})},
        "odometer": {"preset": "ideal", "rate": 10, "scale_factor": 1.02,
                     "scale_drift": 1e-3}}, faults=faults or [])
    return generate_streams(data, show_progress=False)


def test_imu_bias_and_scale_factor_are_what_the_samples_carry():
    g = _generated()
    truth, imu, sensors = g.streams["truth"], g.streams["imu"], g.streams["truth_sensors"]
    assert list(sensors.columns[:1]) == ["t"] and set(sensors.columns) <= set(col.TRUTH_SENSORS)
    assert np.allclose(np.diff(sensors["t"]), 1.0 / TRUE_ERROR_RATE_HZ)
    at = np.searchsorted(imu["t"].to_numpy(), sensors["t"].to_numpy())
    on_truth = np.searchsorted(truth["t"].to_numpy(), sensors["t"].to_numpy())
    for group, true_axes in (("gyro", ("wx", "wy", "wz")), ("accel", ("fx", "fy", "fz"))):
        for axis, true_col in zip("xyz", true_axes, strict=True):
            measured = imu[f"{group}_{axis}"].to_numpy()[at]
            x = truth[true_col].to_numpy()[on_truth]
            sf = sensors[f"{group}_scale_factor_{axis}"].to_numpy()
            bias = sensors[f"{group}_bias_{axis}"].to_numpy()
            np.testing.assert_allclose(measured - (1.0 + sf) * x, bias, rtol=0, atol=1e-12)
            assert np.ptp(bias) > 0  # the random walk and the ramp move it


def test_odometer_scale_factor_is_the_measured_to_true_speed_ratio():
    g = _generated(faults=[{"kind": "odometer_scale_change", "scale_change": 0.05,
                            "start": 20.0, "duration": 5.0}])
    odo, truth, sensors = g.streams["odometer"], g.streams["truth"], g.streams["truth_sensors"]
    t = odo["t"].to_numpy()
    true_speed = np.interp(t, truth["t"], truth["speed"])
    moving = true_speed > 1.0
    ratio = odo["speed"].to_numpy()[moving] / true_speed[moving]
    expected = np.interp(t[moving], sensors["t"], sensors["odometer_scale_factor"])
    np.testing.assert_allclose(ratio, expected, rtol=1e-9)
    in_fault = (t[moving] >= 20.0) & (t[moving] < 25.0)
    assert in_fault.any() and expected[in_fault].min() > 1.06


def test_imu_bias_step_fault_shows_in_the_true_bias():
    step = {"kind": "imu_bias_step", "axes": ["gyro_z"], "gyro": 0.05, "start": 10.0,
            "duration": 4.0}
    plain, stepped = _generated(), _generated(faults=[step])
    t = plain.streams["truth_sensors"]["t"].to_numpy()
    diff = (stepped.streams["truth_sensors"]["gyro_bias_z"]
            - plain.streams["truth_sensors"]["gyro_bias_z"]).to_numpy()
    np.testing.assert_allclose(diff, np.where((t >= 10.0) & (t < 14.0), 0.05, 0.0), atol=1e-15)


def test_receiver_clock_matches_truth_gnss(tmp_path):
    out = generate_dataset(load_scenario(QUICKSTART), tmp_path / "q", show_progress=False)
    ds = open_dataset(out)
    sensors, truth_gnss = ds.read("truth_sensors"), ds.read("truth_gnss")
    assert ds.units("truth_sensors")["gyro_bias_x"] == "rad/s"
    clock = truth_gnss.groupby("t")[["receiver_clock", "receiver_clock_drift"]].first()
    common = np.intersect1d(np.round(sensors["t"], 6), np.round(clock.index, 6))
    assert len(common) > 100
    s = sensors.set_index(np.round(sensors["t"], 6)).loc[common]
    c = clock.set_index(np.round(clock.index, 6)).loc[common]
    np.testing.assert_allclose(s["clock_bias"], c["receiver_clock"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(s["clock_drift"], c["receiver_clock_drift"], rtol=0, atol=1e-9)
    assert "truth_sensors" in ds.manifest["streams"]


@pytest.mark.parametrize(("output", "gyro_unit", "accel_unit"),
                         [("rate", "rad/s", "m/s^2"), ("increment", "rad", "m/s")])
def test_imu_unit_metadata_says_what_the_output_is(tmp_path, output, gyro_unit, accel_unit):
    scenario = load_scenario(QUICKSTART, overrides=[f"sensors.imu.output={output}"])
    ds = open_dataset(generate_dataset(scenario, tmp_path / output, show_progress=False))
    units = ds.units("imu")
    assert [units[a] for a in col.IMU_AXES] == [gyro_unit] * 3 + [accel_unit] * 3
    # the true biases stay rates whatever the output
    assert ds.units("truth_sensors")["gyro_bias_z"] == "rad/s"
