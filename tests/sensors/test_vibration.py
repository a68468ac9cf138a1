"""IMU vibration: engine line rms and frequency, exact increments of the sinusoid, road vibration
rms proportional to speed and zero at standstill, band-limited spectrum, unchanged other draws."""

from __future__ import annotations

import numpy as np
import pytest
from sensor_truths import static_truth, truth_from_segments

from simulator import columns as col
from simulator.schema import Context
from simulator.sensors.imu import IMU_FIELD, Imu
from simulator.tables import as_frame


def run(truth, block: dict, seed: int = 1):
    ctx = Context("test.yaml")
    cfg = IMU_FIELD.check(block, ("sensors", "imu"), ctx)
    assert not ctx.problems, ctx.problems
    imu = Imu(cfg)
    return as_frame(imu.generate(truth, np.random.default_rng(seed))["imu"]), imu


@pytest.fixture(scope="module")
def still():
    return static_truth(60.0)


def test_engine_line(still):
    block = {"rate": 200, "vibration": {"engine_frequency": 27.0, "engine_accel": 0.3,
                                        "engine_gyro": 0.01}}
    out, _ = run(still, block)
    ideal, _ = run(still, {"rate": 200})
    # rates are interval means: the line's rms is A |sinc(f dt)|, the moving average's gain
    gain = abs(np.sinc(27.0 / 200))
    for axes, rms in ((col.IMU_AXES[3:], 0.3 * gain), (col.IMU_AXES[:3], 0.01 * gain)):
        vib = (out[list(axes)] - ideal[list(axes)]).to_numpy()
        np.testing.assert_allclose(np.sqrt(np.mean(vib**2, axis=0)), rms, rtol=0.01)
        spectrum = np.abs(np.fft.rfft(vib[:, 0]))
        freq = np.fft.rfftfreq(len(vib), 1 / 200)
        assert freq[np.argmax(spectrum)] == pytest.approx(27.0, abs=0.05)


def test_engine_increments_are_exact_integrals(still):
    # the increment of A sin(2 pi f t + p) over dt has rms A/sqrt(2) |sinc(f dt)| dt
    f, rate = 27.0, 100.0
    block = {"rate": rate, "output": "increment",
             "vibration": {"engine_frequency": f, "engine_accel": 0.3}}
    out, _ = run(still, block)
    ideal, _ = run(still, {"rate": rate, "output": "increment"})
    vib = (out["accel_x"] - ideal["accel_x"]).to_numpy()
    expected = 0.3 * abs(np.sinc(f / rate)) / rate
    assert np.sqrt(np.mean(vib**2)) == pytest.approx(expected, rel=0.01)


def test_road_vibration_scales_with_speed_and_band():
    truth = truth_from_segments([{"stop": {"duration": 20}},
                                 {"accelerate": {"to_speed": 20, "accel": 2}},
                                 {"straight": {"duration": 60}}])
    block = {"rate": 200, "vibration": {"road_accel": 0.5, "road_speed": 10.0,
                                        "road_band": [8.0, 20.0]}}
    out, _ = run(truth, block)
    ideal, _ = run(truth, {"rate": 200})
    vib = (out[list(col.IMU_AXES[3:])] - ideal[list(col.IMU_AXES[3:])]).to_numpy()
    t = out["t"].to_numpy()
    assert np.all(vib[t < 19.0] == 0.0)
    cruise = t > 40.0
    # at 20 m/s, twice the 10 m/s reference
    np.testing.assert_allclose(np.sqrt(np.mean(vib[cruise] ** 2, axis=0)), 1.0, rtol=0.05)
    spectrum = np.abs(np.fft.rfft(vib[cruise, 1])) ** 2
    freq = np.fft.rfftfreq(cruise.sum(), 1 / 200)
    in_band = (freq >= 7.5) & (freq <= 20.5)
    assert spectrum[in_band].sum() / spectrum.sum() > 0.95


def test_vibration_leaves_other_draws_unchanged(still):
    _, plain = run(still, {"preset": "automotive"}, seed=4)
    _, shaken = run(still, {"preset": "automotive",
                            "vibration": {"engine_accel": 0.2, "road_accel": 0.1}}, seed=4)
    assert plain.drawn == shaken.drawn


def test_bad_band():
    ctx = Context("test.yaml")
    IMU_FIELD.check({"vibration": {"road_band": [30, 5]}}, ("sensors", "imu"), ctx)
    assert any("sensors.imu.vibration.road_band" in str(p) for p in ctx.problems)
