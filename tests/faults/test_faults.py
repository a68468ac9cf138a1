"""Faults: triggers, validation, and each kind's effect present inside its interval and absent
outside (faulted against clean streams of the same seed)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from conftest import scenario_data

from simulator.dataset.generate import build_truth, generate_streams
from simulator.errors import InputError
from simulator.faults import FAULT_REGISTRY
from simulator.faults.base import FaultContext
from simulator.faults.triggers import fault_intervals

DRIVE = [
    {"stop": {"duration": 10}},
    {"accelerate": {"to_speed": 10.0, "accel": 1.0}},
    {"straight": {"length": 300}},
    {"straight": {"length": 200, "zone": "tunnel"}},
    {"straight": {"length": 1500}},
]


@pytest.fixture(scope="module")
def truth():
    return build_truth(scenario_data(DRIVE))


def _fault(kind: str, **fields) -> dict:
    """A resolved fault entry (validated through the scenario schema)."""
    data = scenario_data(DRIVE, faults=[{"kind": kind, **fields}])
    return data["faults"][0]


def test_start_zone_and_distance_triggers(truth):
    rng = np.random.default_rng(0)
    assert fault_intervals(_fault("imu_bias_step", start=20, duration=5), truth, rng) == [
        (20.0, 25.0)]
    (zone,) = fault_intervals(_fault("imu_bias_step", zone="tunnel"), truth, rng)
    # stop 10 s; 0 -> 10 m/s at 1 m/s^2 with jerk 1.5 m/s^3 takes 10 + 1/1.5 s; 300 m at 10 m/s
    accelerate = 10.0 + 1.0 / 1.5
    assert zone == pytest.approx((10 + accelerate + 30, 10 + accelerate + 50))
    (a, b), = fault_intervals(_fault("imu_bias_step", distance=[100, 200]), truth, rng)
    s = truth.profile.distance_of_time(np.array([a, b]))
    assert s == pytest.approx([100, 200], abs=0.11)


def test_random_trigger_matches_rate_and_distribution():
    long_drive = [{"accelerate": {"to_speed": 10.0, "accel": 1.0}},
                  {"straight": {"length": 10.0 * 40 * 3600}}]  # 40 hours
    data = scenario_data(long_drive, faults=[{
        "kind": "imu_bias_step", "random": {"rate": "6 /h", "duration": {
            "distribution": "exponential", "mean": 20.0}}}],
        sensors={"imu": {"preset": "ideal", "rate": 1}},
        vehicle="rigid")  # a random trigger reads the drive's duration only, not the body
    truth = build_truth(data)
    intervals = fault_intervals(data["faults"][0], truth, np.random.default_rng(7))
    hours = truth.duration_s / 3600
    count = len(intervals)
    # Poisson count: 240 expected, standard deviation sqrt(240) = 15.5
    assert abs(count - 6 * hours) < 4 * np.sqrt(6 * hours)
    lengths = np.array([b - a for a, b in intervals])
    assert lengths.mean() == pytest.approx(20.0, rel=4 / np.sqrt(count))
    # exponential: the standard deviation equals the mean
    assert lengths.std() == pytest.approx(20.0, rel=0.2)
    starts = np.array([a for a, _ in intervals])
    assert np.all(np.diff(starts) > 0)


@pytest.mark.parametrize("fault, key, words", [
    ({"kind": "volcano", "start": 1, "duration": 1}, "faults.0.kind", "unknown fault kind"),
    ({"kind": "baro_jump", "start": 1, "duration": 1, "delta_pa": 30}, "faults.0.kind",
     "no configured"),
    ({"kind": "imu_bias_step", "start": 1, "duration": "3 m"}, "faults.0.duration",
     "dimension"),
    ({"kind": "imu_bias_step", "start": 200, "duration": 100}, "faults.0.duration",
     "ends after the drive"),
    ({"kind": "imu_bias_step", "zone": "garage"}, "faults.0.zone", "no stretch"),
    ({"kind": "imu_bias_step", "start": 1}, "faults.0.duration", "needs a duration"),
    ({"kind": "imu_bias_step", "start": 1, "duration": 1, "zone": "tunnel"}, "faults.0",
     "exactly one trigger"),
    ({"kind": "gnss_latency", "start": 1, "duration": 1}, "faults.0.latency",
     "missing required key"),
])
def test_fault_validation(fault, key, words):
    with pytest.raises(InputError) as exc:
        scenario_data(DRIVE, faults=[fault])
    text = str(exc.value)
    assert f"{key}:" in text and words in text


def _apply(kind: str, streams: dict, intervals, truth, sensors=None, **params):
    fault = FAULT_REGISTRY[kind]
    context = FaultContext(truth, sensors or {}, np.random.default_rng(1))
    fault.apply(streams, intervals, params, context)
    return streams


def _stream(rate: float, duration: float, **columns) -> pd.DataFrame:
    t = np.arange(0, duration, 1 / rate)
    return pd.DataFrame({"t": t, **{k: f(t) for k, f in columns.items()}})


def _inside(t, a, b):
    return (t >= a) & (t < b)


def test_baro_jump_steps_and_recovers(truth):
    clean = _stream(20, 100, pressure=lambda t: 101325.0 - 0.1 * t)
    faulted = _apply("baro_jump", {"baro": clean.copy()}, [(30.0, 50.0)], truth,
                     delta_pa=30.0, recovery=5.0)["baro"]
    diff = faulted.pressure - clean.pressure
    t = clean.t
    assert np.all(diff[~_inside(t, 30, 50)] == 0.0)
    assert np.allclose(diff[_inside(t, 30, 45)], 30.0)
    assert 0 < diff[_inside(t, 47.5, 47.6)].iloc[0] < 30.0


def test_odometer_slip_and_scale_change(truth):
    clean = _stream(10, 100, speed=lambda t: np.full_like(t, 10.0))
    slip = _apply("odometer_slip", {"odometer": clean.copy()}, [(20.0, 30.0)], truth,
                  slip=-1.0)["odometer"]
    assert np.all(slip.speed[_inside(clean.t, 20, 30)] == 0.0)
    assert np.all(slip.speed[~_inside(clean.t, 20, 30)] == 10.0)
    tyre = _apply("odometer_scale_change", {"odometer": clean.copy()}, [(50.0, 100.0)], truth,
                  scale_change=0.03)["odometer"]
    assert np.allclose(tyre.speed[_inside(clean.t, 50, 100)], 10.3)
    assert np.all(tyre.speed[~_inside(clean.t, 50, 100)] == 10.0)


def test_imu_bias_step_on_rates_and_increments(truth):
    zeros = {a: np.zeros_like for a in ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y",
                                         "accel_z")}
    clean = _stream(100, 10, **zeros)
    sensors = {"imu": {"rate": 100.0, "output": "increment"}}
    out = _apply("imu_bias_step", {"imu": clean.copy()}, [(2.0, 4.0)], truth, sensors,
                 axes=["gyro_z", "accel_x"], gyro=1e-3, accel=0.05)["imu"]
    inside = _inside(clean.t, 2, 4)
    assert np.allclose(out.gyro_z[inside], 1e-5) and np.allclose(out.accel_x[inside], 5e-4)
    assert np.all(out.gyro_z[~inside] == 0) and np.all(out.gyro_x == 0)


def test_saturation_burst_clips(truth):
    clean = _stream(200, 10, accel_z=lambda t: np.full_like(t, -9.8))
    out = _apply("imu_saturation_burst", {"imu": clean.copy()}, [(5.0, 5.5)], truth,
                 {"imu": {"rate": 200.0, "output": "rate"}}, axes=["accel_z"],
                 gyro_amplitude=0.0, accel_amplitude=40.0, frequency=30.0, gyro_range=None,
                 accel_range=16.0)["imu"]
    inside = _inside(clean.t, 5, 5.5)
    assert out.accel_z[inside].min() == pytest.approx(-16.0)
    assert out.accel_z[inside].max() == pytest.approx(16.0)
    assert np.all(out.accel_z[~inside] == -9.8)


def test_dropout_and_jitter(truth):
    clean = _stream(10, 30, speed=np.ones_like)
    out = _apply("sensor_dropout", {"odometer": clean.copy()}, [(10.0, 12.0)], truth,
                 stream="odometer")["odometer"]
    assert len(out) == len(clean) - 20
    assert not np.any(_inside(out.t, 10, 12))
    jittered = _apply("timestamp_jitter", {"odometer": clean.copy()}, [(10.0, 20.0)], truth,
                      stream="odometer", sigma=0.01)["odometer"]
    moved = jittered.t - clean.t
    assert np.all(moved[~_inside(clean.t, 10, 20)] == 0.0)
    assert 0.005 < moved[_inside(clean.t, 10, 20)].std() < 0.02
    assert np.all(np.diff(jittered.t) > 0)


def _fixes(truth):
    t = np.arange(0.0, 60.0, 1.0)
    table = truth.table(t)
    return pd.DataFrame({"t": t, "lat": table.lat, "lon": table.lon, "alt": table.alt,
                         "vn": table.vn, "ve": table.ve, "vd": table.vd, "speed": table.speed,
                         "course": table.yaw, "num_sats": 8, "hdop": 1.0, "vdop": 1.5,
                         "fix": 2})


def test_gnss_outage_latency_jump_and_rate_drop(truth):
    clean = _fixes(truth)
    raw = pd.DataFrame({"t": np.repeat(clean.t, 5), "sv": np.tile(np.arange(1, 6), 60)})
    out = _apply("gnss_outage", {"gnss_fix": clean.copy(), "gnss_raw": raw.copy()},
                 [(10.0, 20.0)], truth)
    inside = _inside(clean.t, 10, 20)
    assert np.all(out["gnss_fix"].fix[inside] == 0) and out["gnss_fix"].lat[inside].isna().all()
    pd.testing.assert_frame_equal(out["gnss_fix"][~inside], clean[~inside], check_dtype=False)
    assert not np.any(_inside(out["gnss_raw"].t, 10, 20)) and len(out["gnss_raw"]) == 250

    late = _apply("gnss_latency", {"gnss_fix": clean.copy()}, [(30.0, 40.0)], truth,
                  latency=2.0)["gnss_fix"]
    inside = _inside(clean.t, 30, 40)
    assert np.allclose(late.lat[inside], clean.lat.shift(2)[inside])
    pd.testing.assert_frame_equal(late[~inside], clean[~inside])

    jump = _apply("gnss_fix_jump", {"gnss_fix": clean.copy()}, [(40.0, 50.0)], truth,
                  offset=[30.0, -20.0, 5.0])["gnss_fix"]
    inside = _inside(clean.t, 40, 50)
    from simulator import earth
    ned = earth.ecef_to_ned(
        earth.geodetic_to_ecef(np.radians(jump.lat[inside]), np.radians(jump.lon[inside]),
                               jump.alt[inside].to_numpy()),
        np.radians(clean.lat[inside].iloc[0]), np.radians(clean.lon[inside].iloc[0]),
        clean.alt[inside].iloc[0])
    assert ned[0] == pytest.approx([30.0, -20.0, 5.0], abs=1e-3)
    pd.testing.assert_frame_equal(jump[~inside], clean[~inside])

    slow = _apply("gnss_rate_drop", {"gnss_fix": clean.copy()}, [(10.0, 30.0)], truth,
                  rate=0.2)["gnss_fix"]
    assert list(slow.t[_inside(slow.t, 10, 30)]) == [10.0, 15.0, 20.0, 25.0]
    assert len(slow) == 60 - 16


def test_faulted_dataset_identical_outside_the_interval():
    clean = generate_streams(scenario_data(DRIVE), show_progress=False).streams
    faulted = generate_streams(scenario_data(DRIVE, faults=[
        {"kind": "imu_bias_step", "start": 40, "duration": 10, "gyro": "100 deg/h"},
        {"kind": "timestamp_jitter", "stream": "imu", "start": 60, "duration": 5,
         "sigma": 0.001}]), show_progress=False).streams
    t = clean["imu"].t.to_numpy()
    outside = ~(_inside(t, 40, 50) | _inside(t, 60, 65))
    pd.testing.assert_frame_equal(faulted["imu"][outside], clean["imu"][outside])
    assert not faulted["imu"].equals(clean["imu"])
    events = faulted["events"]
    assert list(events.kind) == ["imu_bias_step", "zone", "timestamp_jitter"]
    assert events.t_start.iloc[0] == 40.0 and events.t_end.iloc[0] == 50.0


GNSS = {"imu": {"preset": "ideal", "rate": 100},
        "gnss": {"preset": "automotive", "rate": 1, "outputs": ["fix", "raw"]}}


def _gnss_streams(faults, **gnss):
    sensors = {**GNSS, "gnss": {**GNSS["gnss"], **gnss}}
    data = scenario_data(DRIVE, sensors=sensors, faults=faults)
    return generate_streams(data, show_progress=False).streams


@pytest.fixture(scope="module")
def clean_gnss():
    return _gnss_streams([])


def _same_outside(faulted, clean, name, a, b):
    f, c = faulted[name], clean[name]
    pd.testing.assert_frame_equal(f[~_inside(f.t, a, b)].reset_index(drop=True),
                                  c[~_inside(c.t, a, b)].reset_index(drop=True))


def test_satellite_limit_keeps_the_highest(clean_gnss):
    faulted = _gnss_streams([{"kind": "gnss_satellite_limit", "start": 100, "duration": 30,
                              "count": 3}])
    for name in ("gnss_raw", "gnss_fix", "truth_gnss", "imu"):
        _same_outside(faulted, clean_gnss, name, 100, 130)
    raw, clean_raw = faulted["gnss_raw"], clean_gnss["gnss_raw"]
    inside = _inside(raw.t, 100, 130)
    assert raw[inside].groupby("t").size().max() == 3
    # the three kept are the three highest of the clean epoch
    epoch = clean_raw[clean_raw.t == 110.0].nlargest(3, "elevation")
    assert set(raw[raw.t == 110.0].sv) == set(epoch.sv)
    fix = faulted["gnss_fix"]
    assert set(fix.fix[_inside(fix.t, 100, 130)]) == {1}  # 2-D fixes with held height
    # the receiver's DOP mask (20): three high satellites with a poor geometry give no fix
    masked = _gnss_streams([{"kind": "gnss_satellite_limit", "start": 100, "duration": 30,
                             "count": 3}], dop_mask=1.0)["gnss_fix"]
    inside = _inside(masked.t, 100, 130)
    assert (masked.fix[inside] == 0).all() and masked.lat[inside].isna().all()
    assert (fix.hdop[fix.fix > 0] <= 20.0).all()
    assert (faulted["truth_gnss"].tracked[_inside(faulted["truth_gnss"].t, 100, 130)] == 0).any()
    outages = faulted["events"][faulted["events"].kind == "gnss_outage"]
    assert not _inside(outages.t_start, 100, 130).any()  # measurements remain: no outage


def test_satellite_limit_zero_is_an_outage(clean_gnss):
    faulted = _gnss_streams([{"kind": "gnss_satellite_limit", "start": 100, "duration": 30,
                              "count": 0}])
    fix = faulted["gnss_fix"]
    assert (fix.fix[_inside(fix.t, 100, 130)] == 0).all()
    outages = faulted["events"][faulted["events"].kind == "gnss_outage"]
    spans = list(zip(outages.t_start, outages.t_end, strict=True))
    assert (100.0, 130.0) in spans and len(spans) == 2  # and the tunnel's


def test_outage_fault_and_tunnel_each_appear_once(clean_gnss):
    tunnel = [(a, b) for a, b, name in build_truth(scenario_data(DRIVE)).profile.zones]
    assert len(tunnel) == 1
    faulted = _gnss_streams([{"kind": "gnss_outage", "start": 120, "duration": 60}])
    outages = faulted["events"][faulted["events"].kind == "gnss_outage"]
    assert len(outages) == 2
    assert outages.t_start.iloc[1] == 120.0 and outages.t_end.iloc[1] == 180.0
    # the tunnel has no sky: its outage comes from the measurements themselves
    assert outages.t_start.iloc[0] == pytest.approx(np.ceil(tunnel[0][0]))
    _same_outside(faulted, clean_gnss, "gnss_fix", 120, 180)


def test_multipath_moves_the_fix(clean_gnss):
    faulted = _gnss_streams([{"kind": "gnss_multipath", "start": 100, "duration": 40,
                              "satellites": 2, "sigma": 40.0}])
    for name in ("gnss_raw", "gnss_fix", "truth_gnss"):
        _same_outside(faulted, clean_gnss, name, 100, 140)
    raw, clean_raw = faulted["gnss_raw"], clean_gnss["gnss_raw"]
    changed = raw.pseudorange.to_numpy() != clean_raw.pseudorange.to_numpy()
    assert raw.sv[changed].nunique() == 2 and _inside(raw.t[changed], 100, 140).all()
    assert np.abs(raw.pseudorange - clean_raw.pseudorange)[changed].std() > 10.0
    moved = np.hypot(faulted["gnss_fix"].lat - clean_gnss["gnss_fix"].lat,
                     faulted["gnss_fix"].lon - clean_gnss["gnss_fix"].lon) * 111e3
    assert moved[_inside(faulted["gnss_fix"].t, 100, 140)].max() > 5.0


ALL_SENSORS = {"imu": {"preset": "automotive", "rate": 100},
               "odometer": {"preset": "abs-wheel-speed"}, "baro": {"preset": "bosch-bmp280"},
               "mag": {"preset": "automotive"},
               "gnss": {"preset": "automotive", "rate": 1, "outputs": ["fix", "raw"]}}
EVERY_KIND = [
    ("gnss_outage", {}, ["gnss_fix", "gnss_raw", "truth_gnss"]),
    ("gnss_satellite_limit", {"count": 2}, ["gnss_fix", "gnss_raw", "truth_gnss"]),
    ("gnss_multipath", {"sigma": 30.0}, ["gnss_fix", "gnss_raw", "truth_gnss"]),
    ("gnss_fix_jump", {"offset": [20.0, 0.0, 0.0]}, ["gnss_fix"]),
    ("gnss_latency", {"latency": 2.0}, ["gnss_fix"]),
    ("gnss_rate_drop", {"rate": 0.2}, ["gnss_fix", "gnss_raw", "truth_gnss"]),
    ("baro_jump", {"delta_pa": 30.0}, ["baro"]),
    ("odometer_slip", {"slip": 0.3}, ["odometer", "truth_sensors"]),
    ("odometer_scale_change", {"scale_change": "2 %"}, ["odometer", "truth_sensors"]),
    ("imu_bias_step", {"gyro": "0.5 deg/s"}, ["imu", "truth_sensors"]),
    ("imu_saturation_burst", {"accel_amplitude": 60.0}, ["imu"]),
    ("sensor_dropout", {"stream": "mag"}, ["mag"]),
    ("timestamp_jitter", {"stream": "odometer", "sigma": 0.01}, ["odometer"]),
]


@pytest.fixture(scope="module")
def clean_all():
    return generate_streams(scenario_data(DRIVE, sensors=ALL_SENSORS),
                            show_progress=False).streams


def test_every_kind_is_covered():
    assert {kind for kind, _, _ in EVERY_KIND} == set(FAULT_REGISTRY)


@pytest.mark.parametrize("kind, params, touched", EVERY_KIND, ids=[k[0] for k in EVERY_KIND])
def test_kind_declares_every_stream_it_changes(kind, params, touched):
    """The dataset writer writes a stream early unless a fault may change it: a fault changing
    a stream it does not declare would race with that write (the GNSS truth table of
    ``gnss_satellite_limit`` was written either before or after its ``tracked`` flags)."""
    # truth_sensors is made from the applied faults' events after every fault ran, and written
    # with the last streams
    assert set(touched) - {"truth_sensors"} <= set(FAULT_REGISTRY[kind].changed_streams)


@pytest.mark.parametrize("kind, params, touched", EVERY_KIND, ids=[k[0] for k in EVERY_KIND])
def test_fault_acts_only_inside_its_interval(clean_all, kind, params, touched):
    """Faulted against clean dataset of the same seed: the touched streams differ inside the
    interval and are identical outside it; every other stream is identical."""
    a, b = 95.0, 125.0
    faulted = generate_streams(scenario_data(DRIVE, sensors=ALL_SENSORS, faults=[
        {"kind": kind, "start": a, "duration": b - a, **params}]), show_progress=False).streams
    for name, clean in clean_all.items():
        if name == "events":
            continue
        if name not in touched:
            pd.testing.assert_frame_equal(faulted[name], clean, obj=name)
            continue
        _same_outside(faulted, clean_all, name, a, b)
        inside_f = faulted[name][_inside(faulted[name].t, a, b)].reset_index(drop=True)
        inside_c = clean[_inside(clean.t, a, b)].reset_index(drop=True)
        assert not inside_f.equals(inside_c), f"{kind} left {name} unchanged"
    events = faulted["events"]
    rows = events[(events.kind == kind) & (events.t_start == a)]
    assert len(rows) == 1 and rows.t_end.iloc[0] == b  # the outage row, or the fault's own
