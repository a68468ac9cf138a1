"""``ins_odo_ekf``'s ``tuning: datasheet`` against the simulator's car and odometer, models the
filter does not share (``simulator.vehicle``, ``simulator.sensors.odometer``):

* the odometer's speed is ``toolbox.datasheet.odometer_delay_s`` old: the ``automotive`` CAN
  speed (tooth timing at 50 Hz, 20 ms latency) is the mean between the tooth edges of its last
  interval, half an interval (10 ms) older than its latency; least squares of the speed on the
  truth's speed and acceleration give the delay; below 4 m/s, where the edges (42.5 mm apart)
  come less often than twice an interval, the speed is timed over the last edge pair and its
  age is the latency plus the edges' spacing in time (``odometer_window_s`` at the reading);
* on a stop-and-go drive (hard starts and stops, as at the lights of a city) the filter knows
  its velocity error: the body's squat on its springs under each acceleration tilts the rear
  axle's velocity off the body's x axis by k a (a constant of the car, a state, not white noise
  at 50 Hz), and the odometer's delay times the acceleration is taken out of its prediction.
  Measured on this drive, seed 1, mean (error / sigma)^2 after 60 s: in the last test.
"""

from __future__ import annotations

import numpy as np
import pytest

from estimators.toolbox.datasheet import odometer_delay_s
from simulator.pipeline import estimate, generate, load_scenario
from simulator.scoring.consistency import normalised_errors

CYCLE = """
    - accelerate: {to_speed: 14.0, accel: 2.0}
    - straight: {length: 60}
    - accelerate: {to_speed: 0.0, accel: 2.0}
    - stop: {duration: 4}"""
SCENARIO = """
name: stop-and-go
seed: 1
start: {utc: 2024-01-01T12:00:00Z, lat: 45.0, lon: 7.0, alt: 200.0, heading: 0.0}
trajectory:
  kind: segments
  segments:
    - stop: {duration: 5}""" + CYCLE * 6 + """
sensors:
  imu: {preset: automotive, rate: 100}
  odometer: {preset: automotive}
  gnss: {preset: automotive, rate: 1}
estimators: []
"""


@pytest.fixture(scope="module")
def stop_and_go(tmp_path_factory):
    folder = tmp_path_factory.mktemp("stopgo")
    path = folder / "stop_and_go.yaml"
    path.write_text(SCENARIO)
    return generate(load_scenario(path, [], 1), folder / "ds")


def test_the_odometer_delay_is_its_latency_and_half_its_window(stop_and_go):
    truth, odo = stop_and_go.read("truth"), stop_and_go.read("odometer")
    t, u = odo["t"].to_numpy(), odo["speed"].to_numpy()
    speed = np.interp(t, truth["t"], truth["speed"])
    accel = np.interp(t, truth["t"], np.gradient(truth["speed"].to_numpy(),
                                                 truth["t"].to_numpy()))
    moving = speed > 4.0  # where the edges are dense (at 1-4 m/s the window is longer)
    x = np.c_[speed, accel][moving]
    (scale, slope), *_ = np.linalg.lstsq(x, u[moving], rcond=None)
    residual = u[moving] - x @ np.array([scale, slope])
    # the delay's standard error from the fit (the residual's scatter over the acceleration's)
    cov = np.linalg.inv(x.T @ x) * residual.var()
    delay, delay_se = -slope / scale, np.sqrt(cov[1, 1]) / scale
    expected = odometer_delay_s(stop_and_go.manifest["datasheet"])
    assert abs(delay - expected) < max(4 * delay_se, 1e-3), (delay, delay_se, expected)
    assert abs(expected - 0.030) < 1e-9  # 20 ms latency + half of the 20 ms interval


@pytest.mark.parametrize("band", [(0.6, 1.5), (1.5, 3.0)])
def test_a_slow_can_speed_is_as_old_as_its_edges_are_apart(stop_and_go, band):
    """The delay fitted on the readings in a band of speed (m/s) against the mean of
    ``odometer_delay_s`` at those readings: 20 ms + 42.5 mm / v (62 ms at 1 m/s), not the
    30 ms of dense edges."""
    truth, odo = stop_and_go.read("truth"), stop_and_go.read("odometer")
    t, u = odo["t"].to_numpy(), odo["speed"].to_numpy()
    speed = np.interp(t, truth["t"], truth["speed"])
    accel = np.interp(t, truth["t"], np.gradient(truth["speed"].to_numpy(),
                                                 truth["t"].to_numpy()))
    inside = (u > band[0]) & (u < band[1]) & (np.abs(accel) > 1.0)
    sheet = stop_and_go.manifest["datasheet"]
    expected = np.array([odometer_delay_s(sheet, v) for v in u[inside]])
    # the reading's scale from the dense edges, then the delay: u / scale = speed - delay a
    fast = speed > 4.0
    scale = np.linalg.lstsq(np.c_[speed, accel][fast], u[fast], rcond=None)[0][0]
    lag = (speed[inside] - u[inside] / scale) / accel[inside]
    standard_error = lag.std() / np.sqrt(inside.sum())
    assert inside.sum() > 100
    assert abs(lag.mean() - expected.mean()) < 4 * standard_error + 1e-3, (
        lag.mean(), standard_error, expected.mean())
    # and distinguishably older than the 30 ms of dense edges
    assert lag.mean() - odometer_delay_s(sheet) > 4 * standard_error


def test_ins_odo_ekf_knows_its_velocity_error_through_starts_and_stops(stop_and_go):
    solution, _ = estimate(stop_and_go, "ins_odo_ekf")
    nse = normalised_errors(stop_and_go.read("truth"), solution)
    print({k: round(v, 2) for k, v in nse.items()})
    # before the squat state and the delay: vn 28.9, vd 8.1, roll 10.2; after: vn 3.8, vd 0.5,
    # roll 4.1; with the slow CAN speed's age (odometer_window_s at the reading) and the fix's
    # drive-long part from its report: vn 1.25, vd 0.64, roll 4.66, pitch 3.37 (seed 1; roll
    # and pitch still above the goal of 3, below the ceiling of 10)
    assert all(v < 10.0 for v in nse.values()), nse
    assert nse["vd"] < 3.0, nse
