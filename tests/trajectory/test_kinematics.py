"""Exact kinematics: the ideal IMU integrated by an independent strapdown closes on the truth,
and the road geometry does what the segments ask."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import scenario_data, ten_minute_drive
from scipy.integrate import quad

from estimators.toolbox.strapdown import rates_to_increments, run_strapdown
from simulator import earth
from simulator.dataset.generate import build_truth
from simulator.sensors import resolve_block
from simulator.sensors.imu import Imu
from simulator.tables import as_frame


@pytest.fixture(scope="module")
def drive():
    return build_truth(scenario_data(ten_minute_drive()))


def _closure(truth, imu_table, increments: bool):
    t = imu_table["t"].to_numpy()
    gyro = imu_table[["gyro_x", "gyro_y", "gyro_z"]].to_numpy()
    accel = imu_table[["accel_x", "accel_y", "accel_z"]].to_numpy()
    if increments:
        dtheta, dv, dt = gyro, accel, np.diff(np.concatenate([[0.0], t]))
        t_nav = np.concatenate([[0.0], t])
    else:
        dtheta, dt = rates_to_increments(t, gyro)
        dv, _ = rates_to_increments(t, accel)
        t_nav = t
    ref = truth.table(t_nav)
    first = ref.iloc[0]
    q, v, pos = run_strapdown(
        earth.euler_to_quat(first.roll, first.pitch, first.yaw),
        first[["vn", "ve", "vd"]].to_numpy(float),
        np.array([np.radians(first.lat), np.radians(first.lon), first.alt]), dtheta, dv, dt)
    rn, re = earth.radii_of_curvature(np.radians(ref.lat.to_numpy()))
    d_north = (pos[:, 0] - np.radians(ref.lat.to_numpy())) * (rn + ref.alt.to_numpy())
    d_east = ((pos[:, 1] - np.radians(ref.lon.to_numpy())) * (re + ref.alt.to_numpy())
              * np.cos(pos[:, 0]))
    roll, pitch, yaw = earth.quat_to_euler(q)
    return {
        "horizontal": np.max(np.hypot(d_north, d_east)),
        "vertical": np.max(np.abs(pos[:, 2] - ref.alt.to_numpy())),
        "yaw_deg": np.max(np.abs(np.degrees(earth.wrap_angle(yaw - ref.yaw.to_numpy())))),
        "tilt_deg": np.max(np.abs(np.degrees(np.concatenate([
            earth.wrap_angle(roll - ref.roll.to_numpy()), pitch - ref.pitch.to_numpy()])))),
        "velocity": np.max(np.abs(v - ref[["vn", "ve", "vd"]].to_numpy())),
    }


def test_drive_is_ten_minutes_with_every_manoeuvre(drive):
    assert 590.0 < drive.duration_s < 620.0
    table = drive.table()
    assert table.speed.max() == pytest.approx(12.0)
    assert np.degrees(table.pitch).min() < -4.0 and np.degrees(table.pitch).max() > 4.0


def test_strapdown_closure_ideal_increments(drive):
    """Issue 2's proof of the kinematics: a NED strapdown (Earth and transport rate, normal
    gravity) integrating the ideal 100 Hz IMU from truth stays within 1 m horizontally and
    0.1 deg in yaw over the whole ten-minute drive. Measured: 1.3 cm and 6e-8 deg on the rigid
    body; 1.2 cm and 8e-7 deg with the default automotive body on its class B road (issue 13),
    so the bounds asserted here are far stricter than the issues'."""
    imu = Imu(resolve_block("imu", {"preset": "ideal", "rate": 100.0, "output": "increment",
               "axes": ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]}))
    err = _closure(drive, as_frame(imu.generate(drive, None)["imu"]), increments=True)
    assert err["horizontal"] < 0.1
    assert err["vertical"] < 0.1
    assert err["yaw_deg"] < 1e-4
    assert err["tilt_deg"] < 1e-4
    assert err["velocity"] < 1e-3


def test_point_rate_output_samples_the_truth_exactly(drive):
    imu = Imu(resolve_block("imu", {"preset": "ideal", "rate": 50.0, "output": "rate",
                                    "rate_sampling": "point",
               "axes": ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]}))
    table = as_frame(imu.generate(drive, None)["imu"])
    ref = drive.table(table.t.to_numpy())
    np.testing.assert_array_equal(table[["gyro_x", "gyro_y", "gyro_z"]].to_numpy(),
                                  ref[["wx", "wy", "wz"]].to_numpy())
    np.testing.assert_array_equal(table.accel_z.to_numpy(), ref.fz.to_numpy())


