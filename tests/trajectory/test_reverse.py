"""Reverse driving: the ``reverse`` segment's geometry against plane geometry, the strapdown
closure of its kinematics, the signed odometer and the dead reckoning that uses it."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest
from conftest import scenario_data

from simulator import earth
from simulator.cli import main
from simulator.dataset.generate import build_truth
from simulator.dataset.io import open_dataset
from simulator.replay import run_estimator
from simulator.sensors import resolve_block
from simulator.sensors.imu import Imu
from simulator.tables import as_frame
from tests.scoring_helpers import horizontal_error
from tests.sensors.test_odometer import make as make_odometer
from tests.synthetic import scenario, write_synthetic
from tests.trajectory.test_kinematics import _closure

REVERSES = {"r1": 20.0, "r2": 15.0, "r3": 12.0, "r4": 4.0}
SEGMENTS = [
    {"stop": {"duration": 2}},
    {"accelerate": {"to_speed": 8.0, "accel": 1.0}},
    {"straight": {"length": 60}},
    # while moving: preceded by an automatic stop
    {"reverse": {"length": REVERSES["r1"], "zone": "r1"}},
    # steering right: the rear swings right, the heading turns 90 deg left
    {"reverse": {"length": REVERSES["r2"], "angle": 90, "radius": 6, "zone": "r2"}},
    # no radius: the curve fills the whole length
    {"reverse": {"length": REVERSES["r3"], "angle": -60, "speed": 1.5, "zone": "r3"}},
    {"stop": {"duration": 2}},
    {"accelerate": {"to_speed": 6.0, "accel": 1.0}},
    {"turn": {"angle": 90, "radius": 20}},
    {"straight": {"length": 30}},
    # too short to reach its speed: a lower peak
    {"reverse": {"length": REVERSES["r4"], "speed": 3.0, "zone": "r4"}},
    {"stop": {"duration": 2}},
]
IDEAL_IMU = {"preset": "ideal", "rate": 100.0, "output": "increment",
             "axes": ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]}


@pytest.fixture(scope="module")
def truth():
    # a rigid body: these tests check the reversing geometry and signs exactly
    return build_truth(scenario_data(SEGMENTS, vehicle="rigid"))


def _span(truth, name: str) -> tuple[float, float]:
    """Start and end time of the reversing inside zone ``name`` (the zone of ``r1`` also
    holds the automatic stop before it)."""
    (start, end), = [(a, b) for a, b, z in truth.profile.zones if z == name]
    t = np.linspace(start, end, 20001)
    back = np.flatnonzero(truth.profile.direction_at(t) < 0)
    return float(t[back[0]]), end


def _ned(truth, t: np.ndarray, t0: float) -> np.ndarray:
    """NED position (m) at times t relative to the position at t0, from the geodetic truth."""
    tab = truth.table(np.concatenate([[t0], t]))
    ecef = earth.geodetic_to_ecef(np.radians(tab.lat), np.radians(tab.lon), tab.alt)
    return earth.ecef_to_ned(ecef, np.radians(tab.lat.iloc[0]), np.radians(tab.lon.iloc[0]),
                             tab.alt.iloc[0])[1:]


def test_strapdown_closure_with_reversing(truth):
    """The same bounds as the forward ten-minute drive (tests/trajectory/test_kinematics.py): an
    independent NED strapdown of the ideal IMU closes on the truth through four reverses."""
    imu = Imu(resolve_block("imu", IDEAL_IMU))
    err = _closure(truth, as_frame(imu.generate(truth, None)["imu"]), increments=True)
    assert err["horizontal"] < 0.1
    assert err["vertical"] < 0.1
    assert err["yaw_deg"] < 1e-4
    assert err["tilt_deg"] < 1e-4
    assert err["velocity"] < 1e-3


def test_straight_reverse_moves_back_by_length(truth):
    for name in ("r1", "r4"):
        t0, t1 = _span(truth, name)
        yaw = truth.table(np.array([t0, t1])).yaw.to_numpy()
        assert yaw[1] == pytest.approx(yaw[0], abs=1e-12)
        moved = _ned(truth, np.array([t1]), t0)[0]
        expected = -REVERSES[name] * np.array([np.cos(yaw[0]), np.sin(yaw[0]), 0.0])
        np.testing.assert_allclose(moved, expected, atol=1e-4)


def test_reverse_arc_heading_radius_and_side(truth):
    # r2: angle 90, radius 6: the heading changes by -90 deg, the path curvature peaks at
    # 1/6 per metre, and the rear ends up behind and to the right of where it started
    t0, t1 = _span(truth, "r2")
    tab = truth.table(np.linspace(t0, t1, 4001))
    turned = np.degrees(np.unwrap(tab.yaw.to_numpy()))
    assert turned[-1] - turned[0] == pytest.approx(-90.0, abs=1e-9)
    assert tab.distance.iloc[-1] - tab.distance.iloc[0] == pytest.approx(15.0, abs=1e-9)
    earth_z = earth.OMEGA_E_RAD_S * np.sin(np.radians(37.5))  # Earth rate on body z, bound
    moving = np.abs(tab.speed.to_numpy()) > 0.5
    curvature = np.abs(tab.wz.to_numpy()[moving] / tab.speed.to_numpy()[moving])
    assert curvature.max() == pytest.approx(1 / 6, abs=earth_z / 0.5 + 1e-9)
    moved = _ned(truth, np.array([t1]), t0)[0]
    yaw0 = tab.yaw.iloc[0]
    forward = moved[0] * np.cos(yaw0) + moved[1] * np.sin(yaw0)
    right = -moved[0] * np.sin(yaw0) + moved[1] * np.cos(yaw0)
    assert forward < -5.0 and right > 3.0
    # the centre of the circle is on the right, as when driving forward with right steering:
    # centripetal acceleration + body y, and the car leans out (roll < 0)
    assert tab.fy.max() > 0.6 and tab.fy.min() > -1e-3 and tab.roll.max() <= 0.0
    # r3: angle -60, no radius: the heading turns +60 deg over the whole 12 m
    t0, t1 = _span(truth, "r3")
    yaw = np.degrees(np.unwrap(truth.table(np.linspace(t0, t1, 2001)).yaw.to_numpy()))
    assert yaw[-1] - yaw[0] == pytest.approx(60.0, abs=1e-9)


def test_velocity_along_minus_body_x_while_reversing(truth):
    tab = truth.table()
    c_bn = earth.euler_to_dcm(tab.roll.to_numpy(), tab.pitch.to_numpy(), tab.yaw.to_numpy())
    v_body = np.einsum("nji,nj->ni", c_bn, tab[["vn", "ve", "vd"]].to_numpy())
    assert np.abs(v_body[:, 1:]).max() < 1e-12  # non-holonomic constraint
    np.testing.assert_allclose(v_body[:, 0], tab.speed, atol=1e-12)
    back = truth.profile.direction_at(tab.t.to_numpy()) < 0
    assert tab.speed[back].max() == 0.0 and tab.speed[back].min() == pytest.approx(-2.0)
    assert tab.speed[~back].min() == 0.0
    assert not np.signbit(tab.speed[tab.speed == 0.0]).any()  # +0.0 at rest, never -0.0
    # the fourth reverse (4 m) is too short to reach 3 m/s: up and straight down again
    t0, t1 = _span(truth, "r4")
    assert -3.0 < tab.speed[(tab.t >= t0) & (tab.t <= t1)].min() < -1.5
    # speed and acceleration continuous through every change of direction
    assert np.abs(np.diff(tab.speed)).max() < 0.011
    assert np.abs(np.diff(tab.fx)).max() < 0.016


@pytest.mark.parametrize("block", [
    {"rate": 10.0, "scale_factor": 1.02, "ticks_per_meter": 20.0},
    {"rate": 50.0, "scale_factor": 0.97},
])
def test_odometer_is_signed_and_sums_to_net_displacement(truth, block):
    out = as_frame(make_odometer(block).generate(truth, np.random.default_rng(1))["odometer"])
    speed = out["speed"].to_numpy()
    # net displacement along the path: distance travelled minus twice what was backed up
    travelled = truth.table(np.array([truth.duration_s])).distance.iloc[0]
    net = travelled - 2 * sum(REVERSES.values())
    if "ticks_per_meter" in block:
        wheel = np.sum(speed) / block["rate"]
        assert abs(wheel - block["scale_factor"] * net) <= 1.0 / block["ticks_per_meter"]
        assert (out["ticks"] < 0).sum() > 50
    else:  # the instantaneous speed integrated by the trapezoidal rule (error O(dt^2))
        wheel = np.sum(0.5 * (speed[1:] + speed[:-1])) / block["rate"]
        assert wheel == pytest.approx(block["scale_factor"] * net, abs=2e-3)
        ref = truth.table(out["t"].to_numpy()).speed.to_numpy()
        np.testing.assert_allclose(speed, block["scale_factor"] * ref, atol=1e-12)
    assert speed.min() < -1.0
    still = truth.table(out["t"].to_numpy()).speed.to_numpy() == 0.0
    assert still.sum() > 20 and np.all(speed[still] == 0.0)
    assert not np.signbit(speed[speed == 0.0]).any()


def test_dead_reckoning_follows_reversing(tmp_path):
    """Ideal IMU and the exact signed speed at 10 Hz: the 2-D dead reckoning stays on the
    level drive through the reverses (off by metres if it took the speed as unsigned)."""
    data = scenario(SEGMENTS, imu_output="rate")
    data["limits"]["roll_gradient"] = 0.0  # level body: only integration error remains
    ds = open_dataset(write_synthetic(tmp_path / "ds", data, streams=("imu", "odometer")))
    truth = ds.read("truth")
    assert truth["speed"].min() < -1.9
    solution, _ = run_estimator(ds, "dead_reckoning", show_progress=False)
    assert horizontal_error(solution, truth).max() < 0.01


@pytest.mark.parametrize("segment, words", [
    ("reverse: {length: 10, angle: 90, radius: 0.4}", "lateral acceleration"),
    ("reverse: {length: 3, angle: 180, radius: 5}", "more than length"),
    ("reverse: {length: 0}", "greater than"),
])
def test_bad_reverse_is_named(tmp_path, capsys, segment, words):
    path = tmp_path / "scenario.yaml"
    path.write_text(textwrap.dedent(f"""\
        name: bad
        start: {{utc: 2024-05-01T03:00:00Z, lat: 37.5, lon: 127.0, alt: 40.0, heading: 0.0}}
        trajectory:
          kind: segments
          segments:
            - accelerate: {{to_speed: 5, accel: 1.0}}
            - {segment}
        """))
    code = main(["validate", str(path)])
    out = capsys.readouterr()
    text = out.err + out.out
    assert code == 2 and "trajectory.segments.1.reverse" in text and words in text, text
