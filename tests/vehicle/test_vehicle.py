"""The vehicle model (issue 13): the body on its suspension, side slip, road roughness and
vibration, each against an analytic case, a published value, an independent integration or the
real car log of ../shared/refdata."""

from __future__ import annotations

import numpy as np
import pytest

from simulator import earth
from simulator.dataset.generate import build_truth
from simulator.errors import InputError
from simulator.vehicle.body import BodyMotion
from simulator.vehicle.params import ROUGHNESS_CLASSES, vehicle_parameters
from simulator.vehicle.road import ISO_N0, draw_roughness
from simulator.vehicle.suspension import FullCar, simulate
from tests.conftest import scenario_data, ten_minute_drive

G = earth.G0_M_S2
# a smooth road and no engine: the responses to one input alone
QUIET = {"roughness": "none", "camber": 0.0, "engine_accel": 0.0}


def _truth(segments, vehicle="automotive", **extra):
    return build_truth(scenario_data(segments, vehicle=vehicle, **extra))


def _body_velocity(table) -> np.ndarray:
    """NED velocity of the truth rotated into the body (FRD), (n, 3)."""
    trig = (np.cos(table.roll), np.sin(table.roll), np.cos(table.pitch), np.sin(table.pitch),
            np.cos(table.yaw), np.sin(table.yaw))
    return earth.ned_to_body_components(*(np.asarray(x) for x in trig),
                                        table.vn.to_numpy(), table.ve.to_numpy(),
                                        table.vd.to_numpy())


def _sine_body() -> tuple[BodyMotion, np.ndarray, float]:
    """A body whose six channels are sin(w t) on a 0.05 s grid over 2 s, with exact rates and
    accelerations at the nodes: (body, grid, w)."""
    t = np.linspace(0.0, 2.0, 41)
    w = 3.0
    rows = [np.sin(w * t), w * np.cos(w * t), -w * w * np.sin(w * t)]
    return BodyMotion(t, np.vstack([np.tile(row, (6, 1)) for row in rows]), np.zeros(3)), t, w


def test_body_channels_between_grid_times_are_c2_quintics_through_the_nodes():
    """Between grid times a channel is the quintic Hermite interpolant of the values and first
    two derivatives at the ends: a sine sampled every 0.05 s is reproduced within the
    interpolation error h^6 |f^(6)| / 46080 (below 1e-9 here), and value, rate and
    acceleration are continuous across every node."""
    body, t, w = _sine_body()
    fine = np.linspace(0.0, 2.0, 4001)
    got = body.evaluate(fine)
    np.testing.assert_allclose(got["heave"], np.sin(w * fine), atol=1e-9)
    np.testing.assert_allclose(got["slip_rate"], w * np.cos(w * fine), atol=1e-7)
    np.testing.assert_allclose(got["roll_accel"], -w * w * np.sin(w * fine), atol=1e-5)
    before, at = body.evaluate(t[1:-1] - 1e-12), body.evaluate(t[1:-1])
    for key in ("pitch", "pitch_rate", "pitch_accel"):
        np.testing.assert_allclose(before[key], at[key], atol=1e-8)
    np.testing.assert_array_equal(at["heave"], np.sin(w * t[1:-1]))  # the nodes themselves


def test_suspension_integration_matches_runge_kutta():
    """The modal exact-hold integration against a fine classical Runge-Kutta integration of
    the same state equations: a 5 cm step under the front-left wheel, a braking ramp, a road
    slope ramping up under the rear-right wheel and a vertical acceleration ramp."""
    car = FullCar.from_parameters(vehicle_parameters("automotive"))
    a, b = car.state_space()
    h, n = 0.01, 400
    u = np.zeros((n, 11))
    u[50:, 0] = 0.05
    u[100:, 4] = np.minimum(np.arange(n - 100) * h, 1.0) * -3.0
    u[150:, 9] = np.minimum(np.arange(n - 150) * h, 0.5) * 0.1
    u[200:, 10] = np.minimum(np.arange(n - 200) * h, 0.5) * 1.0
    out = simulate(car, u.T, h)
    x = np.zeros(18)
    ref = np.empty((n, 15))
    sub = 50
    for k in range(n):
        ref[k, :5], ref[k, 5:10] = x[:5], x[9:14]
        ref[k, 10:] = (a @ x + b @ u[k])[9:14]
        if k + 1 < n:
            for j in range(sub):
                def uu(frac, k=k, j=j):
                    return u[k] + (u[k + 1] - u[k]) * (j + frac) / sub
                dt = h / sub
                k1 = a @ x + b @ uu(0.0)
                k2 = a @ (x + dt / 2 * k1) + b @ uu(0.5)
                k3 = a @ (x + dt / 2 * k2) + b @ uu(0.5)
                k4 = a @ (x + dt * k3) + b @ uu(1.0)
                x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    out = out.T
    np.testing.assert_allclose(out[:, :10], ref[:, :10], atol=1e-10)
    np.testing.assert_allclose(out[:, 10:], ref[:, 10:], atol=1e-8)


