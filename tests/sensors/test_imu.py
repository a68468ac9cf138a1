"""IMU model: schema and presets, exact truth for the ideal unit, each deterministic error term
against its closed form, lever arm against rigid-body kinematics, reduced units."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from sensor_truths import drive_truth, truth_from_segments

from simulator import columns as col
from simulator.earth import G0_M_S2
from simulator.schema import Context
from simulator.sensors import SENSOR_FIELDS, SENSOR_MODELS
from simulator.sensors.imu import IMU_FIELD, REDUCED_UNITS, Imu
from simulator.sensors.imu_presets import IMU_PRESETS
from simulator.tables import as_frame


def resolve(block: dict) -> dict:
    ctx = Context("test.yaml")
    out = IMU_FIELD.check(block, ("sensors", "imu"), ctx)
    assert not ctx.problems, ctx.problems
    return out


def problems(block: dict) -> list[str]:
    ctx = Context("test.yaml")
    IMU_FIELD.check(block, ("sensors", "imu"), ctx)
    return [str(p) for p in ctx.problems]


@pytest.fixture(scope="module")
def truth():
    return drive_truth()


def run(truth, block: dict, seed: int = 3):
    """The unit's output; rates are point samples unless the block says otherwise, so each error
    term is checked against the analytic truth at the sample time."""
    imu = Imu(resolve({"rate_sampling": "point", **block}))
    return as_frame(imu.generate(truth, np.random.default_rng(seed))["imu"]), imu


def test_registered():
    assert SENSOR_FIELDS["imu"] is IMU_FIELD and SENSOR_MODELS["imu"] is Imu


def test_preset_merged_with_overrides_winning():
    cfg = resolve({"preset": "bosch-smi130", "gyro": {"noise_density": "0.01 deg/s/sqrt(Hz)"}})
    # Park et al. 2019, Table 1: 1 deg/s zero-point offset, 70 mg, 0.19 mg/sqrt(Hz), 20 Hz
    assert cfg["rate"] == 20.0
    assert cfg["gyro"]["bias"] == pytest.approx(np.radians(1.0))
    assert cfg["accel"]["bias"] == pytest.approx(0.070 * G0_M_S2)
    assert cfg["accel"]["noise_density"] == pytest.approx(0.19e-3 * G0_M_S2)
    assert cfg["gyro"]["noise_density"] == pytest.approx(np.radians(0.01))
    # every value is shown in the resolved block
    assert all(v is not None for k, v in cfg["gyro"].items()
               if k not in ("bias_correlation_time", "range", "bandwidth"))


def test_every_preset_resolves():
    for name in IMU_PRESETS:
        cfg = resolve({"preset": name})
        assert cfg["preset"] == name and cfg["rate"] > 0


@pytest.mark.parametrize("block, message", [
    ({"preset": "nope"}, "unknown IMU preset"),
    ({"gyro": {"noise_density": "1 m"}}, "sensors.imu.gyro.noise_density"),
    ({"accel": {"bias": -1.0}}, "below the minimum"),
    ({"gyro": {"range": 1.0, "resolution": 2.0}}, "must be smaller than range"),
    ({"gyro": {"bias": [1.0, 2.0]}}, "expected a list of 3"),
    ({"axes": ["gyro_q"]}, "is not one of"),
    ({"accel": {"g_sensitivity": 1.0}}, "unknown key"),
    ({"accel": {"gauss_markov_sigma": [0.0, 1e-3, 0.0]}}, "gauss_markov_correlation_time"),
    ({"gyro": {"gauss_markov_sigma": 1e-4, "gauss_markov_correlation_time": [5.0, 0.0, 5.0]}},
     "must be above 0 on every axis whose gauss_markov_sigma is"),
])
def test_bad_input_named(block, message):
    found = problems(block)
    assert found and any(message in p for p in found), found


def test_ideal_point_rate_output_is_truth(truth):
    out, _ = run(truth, {"preset": "ideal", "rate": 50})
    k = truth.inertial(out["t"].to_numpy())
    np.testing.assert_array_equal(out[list(col.IMU_AXES[:3])].to_numpy(), k["w_body"])
    np.testing.assert_array_equal(out[list(col.IMU_AXES[3:])].to_numpy(), k["f_body"])


def _assert_interval_integrals(truth, out, dt: float, per_second: bool, abs_tol: float) -> None:
    """Each row against adaptive quadrature (scipy.integrate.quad) of the analytic body rate and
    specific force over (t - dt, t] (divided by dt when ``per_second``), on rows spread over the
    drive: the first, and some whose interval holds a kinematic breakpoint."""
    breaks = truth.breakpoints()
    rows = np.unique(np.concatenate([np.searchsorted(out["t"], breaks[:6]),
                                     np.linspace(0, len(out) - 1, 8).astype(int)]))
    for i in rows:
        t1 = out["t"].iloc[i]
        for j, axis in enumerate(col.IMU_AXES):
            key, comp = ("w_body", j) if j < 3 else ("f_body", j - 3)
            exact, _ = quad(lambda s, key=key, comp=comp: truth.inertial(s)[key][0, comp],
                            t1 - dt, t1, points=breaks[(breaks > t1 - dt) & (breaks < t1)],
                            epsabs=1e-14, epsrel=1e-12)
            assert out[axis].iloc[i] == pytest.approx(exact / dt if per_second else exact,
                                                      abs=abs_tol)


def test_ideal_rate_output_is_interval_mean(truth):
    # the default rate sampling; the first row's interval starts before the drive, where the
    # truth holds its starting state
    out, imu = run(truth, {"preset": "ideal", "rate": 50, "rate_sampling": "interval_mean"})
    assert imu.timing()["imu"]["delay_s"] == pytest.approx(0.01)  # half a sample
    assert out["t"].iloc[0] == 0.0
    _assert_interval_integrals(truth, out, 0.02, per_second=True, abs_tol=1e-9)


def test_ideal_increments_are_exact_integrals(truth):
    out, _ = run(truth, {"preset": "ideal", "rate": 100, "output": "increment"})
    _assert_interval_integrals(truth, out, 0.01, per_second=False, abs_tol=1e-11)


def test_scale_factor_and_misalignment_follow_drawn_matrix(truth):
    block = {"gyro": {"scale_factor": "1 %", "misalignment": "2 mrad"},
             "accel": {"scale_factor": "0.5 %", "misalignment": "1 mrad"}}
    out, imu = run(truth, block)
    k = truth.inertial(out["t"].to_numpy())
    for group, true, axes in (("gyro", k["w_body"], col.IMU_AXES[:3]),
                              ("accel", k["f_body"], col.IMU_AXES[3:])):
        d = imu.drawn[group]
        m = np.array(d["misalignment"]) + np.diag(d["scale_factor"])
        assert np.all(np.diag(np.array(d["misalignment"])) == 0)
        np.testing.assert_allclose(out[list(axes)].to_numpy(), true @ (np.eye(3) + m).T,
                                   rtol=0, atol=1e-12)


def test_turn_on_bias_temperature_and_ramp(truth):
    block = {"gyro": {"bias": 0.01, "temperature_coefficient": 1e-3, "ramp": 1e-5},
             "temperature": {"offset": 2.0, "warmup": 10.0, "warmup_time": 30.0}}
    out, imu = run(truth, block)
    t = out["t"].to_numpy()
    k = truth.inertial(t)
    d = imu.drawn["gyro"]
    d_temp = 2.0 + 10.0 * (1 - np.exp(-t / 30.0))
    expected = (k["w_body"] + np.array(d["bias"]) + d_temp[:, None] * d["temperature_coefficient"]
                + t[:, None] * np.array(d["ramp"]))
    np.testing.assert_allclose(out[list(col.IMU_AXES[:3])].to_numpy(), expected, atol=1e-12)
    assert np.all(np.abs(d["ramp"]) == 1e-5)


def test_scale_factor_temperature_coefficient(truth):
    block = {"accel": {"scale_factor_temperature_coefficient": "100 ppm/K"},
             "temperature": {"offset": -5.0, "warmup": 20.0, "warmup_time": 40.0}}
    out, imu = run(truth, block)
    t = out["t"].to_numpy()
    k = truth.inertial(t)
    s_t = np.array(imu.drawn["accel"]["scale_factor_temperature_coefficient"])
    d_temp = -5.0 + 20.0 * (1 - np.exp(-t / 40.0))
    np.testing.assert_allclose(out[list(col.IMU_AXES[3:])].to_numpy(),
                               k["f_body"] * (1 + d_temp[:, None] * s_t), atol=1e-12)
    assert np.all(s_t != 0)


def test_g_sensitivity(truth):
    out, imu = run(truth, {"gyro": {"g_sensitivity": "0.1 deg/s/g"}})
    k = truth.inertial(out["t"].to_numpy())
    g = np.array(imu.drawn["gyro"]["g_sensitivity"])
    np.testing.assert_allclose(out[list(col.IMU_AXES[:3])].to_numpy(),
                               k["w_body"] + k["f_body"] @ g.T, atol=1e-14)


def test_saturation_and_quantisation(truth):
    out, _ = run(truth, {"gyro": {"range": "5 deg/s", "resolution": "0.1 deg/s"},
                         "accel": {"range": "0.5 g", "resolution": "10 mg"}})
    gz = out["gyro_z"].to_numpy()
    q = np.radians(0.1)
    np.testing.assert_allclose(gz / q, np.round(gz / q), atol=1e-9)
    assert np.abs(gz).max() == pytest.approx(np.radians(5.0), abs=q)
    assert out["accel_z"].min() == pytest.approx(-0.5 * G0_M_S2, abs=0.01 * G0_M_S2)


def test_increment_quantisation_carries_remainder(truth):
    ideal, _ = run(truth, {"output": "increment"})
    quant, _ = run(truth, {"output": "increment", "accel": {"resolution": "50 mg"}})
    step = 0.05 * G0_M_S2 * 0.01
    # each increment is off by up to a few quanta, but the running sum by at most half a quantum
    assert np.abs(quant["accel_x"] - ideal["accel_x"]).max() > 0.5 * step
    drift = np.abs(np.cumsum(quant["accel_x"]) - np.cumsum(ideal["accel_x"]))
    assert drift.max() <= 0.5 * step + 1e-12


def test_lever_arm_centripetal_in_steady_turn():
    # steady right turn of radius 40 m at 12 m/s: a unit r to the right of the reference point
    # runs on a circle smaller by r, so its centripetal acceleration (v/R)^2 (R - r) is lower by
    # (v/R)^2 r (to 1 %: the body roll in the turn tilts the rate vector by a few degrees)
    truth = truth_from_segments([{"stop": {"duration": 1}},
                                 {"accelerate": {"to_speed": 12, "accel": 2}},
                                 {"turn": {"angle": 180, "radius": 40}}],
                                start={"lat": 0.0, "lon": 0.0, "alt": 0.0, "heading": 0.0})
    ideal, _ = run(truth, {"rate": 100})
    moved, _ = run(truth, {"rate": 100, "lever_arm": [0.0, 1.5, 0.0]})
    t = ideal["t"].to_numpy()
    w = truth.inertial(t)["w_body"]
    steady = np.abs(w[:, 2] - w[:, 2].max()) < 1e-5
    assert steady.sum() > 100
    diff = (moved["accel_y"] - ideal["accel_y"]).to_numpy()[steady]
    np.testing.assert_allclose(diff, -(12.0 / 40.0) ** 2 * 1.5, rtol=1e-2)
    np.testing.assert_allclose(moved[list(col.IMU_AXES[:3])], ideal[list(col.IMU_AXES[:3])])


def test_lever_arm_increment_matches_rate(truth):
    rate, _ = run(truth, {"rate": 100, "lever_arm": [0.5, -0.3, 0.8]})
    incr, _ = run(truth, {"rate": 100, "output": "increment", "lever_arm": [0.5, -0.3, 0.8]})
    # the increment over (t - dt, t] against the trapezoid of the rate samples
    trap = 0.5 * (rate["accel_y"].to_numpy()[:-1] + rate["accel_y"].to_numpy()[1:]) * 0.01
    np.testing.assert_allclose(incr["accel_y"].to_numpy(), trap, atol=2e-4)


def test_mounting_yaw_90_swaps_axes(truth):
    ideal, _ = run(truth, {})
    turned, _ = run(truth, {"mounting": [0.0, 0.0, 90.0]})
    np.testing.assert_allclose(turned["accel_x"], ideal["accel_y"], atol=1e-12)
    np.testing.assert_allclose(turned["accel_y"], -ideal["accel_x"], atol=1e-12)
    np.testing.assert_allclose(turned["gyro_z"], ideal["gyro_z"], atol=1e-15)


def test_timestamp_jitter_samples_truth_off_the_stamp(truth):
    ideal, _ = run(truth, {})
    jittered, _ = run(truth, {"timestamp_jitter": "1 ms"})
    np.testing.assert_array_equal(jittered["t"], ideal["t"])
    diff = (jittered["gyro_z"] - ideal["gyro_z"]).to_numpy()
    assert 0 < np.abs(diff).max() < 1e-3


@pytest.mark.parametrize("unit", ["riss3d", "drm1", "drm2"])
def test_reduced_units_leave_out_exactly_the_missing_axes(truth, unit):
    out, imu = run(truth, {"preset": "automotive", "axes": unit})
    assert list(out.columns) == ["t", *[a for a in col.IMU_AXES if a in REDUCED_UNITS[unit]]]
    full, _ = run(truth, {"preset": "automotive"})
    # the channels a reduced unit has are the same as the full unit's (same draws)
    np.testing.assert_array_equal(out[REDUCED_UNITS[unit]], full[REDUCED_UNITS[unit]])
    assert imu.config["axes"] == REDUCED_UNITS[unit]


def test_seeded_output_is_reproducible(truth):
    a, _ = run(truth, {"preset": "consumer"}, seed=11)
    b, _ = run(truth, {"preset": "consumer"}, seed=11)
    c, _ = run(truth, {"preset": "consumer"}, seed=12)
    np.testing.assert_array_equal(a.to_numpy(), b.to_numpy())
    assert not np.allclose(a["gyro_x"], c["gyro_x"])