def test_strapdown_closure_ideal_rates_smooth_drive():
    """Point rate samples integrated with trapezoidal increments: second-order accurate, so on a
    drive without the sharp speed bump the closure is still within a metre over six minutes."""
    segments = [s for s in ten_minute_drive() if "speed_bump" not in s][:-3]
    truth = build_truth(scenario_data(segments))
    imu = Imu(resolve_block("imu", {"preset": "ideal", "rate": 100.0, "output": "rate",
                                    "rate_sampling": "point",
               "axes": ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]}))
    err = _closure(truth, as_frame(imu.generate(truth, None)["imu"]), increments=False)
    assert err["horizontal"] < 1.0
    assert err["yaw_deg"] < 0.01


def test_standstill_reads_gravity_and_earth_rate():
    table = _drive(ten_minute_drive()[:2]).table(np.array([5.0]))
    row = table.iloc[0]
    lat = np.radians(row.lat)
    f = row[["fx", "fy", "fz"]].to_numpy(float)
    w = row[["wx", "wy", "wz"]].to_numpy(float)
    assert np.linalg.norm(f) == pytest.approx(earth.normal_gravity(lat, row.alt), abs=1e-9)
    c_bn = earth.euler_to_dcm(row.roll, row.pitch, row.yaw)
    np.testing.assert_allclose(w, c_bn.T @ earth.earth_rate_ned(lat)[0], atol=1e-15)
    assert row.speed == 0.0


def _drive(segments, limits=None, **start):
    """The truth of a rigid body on the segments: these tests check the road geometry itself
    (the body's motion on it is tested in tests/vehicle/)."""
    data = scenario_data(segments, limits=limits or {}, vehicle="rigid")
    data["start"].update(start)
    return build_truth(data)


def test_straight_north_matches_meridian_arc():
    # independent of the kinematics: the latitude reached by 2 km due north on the ellipsoid,
    # from the meridian arc integral of R_N (Groves eq. 2.105)
    truth = _drive([{"accelerate": {"to_speed": 10.0, "accel": 1.0}},
                    {"straight": {"length": 2000}}], heading=0.0, lat=45.0, alt=0.0)
    end = truth.table(np.array([truth.duration_s])).iloc[0]
    lat0 = np.radians(45.0)

    def arc(lat1):
        return quad(lambda x: earth.radii_of_curvature(x)[0], lat0, lat1)[0]

    from scipy.optimize import brentq
    expected = brentq(lambda x: arc(x) - end.distance, lat0, lat0 + 0.01, xtol=1e-15)
    assert np.radians(end.lat) == pytest.approx(expected, abs=1e-11)  # 0.06 mm
    assert end.lon == pytest.approx(0.0 + 127.0, abs=1e-12)


def test_turn_angle_and_lateral_acceleration():
    truth = _drive([{"accelerate": {"to_speed": 10.0, "accel": 1.0}},
                    {"turn": {"angle": 135, "radius": 50}}, {"straight": {"length": 50}}],
                   limits={"roll_gradient": 0.0}, heading=0.0)
    table = truth.table()
    assert np.degrees(table.yaw.iloc[-1]) == pytest.approx(135.0, abs=1e-9)
    # in the circular part the centripetal acceleration is v^2 / R (+ right, body y), and
    # with no body roll the accelerometer's y axis stays level; the Coriolis term adds at most
    # 2 Omega v sin(lat) = 0.9 mm/s^2
    coriolis = 2 * earth.OMEGA_E_RAD_S * 10.0 * np.sin(np.radians(37.5))
    assert abs(table.fy.max() - 10.0**2 / 50) <= coriolis * 1.01
    assert table.roll.abs().max() == 0.0
    # transitions: lateral acceleration continuous (no step between samples)
    assert np.max(np.abs(np.diff(table.fy))) < 0.05


def test_body_roll_follows_lateral_acceleration():
    truth = _drive([{"accelerate": {"to_speed": 10.0, "accel": 1.0}},
                    {"turn": {"angle": 90, "radius": 50}}], limits={"roll_gradient": "4 deg/g"})
    table = truth.table()
    # rolls outward (left side down, roll < 0) by 4 deg per g of lateral acceleration
    assert np.degrees(table.roll.min()) == pytest.approx(-4.0 * 2.0 / earth.G0_M_S2, rel=1e-6)


