"""The manifest separates what a user knows from the drawn truth, and states each stream's
timing; the stated odometer delay is measured independently on the samples."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.toolbox.installation import Installation
from simulator.dataset.generate import build_manifest, generate_streams
from simulator.scenario import Scenario
from tests.conftest import scenario_data

DRIVE = [{"stop": {"duration": 2}}, {"accelerate": {"to_speed": 20.0, "accel": 1.0}},
         {"straight": {"duration": 5}}]


def _generated(odometer: dict):
    data = scenario_data(DRIVE, sensors={"imu": {"preset": "ideal", "rate": 100},
                                         "odometer": odometer})
    return data, generate_streams(data, show_progress=False)


def test_odometer_delay_in_the_manifest_is_the_delay_of_its_samples():
    rate, latency = 10.0, 0.02
    data, g = _generated({"preset": "ideal", "rate": rate, "ticks_per_meter": 1e6,
                          "latency": latency})
    manifest = build_manifest(Scenario(None, data, []), g)
    delay = manifest["timing"]["odometer"]["delay_s"]
    assert delay == pytest.approx(latency + 0.5 / rate)
    assert "end of the tick-counting interval" in manifest["timing"]["odometer"]["stamp"]
    odo, truth = g.streams["odometer"], g.streams["truth"]
    t = odo["t"].to_numpy()
    true_speed = np.interp(t, truth["t"], truth["speed"])
    accel = np.gradient(truth["speed"].to_numpy(), truth["t"].to_numpy())
    steady = np.interp(t, truth["t"], accel)
    ramp = (np.abs(steady - 1.0) < 1e-9) & (t > 5.0)  # constant acceleration of 1 m/s^2
    assert ramp.sum() > 50
    # a speed that is `delay` old lags the truth by accel * delay
    measured = (true_speed[ramp] - odo["speed"].to_numpy()[ramp]) / 1.0
    assert np.median(measured) == pytest.approx(delay, abs=1e-4)


def test_datasheet_has_the_nominal_scale_factor_and_truth_the_drawn_one():
    data, g = _generated({"preset": "abs-wheel-speed"})
    manifest = build_manifest(Scenario(None, data, []), g)
    assert manifest["datasheet"]["odometer"]["scale_factor"] == 1.0
    assert manifest["truth_parameters"]["odometer"]["scale_factor"] == pytest.approx(1.01)
    assert manifest["datasheet"]["odometer"]["latency"] == pytest.approx(0.02)
    assert manifest["datasheet"]["imu"] == data["sensors"]["imu"]
    assert {"scenario", "sensors", "truth_parameters"} <= set(manifest["knowledge"]["truth"])
    assert {"datasheet", "timing"} <= set(manifest["knowledge"]["user"])
    # rates are interval means at 100 Hz: half a sample late
    assert manifest["timing"]["imu"] == {
        "stamp": "the end of the integration interval (t - 1/rate, t]", "delay_s": 0.005}


def test_datasheet_carries_the_installation_geometry():
    """The car as its user measures it: the automotive preset's rear axle lies l_r = 0.57 x
    2.7 m behind the centre of gravity, the IMU 0.2 m ahead of it and 0.1 m above, so the rear
    axle is 1.739 m behind the IMU and 0.1 m below it; a rigid body has no rear axle. An
    estimator reads it back with ``Installation``."""
    data, g = _generated({"preset": "ideal"})
    data = dict(data, vehicle="automotive")
    sheet = build_manifest(Scenario(None, data, []), g)["datasheet"]
    vehicle = sheet["vehicle"]
    assert vehicle["preset"] == "automotive" and vehicle["wheelbase"] == 2.7
    np.testing.assert_allclose(vehicle["imu_position"], [0.2, 0.0, -0.1])
    np.testing.assert_allclose(vehicle["rear_axle"], [-0.57 * 2.7 - 0.2, 0.0, 0.1])
    site = Installation.from_datasheet(sheet)
    np.testing.assert_allclose(site.rear_axle, vehicle["rear_axle"])
    assert site.wheelbase == 2.7 and site.antenna is None and site.mounting is None
    rigid = build_manifest(Scenario(None, dict(data, vehicle="rigid"), []), g)["datasheet"]
    assert rigid["vehicle"] == {"preset": "rigid"}
    assert Installation.from_datasheet(rigid).rear_axle is None