def test_ride_modes_lie_at_the_preset_frequencies():
    """The body's heave and pitch modes at the axles' ride frequencies (1.2 and 1.35 Hz,
    Gillespie ch. 5), the wheel-hop modes near sqrt((k_s + k_t) / m_u) / 2 pi (about 12 Hz)."""
    p = vehicle_parameters("automotive")
    car = FullCar.from_parameters(p)
    lam = np.linalg.eigvals(car.state_space()[0])
    undamped = np.sort(np.abs(lam[lam.imag > 0])) / (2 * np.pi)
    ride = undamped[:2]
    assert ride.min() > 0.9 * p["front_frequency"] and ride.max() < 1.1 * p["rear_frequency"]
    assert np.all((undamped[-4:] > 10.0) & (undamped[-4:] < 14.0))


def test_speed_bump_at_walking_pace_is_gentle_with_two_axle_events():
    """Issue 13: a 0.08 m x 1.0 m bump at 4 m/s: pitch under 3 deg, pitch rate under 30 deg/s,
    vertical acceleration under 10 m/s^2 (the rigid body: 15.7 deg, 440 deg/s, 31 m/s^2), and
    the front and rear axles' crossings as two events, one wheelbase apart: the front pitches
    the nose up first, the rear then pitches it down."""
    segments = [{"accelerate": {"to_speed": 4.0, "accel": 1.0}}, {"straight": {"length": 20}},
                {"speed_bump": {"height": 0.08, "length": 1.0}}, {"straight": {"length": 20}}]
    for vehicle in (QUIET, "automotive"):
        truth = _truth(segments, vehicle)
        table = truth.table()
        assert np.degrees(np.abs(table.pitch)).max() < 3.0
        assert np.degrees(np.abs(table.wy)).max() < 30.0
        assert np.abs(table.fz + earth.normal_gravity(np.radians(table.lat), table.alt)).max() \
            < 10.0
    p = vehicle_parameters("automotive")
    l_f = p["wheelbase"] * (1 - p["front_weight"])
    (bump_s, _, _), = truth.profile.bumps
    t, s, q = table.t.to_numpy(), table.distance.to_numpy(), table.wy.to_numpy()
    t_front = np.interp(bump_s - l_f, s, t)
    t_rear = np.interp(bump_s + p["wheelbase"] - l_f, s, t)
    assert t_rear - t_front == pytest.approx(p["wheelbase"] / 4.0, rel=1e-6)
    front = (t > t_front) & (t < t_front + 0.25)
    rear = (t > t_rear) & (t < t_rear + 0.25)
    assert q[front].max() > np.radians(2.0) and q[rear].min() < -np.radians(2.0)
    assert np.argmax(q[front]) < np.argmin(q[front])  # nose up, then down, on the front event


def test_braking_pitches_the_nose_down():
    """Issue 13: braking at 3 m/s^2 pitches the body nose-down by 0.3-1.5 deg (real cars
    0.14-0.30 deg per m/s^2); the static value is the pitch moment m_s h a over the pitch
    stiffness of the springs in series with the tyres (Gillespie eq. 5-5 rates)."""
    segments = [{"accelerate": {"to_speed": 20.0, "accel": 2.0}}, {"straight": {"length": 200}},
                {"accelerate": {"to_speed": 0.0, "accel": 3.0}}, {"stop": {"duration": 3}}]
    table = _truth(segments, QUIET).table()
    decel = np.diff(table.speed.to_numpy(), prepend=np.nan) * 100.0
    braking = np.abs(decel + 3.0) < 1e-6  # the constant-deceleration stretch
    assert braking.sum() > 200
    pitch = np.degrees(table.pitch[braking]).to_numpy()
    assert pitch[-1] < -0.3 and pitch[-1] > -1.5
    p = vehicle_parameters("automotive")
    car = FullCar.from_parameters(p)
    static = np.linalg.solve(car.stiffness,
                             car.forcing @ [0, 0, 0, 0, -3.0, 0, 0, 0, 0, 0, 0])[1]
    assert pitch[-1] == pytest.approx(np.degrees(static), rel=0.02)


