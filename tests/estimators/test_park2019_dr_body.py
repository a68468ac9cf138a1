"""The car-body velocity model of ``dr3d_ekf``'s ``tuning: datasheet``
(``park2019_dr.car_body_velocity``: the rear axle rolls along the body's x axis, the IMU ahead
of it moves sideways at w_z L, the body squats by k a) against the simulator's own body model
(``simulator.vehicle``: the steady-state linear bicycle model's side slip, Rajamani 2012 eq.
3.45, and the full-car ride model's pitch), an implementation the filter does not share: on a
slow 8 m turn and the accelerations around it, the sideways velocity of the IMU is w_z L to
within the tyres' slip the filter takes as noise, and the body's squat per m/s^2 lies within
the filter's prior on it."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.builtin.park2019_dr import ACCEL_WINDOW_S, G0, car_body_velocity
from estimators.toolbox.constraints import NonholonomicNoise
from estimators.toolbox.datasheet import ODOMETER_FLOOR_M_S
from estimators.toolbox.installation import Installation
from simulator.earth import euler_to_dcm
from simulator.pipeline import generate, load_scenario

SCENARIO = """
name: body-turn
seed: 1
start: {utc: 2024-01-01T12:00:00Z, lat: 45.0, lon: 7.0, alt: 200.0, heading: 0.0}
trajectory:
  kind: segments
  segments:
    - stop: {duration: 3}
    - accelerate: {to_speed: 4.0, accel: 1.5}
    - turn: {angle: 180, radius: 8}
    - accelerate: {to_speed: 12.0, accel: 2.0}
    - straight: {length: 40}
    - accelerate: {to_speed: 0.0, accel: 2.5}
    - stop: {duration: 2}
sensors:
  imu: {preset: automotive, rate: 100}
  odometer: {preset: automotive}
estimators: []
"""


@pytest.fixture(scope="module")
def drive(tmp_path_factory):
    folder = tmp_path_factory.mktemp("body")
    path = folder / "turn.yaml"
    path.write_text(SCENARIO)
    ds = generate(load_scenario(path, [], 1), folder / "ds")
    truth = ds.read("truth")
    c_bn = euler_to_dcm(*(truth[k].to_numpy() for k in ("roll", "pitch", "yaw")))
    v_body = np.einsum("nji,nj->ni", c_bn, truth[["vn", "ve", "vd"]].to_numpy())
    return truth, v_body, Installation.from_datasheet(ds.manifest["datasheet"])


def test_the_imu_moves_sideways_at_yaw_rate_times_its_distance_from_the_rear_axle(drive):
    truth, v_body, site = drive
    rear_lever = -site.rear_axle[0]
    odo_lever = site.odometer[0] - site.rear_axle[0]
    speed, wz = truth["speed"].to_numpy(), truth["wz"].to_numpy()
    model = np.array([car_body_velocity(s, w, rear_lever, odo_lever, 0.0, 0.0)
                      for s, w in zip(speed, wz, strict=True)])
    turning = np.abs(wz) > 0.2  # 4 m/s on 8 m: 0.5 rad/s
    assert turning.sum() > 300
    lateral = v_body[turning, 1]
    residual = lateral - model[turning, 1]
    # Park's model (no sideways velocity) leaves the whole w_z L, about 0.85 m/s (11 deg)
    assert np.sqrt(np.mean(lateral**2)) > 0.7
    # the kinematic model leaves the tyres' slip: within 3 sigma of the filter's noise for it
    car = NonholonomicNoise(site.wheelbase)
    sigma = np.array([car.sigma(s, w, 0.0)[0] for s, w in zip(speed[turning], wz[turning],
                                                              strict=True)])
    assert np.mean(np.abs(residual) < 3 * sigma) > 0.99
    assert np.sqrt(np.mean(residual**2)) < 0.15 * np.sqrt(np.mean(lateral**2))
    # and the speed along x: the odometer's point (the centre of gravity) runs at the speed;
    # the body's surge on its tyres is within the odometer's floor the filters take as noise
    np.testing.assert_allclose(model[turning, 0], v_body[turning, 0], atol=ODOMETER_FLOOR_M_S)


def test_the_body_squat_per_acceleration_lies_within_the_filters_prior(drive):
    truth, v_body, site = drive
    t, speed = truth["t"].to_numpy(), truth["speed"].to_numpy()
    accel = np.gradient(speed, t)
    straight = (np.abs(truth["wz"].to_numpy()) < 0.01) & (speed > 2.0)
    # the path's angle below the body's x axis against the forward acceleration
    angle, a = v_body[straight, 2] / v_body[straight, 0], accel[straight]
    assert np.abs(a).max() > 1.9
    squat = float(np.sum(angle * a) / np.sum(a * a))
    prior = NonholonomicNoise(site.wheelbase).pitch_compliance  # the filter's 1-sigma
    assert 0.0 < squat < 2 * prior, (squat, prior)
    # with it the angle is explained: what is left is small beside k a at the largest a
    residual = angle - squat * a
    assert np.sqrt(np.mean(residual**2)) < 0.3 * squat * np.abs(a).max()


def test_the_g_slave_tilt_over_the_odometer_window_has_no_lag(drive):
    """The g-slave's specific force less the odometer's acceleration (the speed's difference
    over ACCEL_WINDOW_S, the mean acceleration over that window): the window's mean specific
    force against it leaves gravity's share, g sin(pitch) averaged over the window, to the
    body's own vibration; the step's own specific force against it (the earlier design)
    leaves the acceleration's change over half the window, a jerk's error of one sign."""
    truth, _, _ = drive
    t, speed, fx = (truth[k].to_numpy() for k in ("t", "speed", "fx"))
    dt = float(np.median(np.diff(t)))
    n = int(round(ACCEL_WINDOW_S / dt))
    window_accel = (speed[n:] - speed[:-n]) / (t[n:] - t[:-n])
    window_fx = np.convolve(fx, np.ones(n) / n, mode="valid")[1:]  # samples (k - n, k]
    gravity = G0 * np.sin(truth["pitch"].to_numpy())
    window_gravity = np.convolve(gravity, np.ones(n) / n, mode="valid")[1:]
    matched = window_fx - window_accel - window_gravity
    lagged = fx[n:] - window_accel - gravity[n:]
    jerk = np.abs(np.gradient(np.gradient(speed, t), t)[n:]) > 1.0
    assert jerk.sum() > 50  # the drive's accelerations ramp in and out
    # in a jerk the lagged residual is a tenth of a g-slave degree or more; the matched one
    # is ten times smaller (m/s^2: 0.017 per degree of tilt)
    assert np.sqrt(np.mean(lagged[jerk] ** 2)) > 0.1
    assert np.sqrt(np.mean(matched[jerk] ** 2)) < 0.1 * np.sqrt(np.mean(lagged[jerk] ** 2))
