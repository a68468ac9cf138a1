"""Standard atmosphere against the ICAO 1993 and U.S. 1976 tables; barometer noise, bias,
weather drift, resolution and range; pressure altitude of the ideal barometer."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from sensor_truths import SHARED, drive_truth, static_truth

from simulator.environment.atmosphere import (
    R0_M,
    geopotential_height,
    pressure_altitude_m,
    pressure_pa,
    temperature_k,
)
from simulator.schema import Context
from simulator.sensors import SENSOR_MODELS
from simulator.sensors.baro import BARO_FIELD, Barometer
from simulator.tables import as_frame

TABLES = SHARED / "refdata" / "tables"


def table(name: str) -> pd.DataFrame:
    path = TABLES / name
    if not path.is_file():
        pytest.skip(f"reference table not found: {path} (shared/refdata is missing)")
    return pd.read_csv(path, comment="#")


def make(block: dict) -> Barometer:
    ctx = Context("test.yaml")
    cfg = BARO_FIELD.check(block, ("sensors", "baro"), ctx)
    assert not ctx.problems, ctx.problems
    return Barometer(cfg)


def test_icao_1993_table():
    # ICAO Doc 7488/3 values as transcribed (6 significant digits), -5 km ... 81 km
    icao = table("icao_standard_atmosphere_1993_ambiance.csv")
    h = icao["h_m"].to_numpy()
    np.testing.assert_allclose(pressure_pa(h), icao["p_Pa"], rtol=1e-4)
    np.testing.assert_allclose(temperature_k(h), icao["T_K"], atol=1.5e-3)
    np.testing.assert_allclose(geopotential_height(h), icao["H_m"], atol=0.5)
    assert pressure_pa(1000.0) == pytest.approx(89876.3, abs=0.05)


def test_us_1976_table():
    # the table's elevation is geopotential height; pressure to 1e-8 of the printed values
    us = table("us_standard_atmosphere_1976_astronomy_engine.csv")
    big_h = us["elevation"].to_numpy(dtype=float)
    h = R0_M * big_h / (R0_M - big_h)
    np.testing.assert_allclose(pressure_pa(h), us["pressure"], rtol=5e-5)
    np.testing.assert_allclose(temperature_k(h), us["temperature"], atol=1e-9)


def test_pressure_altitude_inverts_pressure():
    h = np.linspace(-5000.0, 80000.0, 1001)
    np.testing.assert_allclose(pressure_altitude_m(pressure_pa(h)), h, atol=1e-6)


def test_registered():
    assert SENSOR_MODELS["baro"] is Barometer


def test_ideal_barometer_altitude_is_truth():
    truth = drive_truth()
    out = as_frame(make({}).generate(truth, np.random.default_rng(1))["baro"])
    np.testing.assert_allclose(out["altitude"], truth.position(out["t"])[:, 2], atol=1e-6)


def test_bmp280_noise_bias_resolution():
    # Park et al. 2019, Table 2: 1.3 Pa RMS noise at 20 Hz
    baro = make({"preset": "bosch-bmp280"})
    truth = static_truth(600.0)
    out = as_frame(baro.generate(truth, np.random.default_rng(4))["baro"])
    assert len(out) == 600 * 20 + 1
    expected = pressure_pa(truth.position(out["t"])[:, 2]) + baro.drawn["bias"]
    residual = out["pressure"].to_numpy() - expected
    assert np.std(residual) == pytest.approx(1.3, rel=0.05)
    assert abs(np.mean(residual)) < 0.1
    np.testing.assert_allclose(out["pressure"] / 0.16, np.round(out["pressure"] / 0.16),
                               atol=1e-6)


def test_weather_drift_and_range():
    truth = static_truth(3600.0)
    out = as_frame(make({"drift": "-1 hPa/h", "rate": 1}).generate(truth,
                                                                   np.random.default_rng(5))["baro"])
    p = out["pressure"].to_numpy()
    p0 = pressure_pa(truth.position([0.0])[0, 2])
    # the whole column scales with the sea-level pressure
    assert p[-1] - p[0] == pytest.approx(-100.0 * p0 / 101325.0, rel=1e-9)
    clipped = as_frame(make({"range": ["300 hPa", "1000 hPa"]}).generate(
        truth, np.random.default_rng(5))["baro"])
    assert clipped["pressure"].max() == 100000.0


@pytest.mark.parametrize("block, message", [
    ({"preset": "nope"}, "unknown barometer preset"),
    ({"noise": "1 m"}, "sensors.baro.noise"),
    ({"range": [110000, 30000]}, "must be below"),
])
def test_bad_input_named(block, message):
    ctx = Context("test.yaml")
    BARO_FIELD.check(block, ("sensors", "baro"), ctx)
    assert any(message in str(p) for p in ctx.problems), ctx.problems