def test_helix_turns_rise_and_grade():
    truth = _drive([{"accelerate": {"to_speed": 4.0, "accel": 1.0}},
                    {"helix": {"turns": 3, "radius": 11, "rise": -9.0, "direction": "left"}}],
                   heading=10.0)
    table = truth.table()
    heading_change = np.degrees(np.unwrap(table.yaw.to_numpy()))
    assert heading_change[-1] - heading_change[0] == pytest.approx(-3 * 360.0, abs=1e-6)
    assert table.alt.iloc[-1] - table.alt.iloc[0] == pytest.approx(-9.0, abs=1e-6)
    grade = 9.0 / (2 * np.pi * 11 * 3)
    assert np.tan(-table.pitch.min()) == pytest.approx(grade, rel=0.05)


def test_slope_climbs_and_lane_change_shifts():
    truth = _drive([{"accelerate": {"to_speed": 10.0, "accel": 1.0}},
                    {"slope": {"grade": 0.1, "length": 300}},
                    {"lane_change": {"offset": 3.5, "length": 50}}], heading=0.0)
    table = truth.table()
    assert np.tan(table.pitch.max()) == pytest.approx(0.1, rel=1e-9)
    assert table.pitch.iloc[-1] == pytest.approx(0.0, abs=1e-12)
    ned = earth.ecef_to_ned(
        earth.geodetic_to_ecef(np.radians(table.lat), np.radians(table.lon), table.alt),
        np.radians(table.lat.iloc[0]), np.radians(table.lon.iloc[0]), table.alt.iloc[0])
    assert ned[-1, 1] == pytest.approx(3.5, abs=2e-3)  # east shift of the lane change
    assert table.yaw.iloc[-1] == pytest.approx(0.0, abs=1e-7)


def test_speed_bump_height():
    truth = _drive([{"accelerate": {"to_speed": 5.0, "accel": 1.0}},
                    {"straight": {"length": 10}},
                    {"speed_bump": {"height": 0.1, "length": 4.0}},
                    {"straight": {"length": 10}}])
    table = truth.table(np.linspace(0, truth.duration_s, 20001))
    assert table.alt.max() - table.alt.iloc[0] == pytest.approx(0.1, rel=0.01)
    assert table.alt.iloc[-1] == pytest.approx(table.alt.iloc[0], abs=1e-4)


def test_jerk_limited_acceleration():
    truth = _drive([{"accelerate": {"to_speed": 15.0, "accel": 2.0}}])
    table = truth.table()
    assert table.speed.iloc[-1] == pytest.approx(15.0)
    assert table.fx.max() == pytest.approx(2.0, abs=1e-3)
    # acceleration ramps at the configured jerk (1.5 m/s^3 by default)
    jerk = np.diff(table.fx) * 100.0
    assert np.max(np.abs(jerk)) == pytest.approx(1.5, rel=0.02)


def test_zones_cover_their_segments():
    truth = _drive([{"accelerate": {"to_speed": 5.0, "accel": 1.0}},
                    {"straight": {"length": 50, "zone": "tunnel"}},
                    {"straight": {"length": 50}}])
    (start, end, name), = truth.profile.zones
    assert name == "tunnel"
    assert end - start == pytest.approx(10.0)
    assert truth.zone_at(np.array([start + 1.0]))[0] == "tunnel"
    assert truth.zone_at(np.array([end + 1.0]))[0] == ""


@pytest.mark.parametrize("vehicle", ["rigid", None])
def test_strapdown_closure_ideal_interval_mean_rates_with_bump(vehicle):
    """Issue 19: an ideal 100 Hz IMU with ``output: rate`` (interval means, the default), turned
    into increments by the trapezoidal rule (``rates_to_increments``), closes within 2 m over the
    ten-minute drive with its speed bump, on the rigid body and on the default vehicle model.
    Point samples of the same truth alias the bump: measured 628 m on the rigid body (1.1 m with
    the default vehicle, whose suspension smooths the jolt). The interval mean lags half a
    sample (5 ms): a yaw lag of 0.48 rad/s x 5 ms = 0.14 deg in the tightest turn, measured
    0.138 deg; horizontal closure measured 0.48 m (rigid) and 0.52 m (default vehicle)."""
    extra = {"vehicle": vehicle} if vehicle else {}
    truth = build_truth(scenario_data(ten_minute_drive(), **extra))
    block = {"preset": "ideal", "rate": 100.0, "output": "rate"}
    err = _closure(truth, as_frame(Imu(resolve_block("imu", block)).generate(truth, None)["imu"]),
                   increments=False)
    assert err["horizontal"] < 2.0
    assert err["vertical"] < 0.5
    assert err["yaw_deg"] < 0.2
    if vehicle == "rigid":
        point = Imu(resolve_block("imu", {**block, "rate_sampling": "point"}))
        aliased = _closure(truth, as_frame(point.generate(truth, None)["imu"]), increments=False)
        assert aliased["horizontal"] > 10 * err["horizontal"]
