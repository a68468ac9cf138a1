"""IMU constants given as fixed values (``{fixed: ...}``) instead of a 1-sigma: Cho & Choi 2006
situation I fixes the scale factors (eq. 36: 0.2, 0.1, -0.1); the output must be the truth
scaled by exactly those, and every other draw must be unchanged."""

from __future__ import annotations

import numpy as np
import pytest
from sensor_truths import drive_truth

from simulator import columns as col
from simulator.schema import Context
from simulator.sensors.imu import IMU_FIELD, Imu
from simulator.tables import as_frame

# point rate samples, so the output is checked against the analytic truth at each sample time
EQ36 = {"rate_sampling": "point",
        "gyro": {"scale_factor": {"fixed": [0.0, 0.1, -0.1]}, "noise_density": 1e-3},
        "accel": {"scale_factor": {"fixed": [0.2, 0.0, 0.0]}, "bias": {"fixed": 0.05}}}


def _resolve(block: dict) -> tuple[dict, list[str]]:
    ctx = Context("test.yaml")
    out = IMU_FIELD.check(block, ("sensors", "imu"), ctx)
    return out, [str(p) for p in ctx.problems]


@pytest.fixture(scope="module")
def truth():
    return drive_truth()


def test_fixed_scale_factors_and_bias_are_applied_exactly(truth):
    cfg, found = _resolve(EQ36)
    assert not found
    assert cfg["gyro"]["scale_factor"] == {"fixed": [0.0, 0.1, -0.1]}
    imu = Imu(cfg)
    out = as_frame(imu.generate(truth, np.random.default_rng(5))["imu"])
    assert imu.drawn["gyro"]["scale_factor"] == [0.0, 0.1, -0.1]
    assert imu.drawn["accel"]["bias"] == [0.05, 0.05, 0.05]
    k = truth.inertial(out["t"].to_numpy())
    accel = out[list(col.IMU_AXES[3:])].to_numpy()
    np.testing.assert_allclose(accel, k["f_body"] * [1.2, 1.0, 1.0] + 0.05, atol=1e-12)
    # the gyro noise is the same draw as with the scale factors drawn (zero 1-sigma)
    drawn = {"rate_sampling": "point", "gyro": {"scale_factor": 0.0, "noise_density": 1e-3},
             "accel": EQ36["accel"]}
    ref = as_frame(Imu(_resolve(drawn)[0]).generate(truth, np.random.default_rng(5))["imu"])
    gyro = out[list(col.IMU_AXES[:3])].to_numpy()
    noise = ref[list(col.IMU_AXES[:3])].to_numpy() - k["w_body"]
    np.testing.assert_allclose(gyro, k["w_body"] * [1.0, 1.1, 0.9] + noise, atol=1e-12)


@pytest.mark.parametrize("block, message", [
    ({"gyro": {"scale_factor": {"fixed": [0.1, 0.2]}}}, "scale_factor"),
    ({"gyro": {"scale_factor": {"value": 0.1}}}, "value"),
    ({"gyro": {"scale_factor": -0.1}}, "scale_factor"),  # a 1-sigma cannot be negative
    ({"accel": {"bias": {"fixed": "3 deg"}}}, "bias"),
])
def test_bad_fixed_values_are_named(block, message):
    _, found = _resolve(block)
    assert found and all(message in p for p in found), found
