"""The side slip lagging the path over the rear axle's distance (``RoadProfile.slip_relaxation``,
SUMO drives; ``simulator.vehicle.body.relaxed_slip``): the kinematic bicycle model's rear wheel
rolling along the body (Rajamani 2012, section 2.2), against its closed-form solution and
against the truth's own rear-axle velocity."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from simulator.dataset.generate import build_drive
from simulator.vehicle.body import relaxed_slip
from simulator.vehicle.params import vehicle_parameters
from tests.conftest import scenario_data
from tests.vehicle.test_vehicle import QUIET, _body_velocity

L_R = 2.7 * 0.57  # the automotive preset's centre of gravity ahead of the rear axle, m


def test_slip_lag_of_a_clothoid_is_the_closed_form():
    """A steady state growing linearly with the distance (a clothoid entered at constant speed),
    beta_ss = b s, gives dbeta/ds = (b s - beta) / l_r, beta(0) = 0: beta = b (s - l_r (1 -
    e^(-s / l_r))), lagging b s by b l_r once the transient has gone; its rates follow from
    the equation. The grid's steps vary (a stop on the way: the lag holds still), and the
    drive is long enough for several closed-form blocks."""
    v0, b = 2.0, 0.05
    t = np.linspace(0.0, 400.0, 40001)
    v = np.where((t > 100) & (t < 130), 0.0, v0)  # a 30 s stop
    s = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
    a = np.zeros_like(t)
    steady = (b * s, b * v, np.zeros_like(t))
    beta, rate, accel = relaxed_slip(s, v, a, steady, L_R)
    exact = b * (s - L_R * -np.expm1(-s / L_R))
    np.testing.assert_allclose(beta, exact, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(rate, b * v * -np.expm1(-s / L_R), rtol=1e-9, atol=1e-10)
    np.testing.assert_allclose(accel, b * v**2 / L_R * np.exp(-s / L_R), rtol=1e-9, atol=1e-10)
    assert np.all(rate[v == 0] == 0.0)


def _walking_turn(relaxed: bool):
    """A right U-turn of 5 m radius at 2 m/s (clothoids of 3 m at the default lateral jerk):
    the truth table, the rear axle's sideways velocity (m/s) and the path's curvature under the
    centre of gravity (1/m)."""
    segments = [{"accelerate": {"to_speed": 2.0, "accel": 0.5}}, {"straight": {"length": 5}},
                {"turn": {"angle": 180, "radius": 5.0}}, {"straight": {"length": 5}}]
    data = scenario_data(segments, vehicle={**QUIET, "imu_position": [0.0, 0.0, 0.0]})
    drive = build_drive(data)
    if relaxed:
        drive = build_drive(data, replace(drive.profile, slip_relaxation=True))
    table = drive.truth.table()
    v_body = _body_velocity(table)
    kappa = drive.profile.curvature(table.distance.to_numpy())
    return table, v_body[:, 1] - table.wz.to_numpy() * L_R, kappa  # v + w x r, r = (-l_r, 0, 0)


def test_the_rear_axle_rolls_along_the_body_through_a_junction_turn():
    """With the steady-state slip taken at once, the rear axle slides sideways by
    l_r^2 v dkappa/ds in the turn's clothoids: 0.3-0.6 m/s at 2 m/s into a 5 m radius. With
    the lag, what is left is the rear tyres' slip, gain v^3 kappa (gain = m l_f / (L C_r),
    0.0065 m/s here), and the body's sway on its tyres: under 0.03 m/s. On the arc the slip
    reaches the steady state l_r kappa - gain v^2 kappa (within 2 % once 3 l_r into it)."""
    _, steady_rear, _ = _walking_turn(relaxed=False)
    table, rear, kappa = _walking_turn(relaxed=True)
    assert np.abs(steady_rear).max() > 0.3
    assert np.abs(rear).max() < 0.03
    p = vehicle_parameters("automotive")
    gain = p["mass"] * p["wheelbase"] * (1 - p["front_weight"]) / (
        p["wheelbase"] * p["rear_cornering"])
    expected = (L_R - gain * 4.0) / 5.0
    distance = table.distance.to_numpy()
    on_arc = np.flatnonzero(np.abs(kappa - 1 / 5.0) < 1e-9)
    settled = on_arc[distance[on_arc] > distance[on_arc[0]] + 3 * L_R]
    assert len(settled) > 100
    v_body = _body_velocity(table)[settled]
    np.testing.assert_allclose(np.arctan2(v_body[:, 1], v_body[:, 0]), expected, rtol=0.02)
