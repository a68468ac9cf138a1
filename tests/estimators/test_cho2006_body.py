"""The body roll that ``dr2d_drm1_ekf``'s ``tuning: datasheet`` removes from its y
accelerometer (``cho2006_tuning``: the body rolls out of a turn by ROLL_GRADIENT per lateral
acceleration, and the y accelerometer senses gravity's share g k V w_z) against the simulator's
own body (``simulator.vehicle``: the full-car ride model's roll on its springs and anti-roll
bars, an implementation the filter does not share): on slow 10 m and 15 m turns the truth's
lateral specific force carries g sin(-roll) beside the turn's acceleration, whose slope in
V w_z lies within the filter's prior, and the compensation removes most of it."""

from __future__ import annotations

import numpy as np

from estimators.builtin.cho2006_tuning import G0, ROLL_GRADIENT, ROLL_GRADIENT_SPREAD
from simulator.pipeline import generate, load_scenario

SCENARIO = """
name: roll-turn
seed: 1
start: {utc: 2024-01-01T12:00:00Z, lat: 45.0, lon: 7.0, alt: 200.0, heading: 0.0}
trajectory:
  kind: segments
  segments:
    - stop: {duration: 2}
    - accelerate: {to_speed: 6.0, accel: 1.5}
    - turn: {angle: 180, radius: 10}
    - straight: {length: 20}
    - turn: {angle: -90, radius: 15}
    - accelerate: {to_speed: 0.0, accel: 2.0}
sensors:
  imu: {preset: automotive, rate: 100}
estimators: []
"""


def test_the_body_rolls_out_of_a_turn_as_the_filter_removes(tmp_path):
    path = tmp_path / "turn.yaml"
    path.write_text(SCENARIO)
    truth = generate(load_scenario(path, [], 1), tmp_path / "ds").read("truth")
    speed, wz, roll = (truth[k].to_numpy() for k in ("speed", "wz", "roll"))
    lateral = speed * wz  # the turn's acceleration, V w_z
    turning = np.abs(wz) > 0.2
    assert turning.sum() > 300 and np.abs(lateral).max() > 2.0
    share = -G0 * np.sin(roll)  # the roll's gravity share in the y accelerometer
    slope, offset = np.polyfit(lateral[turning], share[turning], 1)
    # the body's roll gradient (truth) within two spreads of the filter's prior, g k
    assert abs(slope - G0 * ROLL_GRADIENT) < 2 * G0 * ROLL_GRADIENT_SPREAD, slope
    # removing g k V w_z leaves a fraction of the share that varies through the turns
    raw = share[turning] - offset
    compensated = raw - G0 * ROLL_GRADIENT * lateral[turning]
    assert np.sqrt(np.mean(compensated**2)) < 0.5 * np.sqrt(np.mean(raw**2))