def _circle(speed: float, lateral_accel: float):
    radius = speed**2 / lateral_accel
    return [{"accelerate": {"to_speed": speed, "accel": 1.0}},
            {"turn": {"angle": 180, "radius": radius}}], radius


@pytest.mark.parametrize("speed, low, high", [(10.0, 0.3, 4.0), (25.0, 0.2, 4.0)])
def test_side_slip_in_a_03_g_turn(speed, low, high):
    """Issue 13: side slip at the centre of gravity in a 0.3 g right turn between 0.3 and 4
    deg, with the bicycle model's sign (Rajamani 2012 eq. 3.45): at 10 m/s +1.9 deg (the
    velocity points into the turn, as the kinematic l_r / R), at 25 m/s -0.26 deg (the rear
    tyres' slip angle turns the body into the turn). The model's slip passes through zero at
    sqrt(l_r L C_r / (m l_f)), 19.5 m/s for the automotive preset, so between about 16 and
    23 m/s a 0.3 g turn slips by less than the issue's 0.3 deg: measured, not tuned away.
    The slip is read from the body-frame velocity, whose lateral part the body roll in the
    turn (2 deg) and the suspension's settling mix slightly: to 0.5 % of the formula."""
    segments, radius = _circle(speed, 0.3 * G)
    vehicle = {**QUIET, "imu_position": [0.0, 0.0, 0.0]}
    table = _truth(segments, vehicle).table()
    v_body = _body_velocity(table)
    arc = np.flatnonzero(np.abs(table.wz - speed / radius) < 1e-3)  # on the arc
    arc = arc[len(arc) // 4: -len(arc) // 4]  # its middle half: the suspension has settled
    beta = np.degrees(np.arctan2(v_body[arc, 1], v_body[arc, 0]))
    p = vehicle_parameters("automotive")
    l_f = p["wheelbase"] * (1 - p["front_weight"])
    l_r = p["wheelbase"] - l_f
    expected = np.degrees(l_r / radius - p["mass"] * l_f * speed**2
                          / (p["wheelbase"] * p["rear_cornering"] * radius))
    assert low < np.abs(beta).min() and np.abs(beta).max() < high
    assert np.sign(beta).tolist() == [np.sign(expected)] * len(beta)
    np.testing.assert_allclose(beta, expected, rtol=5e-3)


def test_low_speed_slip_is_the_kinematic_geometry():
    """At walking pace the slip is the rigid-wheel geometry beta = atan(l_r / R_rear) ~ l_r / R
    (the instantaneous centre on the rear axle's line), whatever the tyres."""
    segments = [{"accelerate": {"to_speed": 1.0, "accel": 0.5}},
                {"turn": {"angle": 90, "radius": 8.0}}]
    vehicle = {**QUIET, "imu_position": [0.0, 0.0, 0.0], "rear_cornering": 5e4}
    table = _truth(segments, vehicle).table()
    arc = np.abs(table.wz - 1.0 / 8.0) < 1e-4
    beta = np.arctan2(*_body_velocity(table)[arc][:, [1, 0]].T)
    l_r = 2.7 * 0.57
    np.testing.assert_allclose(beta, l_r / 8.0, rtol=0.01)


def test_reversing_keeps_the_rear_axle_from_sliding_sideways():
    """Backing into a bay on a 5 m radius: on the arc the rear axle's lateral velocity (the
    kinematic bicycle's no-slip condition, v_lat(cg) - yaw rate x l_r = 0) is near zero, as
    when driving forward (what is left is the tyres' slip term, under 1 % of the speed), and
    the slip at the centre of gravity is -l_r / R (its sign follows the direction). With the
    forward slip kept when reversing, the rear axle slid sideways at 0.9 m/s here."""
    segments = [{"stop": {"duration": 1.0}},
                {"reverse": {"length": 12.0, "angle": 90, "radius": 5.0, "speed": 1.5}}]
    vehicle = {**QUIET, "imu_position": [0.0, 0.0, 0.0]}
    table = _truth(segments, vehicle).table()
    v_body = _body_velocity(table)
    wz = table.wz.to_numpy()
    p = vehicle_parameters("automotive")
    l_r = p["wheelbase"] * p["front_weight"]
    speed = np.hypot(v_body[:, 0], v_body[:, 1])
    on_arc = (speed > 1.0) & (np.abs(np.abs(wz) * 5.0 - speed) < 0.01)
    assert on_arc.sum() > 100 and np.all(v_body[on_arc, 0] < 0)
    rear_lateral = v_body[on_arc, 1] - wz[on_arc] * l_r  # v + w x r, r = (-l_r, 0, 0)
    assert np.abs(rear_lateral).max() < 0.01 * np.abs(v_body[on_arc, 0]).max()
    beta = np.arctan2(v_body[on_arc, 1], v_body[on_arc, 0])  # the velocity against body x
    np.testing.assert_allclose(np.abs(np.pi - np.abs(beta)), l_r / 5.0, rtol=0.05)


def test_body_velocity_at_the_imu_is_no_longer_along_x():
    """Issue 13: body-frame lateral and vertical velocity at the IMU are no longer zero (a
    rigid body: exactly zero, the non-holonomic constraint holds perfectly)."""
    segments = [{"accelerate": {"to_speed": 12.0, "accel": 1.0}}, {"straight": {"length": 200}},
                {"turn": {"angle": 90, "radius": 60}}, {"lane_change": {"offset": 3.5,
                                                                        "length": 60}}]
    rigid = _body_velocity(_truth(segments, "rigid").table())
    assert np.abs(rigid[:, 1:]).max() < 1e-12
    full = _body_velocity(_truth(segments).table())
    assert np.sqrt(np.mean(full[:, 1] ** 2)) > 0.02
    assert np.sqrt(np.mean(full[:, 2] ** 2)) > 0.005


def test_iso8608_roughness_has_the_class_spectrum():
    """The drawn profile's averaged periodogram near n0 = 0.1 cycle/m matches Gd(n0) of class B
    (ISO 8608 Table 1: 64e-6 m^3), and the spectrum falls as n^-2 (waviness 2)."""
    rng = np.random.default_rng(7)
    tracks = draw_roughness(20000.0, ROUGHNESS_CLASSES["B"], rng, tracks=4)
    seg = 4096  # Welch-style average of periodograms of 409.6 m segments
    x = tracks[:, : tracks.shape[1] // seg * seg].reshape(-1, seg)
    psd = (np.abs(np.fft.rfft(x, axis=1)) ** 2).mean(axis=0) * 2 * 0.1 / seg
    n = np.fft.rfftfreq(seg, 0.1)
    near = (n > 0.07) & (n < 0.14)
    fitted = np.mean(psd[near] * (n[near] / ISO_N0) ** 2)
    assert fitted == pytest.approx(64e-6, rel=0.15)
    high = (n > 0.8) & (n < 1.6)
    assert np.mean(psd[high] * (n[high] / ISO_N0) ** 2) == pytest.approx(64e-6, rel=0.15)


def _band_rms(x: np.ndarray, dt: float, low: float, high: float) -> np.ndarray:
    x = x - x.mean(axis=0)
    spectrum = np.fft.rfft(x, axis=0)
    f = np.fft.rfftfreq(len(x), dt)
    band = (f >= low) & (f <= high)
    return np.sqrt((np.abs(spectrum[band]) ** 2).sum(axis=0) * 2 / len(x) ** 2)


RAV4_IMU = "refdata/vehicle/comma2k19_rav4_2018-08-02_seg40/processed_log/IMU"


def _cruise_vibration(vehicle: str | dict = "automotive") -> tuple[np.ndarray, np.ndarray]:
    """Accelerometer and gyro rms in 5-50 Hz per axis (FRD) of the automotive preset cruising
    at 15 m/s on an ISO class B road (the truth's specific force and rate, 100 Hz)."""
    segments = [{"accelerate": {"to_speed": 15.0, "accel": 1.5}},
                {"straight": {"duration": 60}}]
    table = _truth(segments, vehicle).table()
    cruise = table.t.to_numpy() > table.t.iloc[-1] - 55.0
    return (_band_rms(table[["fx", "fy", "fz"]].to_numpy()[cruise], 0.01, 5.0, 50.0),
            _band_rms(table[["wx", "wy", "wz"]].to_numpy()[cruise], 0.01, 5.0, 50.0))


def _rav4_band_rms(shared_dir, stream: str) -> np.ndarray:
    log = shared_dir / RAV4_IMU / stream
    t = np.load(log / "t")
    return _band_rms(np.load(log / "value"), float(np.median(np.diff(t))), 5.0, 50.0)


def test_vibration_at_15_m_s_on_a_class_b_road(shared_dir):
    """Issue 13: accelerometer rms in 5-50 Hz at 15 m/s on an ISO class B road between 0.1 and
    1 m/s^2 (vertical axis) with the automotive preset (measured 0.24); the real RAV4 log of
    comma2k19 at 8-20 m/s on a Californian highway (refdata 3a) reads 0.49 m/s^2 vertically,
    within a factor of three. Fore-aft and sideways the body now moves on its tyres, pushed by
    the road's slopes (``suspension``): 0.052 and 0.059 m/s^2, against 0.017 and 0.050 from
    pitch and roll alone (the same car held rigidly on its tyres, horizontal stiffness 1e12 N/m):
    the slope forces more than double the fore-aft vibration and add to the sideways one."""
    accel, _ = _cruise_vibration()
    assert 0.1 < accel[2] < 1.0
    real = _rav4_band_rms(shared_dir, "accelerometer")
    assert real[2] / 3 < accel[2] < 3 * real[2]
    held, _ = _cruise_vibration({"tyre_longitudinal_stiffness": 1e12,
                                 "tyre_lateral_stiffness": 1e12})
    assert accel[0] > 2 * held[0] and accel[1] > held[1]


@pytest.mark.xfail(strict=True, reason="not shown: fore-aft 0.052 and sideways 0.059 m/s^2 "
                                       "against the log's 0.54 and 0.36 (vertical 0.24 "
                                       "against 0.49): see the docstring")
def test_vibration_per_axis_within_a_factor_two_of_the_rav4_log(shared_dir):
    """Issue 13's check: per-axis accelerometer rms in 5-50 Hz of the automotive preset at 15
    m/s on class B within a factor of two of the real RAV4 log's (comma2k19, refdata 3a: x
    0.54, y 0.36, z 0.49 m/s^2, device axes forward, right, down). Measured: 0.052, 0.059,
    0.24. Not shown, and not tuned: the log's fore-aft and sideways vibration is mostly the
    device rocking on its windshield mount, not the car body translating. Its x
    accelerometer is coherent with its pitch rate (0.90 in 40-52 Hz, 0.77 in 10-20 Hz) and its
    y accelerometer with its roll rate (0.75, 0.51); the three gyro axes explain (multiple
    coherence, 256-sample Welch segments) 0.52 of the 0.54 m/s^2 fore-aft and 0.32 of the
    0.36 sideways, leaving 0.15 and 0.16 m/s^2 (0.31 of 0.49 vertically): a pitch rate of
    0.014 rad/s at 45 Hz times a 9 cm lever gives the 0.38 m/s^2 of x there, while a car body's
    pitch modes lie near 1.5 Hz. The model's body is within a factor of three of that
    remainder fore-aft and sideways; a mount model (a sensor's, not the car's) is not built."""
    accel, _ = _cruise_vibration()
    real = _rav4_band_rms(shared_dir, "accelerometer")
    assert np.all((accel > real / 2) & (accel < 2 * real))


def test_the_road_pushes_the_body_along_its_normal_and_the_tyres_deflect():
    """Fore-aft and sideways on the tyres (``suspension``), static cases: on a camber c the
    contact forces along the road's normal push the body downhill (right) by m g c / (4 k_y)
    (the tyres' lateral deflection, 0.61 mm for the automotive preset at 2.5 %); braking at
    3 m/s^2 carries it forward by m_s a / (4 k_x) on the tyres' fore-aft stiffness."""
    from simulator.vehicle import vehicle_body

    p = vehicle_parameters("automotive")
    segments = [{"accelerate": {"to_speed": 20.0, "accel": 2.0}}, {"straight": {"length": 200}},
                {"accelerate": {"to_speed": 0.0, "accel": 3.0}}, {"stop": {"duration": 3}}]
    truth = _truth(segments, {**QUIET, "camber": 0.025})
    t = truth.t_grid
    _, body = vehicle_body(truth.profile, {**p, **QUIET, "camber": 0.025}, t)
    motion = body.evaluate(t)
    cruising = (t > 12.0) & (t < 15.0)  # at 20 m/s, settled
    np.testing.assert_allclose(motion["sway"][cruising],
                               p["mass"] * G * 0.025 / (4 * p["tyre_lateral_stiffness"]),
                               rtol=1e-3)
    speed = truth.table().speed.to_numpy()
    braking = np.flatnonzero(np.abs(np.diff(speed, prepend=np.nan) * 100.0 + 3.0) < 1e-6)
    sprung = p["mass"] - 4 * p["unsprung_mass"]
    assert motion["surge"][braking[-1]] == pytest.approx(
        sprung * 3.0 / (4 * p["tyre_longitudinal_stiffness"]), rel=0.02)


def test_strapdown_closes_on_a_rough_road_with_an_suv():
    """Issue 13: an ideal 100 Hz IMU (increments) integrated by the independent strapdown of
    estimators/toolbox closes on the truth within 2 m and 0.2 deg of yaw after the ten-minute
    drive with bumps, helices and turns, here with the SUV on a class C road."""
    from simulator.sensors import resolve_block
    from simulator.sensors.imu import Imu
    from simulator.tables import as_frame
    from tests.trajectory.test_kinematics import _closure

    truth = _truth(ten_minute_drive(), {"preset": "suv", "roughness": "C"})
    imu = Imu(resolve_block("imu", {"preset": "ideal", "rate": 100.0, "output": "increment",
                                    "axes": ["gyro_x", "gyro_y", "gyro_z", "accel_x",
                                             "accel_y", "accel_z"]}))
    err = _closure(truth, as_frame(imu.generate(truth, None)["imu"]), increments=True)
    assert err["horizontal"] < 2.0
    assert err["yaw_deg"] < 0.2


def test_the_road_is_reproducible_and_set_by_its_own_seed():
    """The same road seed gives the same truth; another road seed another road; the scenario's
    seed (the sensors' errors) does not change the road, so a campaign's runs share it."""
    segments = [{"accelerate": {"to_speed": 10.0, "accel": 1.0}}, {"straight": {"length": 100}}]
    a = _truth(segments, seed=5).columns()
    b = _truth(segments, seed=6).columns()
    c = _truth(segments, {"road_seed": 1}, seed=5).columns()
    for key in ("alt", "fz", "wy", "roll"):
        np.testing.assert_array_equal(a[key], b[key])
    assert not np.array_equal(a["fz"], c["fz"])


def test_camber_rolls_the_body_by_the_cross_slope():
    segments = [{"accelerate": {"to_speed": 10.0, "accel": 1.0}}, {"straight": {"length": 100}}]
    table = _truth(segments, {**QUIET, "camber": 0.025}).table()
    np.testing.assert_allclose(table.roll, np.arctan(0.025), rtol=2e-3)


def test_vertical_curves_load_the_suspension():
    """Issue 13: a grade change loads the suspension. On a vertical curve of curvature
    dgamma/ds the path accelerates by a_v = v^2 dgamma/ds normal to the road and the road under
    axle i lies dgamma/ds x_i^2 / 2 above the tangent plane at the centre of gravity; with equal
    front and rear ride frequencies f the quasi-static body heave is
    -a_v / (2 pi f)^2 - a_v m_u / k_t (sprung mass on the ride rate, wheels on their tyres)
    plus the axle heights interpolated at the centre of gravity, (l_r h_f + l_f h_r) / L, and
    the pitch (h_f - h_r) / L. At 15 m/s over a 0.08 slope's crest and sag (a_v up to -+0.75
    m/s^2): +8.5 / -8.5 mm of heave, the dynamics within 2 % of the quasi-static value."""
    from simulator.vehicle import vehicle_body

    equal = {**QUIET, "front_frequency": 1.3, "rear_frequency": 1.3}
    segments = [{"accelerate": {"to_speed": 15.0, "accel": 1.5}}, {"straight": {"length": 100}},
                {"slope": {"grade": 0.08, "length": 300}}, {"straight": {"length": 100}}]
    truth = _truth(segments, equal)
    p = {**vehicle_parameters("automotive"), **equal}
    t = truth.t_grid
    profile, body = vehicle_body(truth.profile, p, t)
    motion = body.evaluate(t)
    s, v = profile.distance_of_time.evaluate(t, (0, 1))
    curvature = profile.grade.evaluate(s, (1,))[0]
    a_v = v * v * curvature
    length = p["wheelbase"]
    l_r = length * p["front_weight"]
    l_f = length - l_r
    h_f, h_r = curvature * l_f**2 / 2, curvature * l_r**2 / 2
    heave = (-a_v / (2 * np.pi * 1.3) ** 2 - a_v * p["unsprung_mass"] / p["tyre_stiffness"]
             + (l_r * h_f + l_f * h_r) / length)
    pitch = (h_f - h_r) / length
    for k in (np.argmax(a_v), np.argmin(a_v)):  # the sag and the crest
        assert abs(a_v[k]) > 0.7
        assert motion["heave"][k] == pytest.approx(heave[k], rel=0.02)
        assert motion["pitch"][k] == pytest.approx(pitch[k], rel=0.1)
    level = np.abs(curvature) == 0.0
    assert np.abs(motion["heave"][level & (t > 20.0)]).max() < 2e-3  # settled off the curves


@pytest.mark.parametrize("block, where", [
    ({"damping": -0.2}, "vehicle.damping"),
    ({"preset": "truck"}, "vehicle.preset"),
    ({"roughness": "Z"}, "vehicle.roughness"),
    ({"wheelbase": "2.7 s"}, "vehicle.wheelbase"),
    ("tank", "vehicle"),
    ({"mass": 150.0, "unsprung_mass": 40.0}, "vehicle.unsprung_mass"),
    ({"tyre_stiffness": 2e4}, "vehicle.tyre_stiffness"),
])
def test_bad_vehicle_values_name_the_key(block, where):
    with pytest.raises(InputError) as info:
        scenario_data([{"stop": {"duration": 1}}], vehicle=block)
    assert where in str(info.value)


def test_wheels_meet_the_bump_one_wheelbase_apart_and_the_grade_loses_it():
    """The road under each corner: the segment's bump shape H 64 u^3 (1 - u)^3 at s + x_i, the
    camber's -c y_i, the forward slope its derivative, and the level road keeps no bump in its
    grade (the rigid body's 8 cm climb is gone from the altitude; the body heaves by about the
    bump instead)."""
    from simulator.vehicle.body import level_road
    from simulator.vehicle.road import RoadSurface

    surface = RoadSurface([(10.0, 1.0, 0.08)], None, 0.0, 0.02)
    x, y = np.array([1.2, 1.2, -1.5, -1.5]), np.array([-0.8, 0.8, -0.8, 0.8])
    s = np.linspace(0.0, 20.0, 2001)
    z, slope = surface.heights(s, x, y)
    ahead, behind = surface.heights(s + 1e-6, x, y)[0], surface.heights(s - 1e-6, x, y)[0]
    for i in range(4):
        u = np.clip((s + x[i] - 10.0), 0.0, 1.0)
        np.testing.assert_allclose(z[i], 0.08 * 64 * (u * (1 - u)) ** 3 - 0.02 * y[i],
                                   atol=1e-15)
        # the slope against the central difference of the heights (step 1 um)
        np.testing.assert_allclose(slope[i], (ahead[i] - behind[i]) / 2e-6, atol=1e-8)
    segments = [{"accelerate": {"to_speed": 4.0, "accel": 1.0}}, {"straight": {"length": 20}},
                {"speed_bump": {"height": 0.08, "length": 1.0}}, {"straight": {"length": 20}}]
    rigid = _truth(segments, "rigid")
    assert np.ptp(level_road(rigid.profile).grade.c) == 0.0
    body = _truth(segments, {**QUIET, "imu_position": [0.0, 0.0, 0.0]}).table()
    assert 0.02 < np.ptp(body.alt) < 0.08


def test_body_at_a_fixed_fraction_of_every_interval_is_the_same_quintic():
    """``BodyMotion.inside`` (one linear map of the end nodes, what the IMU's quadrature asks
    for) gives ``evaluate``'s quintics at t_j + u h, for index arrays and slices alike, and the
    sine they interpolate within the interpolation error."""
    body, t, w = _sine_body()
    h = t[1] - t[0]
    for u in (0.2763932, 0.5, 0.7236068):
        j = np.array([0, 5, 6, 17, 39])
        got, ref = body.inside(j, u), body.evaluate(t[j] + u * h)
        span, ref_span = body.inside(slice(3, 12), u), body.evaluate(t[3:12] + u * h)
        for key in ref:
            np.testing.assert_allclose(got[key], ref[key], rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(span[key], ref_span[key], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(got["surge"], np.sin(w * (t[j] + u * h)), atol=1e-9)


def test_rates_inside_grid_intervals_are_the_truth_there():
    """``Kinematics.rates_inside`` (the IMU quadrature's inner nodes, evaluated piece by piece
    straight to the two vectors) is ``inertial`` at t_j + u h on a rough road with the body,
    over a drive long enough to be evaluated in several pieces."""
    truth = _truth(ten_minute_drive())
    h = 1.0 / truth.rate_hz
    j = np.flatnonzero(np.arange(len(truth.t_grid) - 1) % 7 != 3)  # not one run of intervals
    assert len(j) > 40000
    u = 0.2763932
    got = truth.rates_inside(j, u)
    ref = truth.inertial(truth.t_grid[j] + u * h)
    # the same polynomials summed in another order: rounding (measured 3e-14 rad/s, 1.3e-12
    # m/s^2, on accelerations of several m/s^2)
    np.testing.assert_allclose(got["w_body"], ref["w_body"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(got["f_body"], ref["f_body"], rtol=0, atol=1e-11)
    assert np.ptp(ref["f_body"][:, 2]) > 1.0  # the body vibrates
    rigid = _truth(ten_minute_drive(), "rigid")
    got, ref = rigid.rates_inside(j[::5], u), rigid.inertial(rigid.t_grid[j[::5]] + u * h)
    for key in ("w_body", "f_body"):  # without a body, the very same operations
        np.testing.assert_array_equal(got[key], ref[key])


def test_ideal_increments_on_the_vibrating_body_are_the_exact_integrals():
    """Where the body vibrates (roughness, engine), every IMU increment comes from the Lobatto
    rule on ``rates_inside`` and the grid samples: each checked against adaptive quadrature
    (scipy.integrate.quad) of the analytic truth over its interval, on rows spread over a
    drive with a turn and braking. The bound is four times the largest difference measured
    between two degree-5 rules (Lobatto and Gauss-Legendre, 5e-11 m/s and 2e-13 rad per
    sample, BENCHMARKS.md)."""
    from scipy.integrate import quad

    from simulator import columns as col
    from simulator.sensors import resolve_block
    from simulator.sensors.imu import Imu

    truth = _truth([{"stop": {"duration": 2}}, {"accelerate": {"to_speed": 12.0, "accel": 2.0}},
                    {"turn": {"angle": 90, "radius": 40}},
                    {"accelerate": {"to_speed": 0.0, "accel": 3.0}}])
    imu = Imu(resolve_block("imu", {"preset": "ideal", "rate": 100.0, "output": "increment",
                                    "axes": ["gyro_x", "gyro_y", "gyro_z", "accel_x",
                                             "accel_y", "accel_z"]}))
    out = imu.generate(truth, None)["imu"]
    breaks = truth.breakpoints()
    dt = 0.01
    grid = truth.grid_inertial()
    bounds = {"w_body": 1e-12, "f_body": 2e-10}
    checked = 0
    for i in np.linspace(300, len(out["t"]) - 2, 7).astype(int):
        t1 = out["t"][i]
        if ((breaks > t1 - dt) & (breaks < t1)).any():
            continue  # such an interval is split at its breakpoint: checked for the rigid body
        k = int(round(t1 / dt))
        for j, axis in enumerate(col.IMU_AXES):
            key, comp = ("w_body", j) if j < 3 else ("f_body", j - 3)
            exact, _ = quad(lambda s, key=key, comp=comp: truth.inertial(s)[key][0, comp],
                            t1 - dt, t1, epsabs=1e-15, epsrel=1e-13, limit=200)
            assert abs(out[axis][i] - exact) < bounds[key], (i, axis, out[axis][i] - exact)
            if axis == "accel_z":  # the grid samples alone (trapezoid) would miss it by far more
                trapezoid = 0.5 * dt * (grid[key][k - 1, comp] + grid[key][k, comp])
                assert abs(trapezoid - exact) > 100 * bounds[key]
        checked += 1
    assert checked >= 5
