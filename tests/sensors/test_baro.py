"""Standard atmosphere against the ICAO 1993 and U.S. 1976 tables; barometer noise, bias,
weather drift (default rate against the real ARL1 met file), temperature sensitivity, resolution
and range; pressure altitude of the ideal barometer."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pandas as pd
import pytest
from sensor_truths import SHARED, drive_truth, static_truth, truth_from_segments

from simulator.environment.atmosphere import (
    R0_M,
    geopotential_height,
    pressure_altitude_m,
    pressure_pa,
    temperature_k,
)
from simulator.geoid import geoid_undulation_m, orthometric_height_m
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


def msl_height(truth, t) -> np.ndarray:
    """The truth's height above the EGM96 geoid, m, which the bosch-bmp280 preset's pressure
    follows (``geoid: true``)."""
    lat, lon, h = truth.position(np.asarray(t, dtype=float)).T
    return orthometric_height_m(np.degrees(lat), np.degrees(lon), h)


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


def test_ideal_barometer_altitude_is_the_true_orthometric_height():
    truth = drive_truth()
    out = as_frame(make({}).generate(truth, np.random.default_rng(1))["baro"])
    np.testing.assert_allclose(out["altitude"], msl_height(truth, out["t"]), atol=1e-6)


def test_bmp280_noise_bias_resolution():
    # Park et al. 2019, Table 2: 1.3 Pa RMS noise at 20 Hz
    baro = make({"preset": "bosch-bmp280"})
    truth = static_truth(600.0)
    out = as_frame(baro.generate(truth, np.random.default_rng(4))["baro"])
    assert len(out) == 600 * 20 + 1
    # the preset's weather drift (drawn rate) scales the column; the noise is what is left
    sea_level = 101325.0 + baro.drawn["drift_rate"] * out["t"].to_numpy()
    expected = (pressure_pa(msl_height(truth, out["t"])) * sea_level / 101325.0
                + baro.drawn["bias"])
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
    p0 = pressure_pa(msl_height(truth, [0.0])[0])
    # the whole column scales with the sea-level pressure
    assert p[-1] - p[0] == pytest.approx(-100.0 * p0 / 101325.0, rel=1e-9)
    clipped = as_frame(make({"range": ["300 hPa", "1000 hPa"]}).generate(
        truth, np.random.default_rng(5))["baro"])
    assert clipped["pressure"].max() == 100000.0


def met_pressures_hpa() -> np.ndarray:
    """PR column of the ARL1 whole-day met file (refdata 1a), every 15 min."""
    path = SHARED / "refdata" / "gnss" / "arl1_2015-07-19_gnsstk" / "arlm2000.15m"
    if not path.is_file():
        pytest.skip(f"ARL1 met file not found: {path} (shared/refdata is missing)")
    body = path.read_text().split("END OF HEADER")[1].split("\n")
    return np.array([float(line.split()[6]) for line in body if line.strip()])


def test_weather_drift_on_by_default_like_the_real_met_file():
    """The bosch-bmp280 preset draws a sea-level pressure rate per run with 1-sigma 0.4 hPa/h:
    the rms change over one hour of the real ARL1 met file (0.41 hPa, 96 records, 2015-07-19),
    and the pressure of a static hour changes by that rate scaled to the altitude."""
    hourly = np.diff(met_pressures_hpa()[::4])
    real_rms_hpa_h = np.sqrt(np.mean(hourly ** 2))
    baro = make({"preset": "bosch-bmp280", "noise": 0, "resolution": 0, "rate": 1})
    assert baro.config["weather_drift"] * 3600 / 100 == pytest.approx(real_rms_hpa_h, rel=0.25)
    truth = static_truth(3600.0)
    rates = []
    for seed in range(200):
        out = as_frame(baro.generate(truth, np.random.default_rng(seed))["baro"])
        p = out["pressure"].to_numpy()
        rates.append(baro.drawn["drift_rate"])
        p0 = pressure_pa(msl_height(truth, [0.0])[0])
        assert p[-1] - p[0] == pytest.approx(rates[-1] * 3600 * p0 / 101325.0, abs=1e-6)
    assert np.std(rates) * 3600 / 100 == pytest.approx(0.4, rel=0.15)
    assert make({}).config["weather_drift"] == 0.0  # ideal: no weather


def test_temperature_sensitivity():
    """BMP280 temperature coefficient of offset, 1.5 Pa/K (data sheet Table 2): with a 10 K
    warm-up the pressure error is k_T dT(t) exactly, k_T drawn with 1-sigma 1.5 Pa/K."""
    block = {"temperature_coefficient": "1.5 Pa/K",
             "temperature": {"warmup": 10, "warmup_time": 300}}
    baro = make(block)
    truth = static_truth(1200.0)
    ks = []
    for seed in range(300):
        out = as_frame(baro.generate(truth, np.random.default_rng(seed))["baro"])
        t = out["t"].to_numpy()
        error = out["pressure"].to_numpy() - pressure_pa(msl_height(truth, t))
        k = baro.drawn["temperature_coefficient"]
        np.testing.assert_allclose(error, k * 10 * (1 - np.exp(-t / 300)), atol=1e-6)
        ks.append(k)
    assert np.std(ks) == pytest.approx(1.5, rel=0.12)
    assert make({"preset": "bosch-bmp280"}).config["temperature_coefficient"] == 1.5


@pytest.mark.parametrize("block, message", [
    ({"preset": "nope"}, "unknown barometer preset"),
    ({"noise": "1 m"}, "sensors.baro.noise"),
    ({"range": [110000, 30000]}, "must be below"),
    ({"weather_drift": "-1 hPa/h"}, "below the minimum"),
    ({"temperature_coefficient": "1 Pa"}, "sensors.baro.temperature_coefficient"),
])
def test_bad_input_named(block, message):
    ctx = Context("test.yaml")
    BARO_FIELD.check(block, ("sensors", "baro"), ctx)
    assert any(message in str(p) for p in ctx.problems), ctx.problems


# ARL1 (refdata 1a): RINEX header position, 30.383664 N, 97.725413 W, 217.6 m ellipsoidal
ARL1 = {"lat": 30.383664, "lon": -97.725413, "alt": 217.6, "heading": 0.0}


def test_pressure_at_arl1_follows_the_geoid():
    """Issue 19: the BMP280 preset at ARL1 reads the standard atmosphere at the orthometric
    height H = h - N (EGM96 N = -26.9 m there), not at the ellipsoidal height (about 3 hPa
    higher): error-free to its resolution, and with the preset's drawn errors (bias 1 hPa
    1-sigma, weather, noise) centred within 1 hPa of it over 200 runs."""
    truth = truth_from_segments([{"stop": {"duration": 60.0}}], rate_hz=1.0, start=ARL1,
                                utc=dt.datetime(2015, 7, 19))
    big_h = ARL1["alt"] - float(geoid_undulation_m(ARL1["lat"], ARL1["lon"]))
    p_orthometric, p_ellipsoidal = pressure_pa(big_h), pressure_pa(ARL1["alt"])
    assert p_ellipsoidal - p_orthometric > 250.0  # the geoid matters here: about 3 hPa
    exact = make({"preset": "bosch-bmp280", "bias": 0, "noise": 0, "weather_drift": 0,
                  "temperature_coefficient": 0})
    p = as_frame(exact.generate(truth, np.random.default_rng(0))["baro"])["pressure"]
    assert np.abs(p - p_orthometric).max() <= 0.08 + 1e-9  # half the 0.16 Pa resolution
    preset = make({"preset": "bosch-bmp280"})
    means = [as_frame(preset.generate(truth, np.random.default_rng(s))["baro"])["pressure"].mean()
             for s in range(200)]
    assert abs(np.median(means) - p_orthometric) < 100.0  # 1 hPa
    assert np.median(np.abs(np.array(means) - p_orthometric)) < 100.0


def test_ideal_barometer_reads_the_orthometric_height(shared_dir):
    """``preset: ideal`` has no sensor error, but the air's pressure follows the orthometric
    height: standing at 100 m ellipsoidal height on an EGM96 grid node whose undulation is
    published (35 N 135 E, N = 36.355 m, UNAVCO calculator via RTKLIB's t_geoid.c, refdata
    tables/geoid_egm96_rtklib_utest.csv), it reads 100 - 36.355 = 63.645 m, within the grid's
    centimetre storage; ``geoid: false`` reads the ellipsoidal height."""
    table = pd.read_csv(shared_dir / "refdata" / "tables" / "geoid_egm96_rtklib_utest.csv",
                        comment="#")
    node = table[(table.lat_deg == 35.0) & (table.lon_deg == 135.0)].iloc[0]
    start = {"lat": 35.0, "lon": 135.0, "alt": 100.0, "heading": 0.0}
    truth = truth_from_segments([{"stop": {"duration": 10.0}}], rate_hz=1.0, start=start)
    ideal = as_frame(make({"preset": "ideal"}).generate(truth, np.random.default_rng(0))["baro"])
    np.testing.assert_allclose(ideal["altitude"], 100.0 - node.geoid_N_m, atol=0.0051)
    flat = as_frame(make({"geoid": False}).generate(truth, np.random.default_rng(0))["baro"])
    np.testing.assert_allclose(flat["altitude"], 100.0, atol=1e-6)
