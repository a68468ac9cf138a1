"""Magnetometer: the IGRF field at two places against the NOAA NCEI calculator values that
ppigrf's own test suite uses; hard and soft iron; disturbances only inside covered zones."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pytest
from sensor_truths import truth_from_segments

from simulator.scenario.schema import Context
from simulator.sensors import SENSOR_MODELS
from simulator.sensors.mag import MAG_FIELD, Magnetometer
from simulator.tables import as_frame

# NOAA NCEI geomagnetic calculator, IGRF, 2020-01-01, 5 km above the WGS-84 ellipsoid, as in
# ppigrf's test data (klaundal/ppigrf test/data/2020-01-01/b_{n,e,z}.csv): north, east, down, nT
NCEI = [(37.0, 127.0, (29683.9, -4408.0, 40976.6)),
        (-34.0, 151.0, (23981.7, 5357.9, -51441.4))]


def make(block: dict) -> Magnetometer:
    ctx = Context("test.yaml")
    cfg = MAG_FIELD.check(block, ("sensors", "mag"), ctx)
    assert not ctx.problems, ctx.problems
    return Magnetometer(cfg)


def standing(lat: float, lon: float, heading: float = 0.0, alt: float = 5000.0):
    truth = truth_from_segments([{"stop": {"duration": 5}}], rate_hz=1.0,
                                start={"lat": lat, "lon": lon, "alt": alt, "heading": heading})
    truth.utc_start = dt.datetime(2020, 1, 1)
    return truth


def test_registered():
    assert SENSOR_MODELS["mag"] is Magnetometer


@pytest.mark.parametrize("lat, lon, ncei", NCEI)
def test_igrf_magnitude_and_inclination(lat, lon, ncei):
    out = as_frame(make({}).generate(standing(lat, lon), np.random.default_rng(0))["mag"])
    b = out[["mag_x", "mag_y", "mag_z"]].to_numpy()[0] * 1e9
    ref = np.array(ncei)
    # IGRF-14 (ppigrf) against the IGRF-13-era calculator: agreement to about 10 nT
    assert np.linalg.norm(b) == pytest.approx(np.linalg.norm(ref), abs=15.0)
    inclination = np.degrees(np.arctan2(b[2], np.hypot(b[0], b[1])))
    ref_inclination = np.degrees(np.arctan2(ref[2], np.hypot(ref[0], ref[1])))
    assert inclination == pytest.approx(ref_inclination, abs=0.02)
    np.testing.assert_allclose(b, ref, atol=15.0)


def test_heading_rotates_the_horizontal_field():
    east = as_frame(make({}).generate(standing(37.0, 127.0, heading=90.0),
                                      np.random.default_rng(0))["mag"]).iloc[0]
    north = as_frame(make({}).generate(standing(37.0, 127.0),
                                       np.random.default_rng(0))["mag"]).iloc[0]
    # facing east, the body x axis sees the east component, the y axis minus the north one
    assert east["mag_x"] == pytest.approx(north["mag_y"], rel=1e-9)
    assert east["mag_y"] == pytest.approx(-north["mag_x"], rel=1e-9)


def test_hard_and_soft_iron():
    truth = standing(37.0, 127.0)
    ideal = as_frame(make({}).generate(truth, np.random.default_rng(0))["mag"])
    mag = make({"hard_iron": "5 uT", "soft_iron": 0.02})
    out = as_frame(mag.generate(truth, np.random.default_rng(0))["mag"])
    cols = ["mag_x", "mag_y", "mag_z"]
    soft = np.array(mag.drawn["soft_iron"])
    expected = ideal[cols].to_numpy() @ (np.eye(3) + soft).T + np.array(mag.drawn["hard_iron"])
    np.testing.assert_allclose(out[cols], expected, atol=1e-15)


def test_disturbance_only_in_covered_zones():
    truth = truth_from_segments([
        {"stop": {"duration": 5}}, {"accelerate": {"to_speed": 10, "accel": 2}},
        {"straight": {"length": 300, "zone": "tunnel"}}, {"straight": {"length": 200}}])
    truth.environment = {"zones": {"tunnel": {"sky": "none"}}}
    block = {"disturbance": "20 uT"}
    ideal = as_frame(make({}).generate(truth, np.random.default_rng(0))["mag"])
    out = as_frame(make(block).generate(truth, np.random.default_rng(0))["mag"])
    diff = np.linalg.norm((out[["mag_x", "mag_y", "mag_z"]] - ideal[["mag_x", "mag_y", "mag_z"]])
                          .to_numpy(), axis=1)
    inside = truth.zone_at(out["t"].to_numpy()) == "tunnel"
    assert inside.sum() > 100
    assert np.all(diff[~inside] == 0.0)
    assert np.sqrt(np.mean(diff[inside] ** 2)) == pytest.approx(20e-6 * np.sqrt(3), rel=0.4)
