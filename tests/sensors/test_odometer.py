"""Odometer: distance against truth through the scale factor within one tick, exact zero at
standstill, latency, scale-factor drift statistics, schema."""

from __future__ import annotations

import numpy as np
import pytest
from sensor_truths import drive_truth

from simulator.schema import Context
from simulator.sensors import SENSOR_MODELS
from simulator.sensors.odometer import ODOMETER_FIELD, Odometer
from simulator.tables import as_frame


def make(block: dict) -> Odometer:
    ctx = Context("test.yaml")
    cfg = ODOMETER_FIELD.check(block, ("sensors", "odometer"), ctx)
    assert not ctx.problems, ctx.problems
    return Odometer(cfg)


@pytest.fixture(scope="module")
def truth():
    return drive_truth()


def test_registered():
    assert SENSOR_MODELS["odometer"] is Odometer


@pytest.mark.parametrize("scale, tpm, rate", [(1.02, 20.0, 10.0), (0.97, 47.3, 50.0)])
def test_distance_is_scaled_truth_within_one_tick(truth, scale, tpm, rate):
    odo = make({"rate": rate, "scale_factor": scale, "ticks_per_meter": tpm})
    out = as_frame(odo.generate(truth, np.random.default_rng(1))["odometer"])
    wheel = np.sum(out["speed"].to_numpy() / rate)
    true = truth.profile.distance_of_time(out["t"].iloc[-1])
    assert abs(wheel - scale * true) <= 1.0 / tpm + 1e-9
    assert out["ticks"].sum() == pytest.approx(wheel * tpm)
    assert out["ticks"].dtype == np.int64


def test_exact_zero_at_standstill(truth):
    for block in ({"preset": "abs-wheel-speed"}, {"scale_factor": 1.05}):
        out = as_frame(make(block).generate(truth, np.random.default_rng(2))["odometer"])
        t = out["t"].to_numpy()
        still = truth.profile.distance_of_time(np.clip(t - 0.5, 0, None)) == \
            truth.profile.distance_of_time(np.minimum(t + 0.5, truth.duration_s))
        assert still.sum() > 20
        assert np.all(out["speed"].to_numpy()[still] == 0.0)
        assert np.all(out["speed"].to_numpy() >= 0.0)


def test_latency_delays_the_speed(truth):
    out = as_frame(make({"scale_factor": 1.0, "latency": 0.3, "rate": 20}).generate(
        truth, np.random.default_rng(3))["odometer"])
    t = out["t"].to_numpy()
    late = truth.inertial(np.clip(t - 0.3, 0, None))["speed"]
    np.testing.assert_allclose(out["speed"], late, atol=1e-9)
    now = truth.inertial(t)["speed"]
    assert np.abs(out["speed"] - now).max() > 0.1


def test_scale_drift_is_a_random_walk(truth):
    # the scale factor after T seconds has spread scale_drift * sqrt(T)
    odo = make({"scale_drift": "1 %/sqrt(h)", "scale_factor": 1.0})
    ends = []
    for seed in range(300):
        odo.generate(truth, np.random.default_rng(seed))
        ends.append(odo.drawn["scale_factor_end"] - odo.drawn["scale_factor"])
    t_end = np.floor(truth.duration_s * 10) / 10
    assert np.std(ends) == pytest.approx(0.01 / 60 * np.sqrt(t_end), rel=0.12)


@pytest.mark.parametrize("block, message", [
    ({"preset": "nope"}, "unknown odometer preset"),
    ({"scale_factor": 0}, "greater than"),
    ({"latency": "1 m"}, "sensors.odometer.latency"),
    ({"ticks_per_meter": -1}, "below the minimum"),
])
def test_bad_input_named(block, message):
    ctx = Context("test.yaml")
    ODOMETER_FIELD.check(block, ("sensors", "odometer"), ctx)
    assert any(message in str(p) for p in ctx.problems), ctx.problems
