"""The numba strapdown kernel's Earth model is ``simulator.earth``'s: its normal gravity, radii
of curvature and Earth and transport rates equal earth.py's on random places and velocities
(the kernel restates them in compiled form; its constants are imported from earth.py)."""

from __future__ import annotations

import numpy as np

from estimators.toolbox import strapdown
from simulator import earth

RNG = np.random.default_rng(12)
LAT = RNG.uniform(-np.radians(89.0), np.radians(89.0), 200)
ALT = RNG.uniform(-500.0, 9000.0, 200)
V_NED = RNG.normal(0.0, 30.0, (200, 3))


def test_gravity_equals_earth_normal_gravity():
    kernel = np.array([strapdown._normal_gravity(lat, h) for lat, h in zip(LAT, ALT, strict=True)])
    np.testing.assert_allclose(kernel, earth.normal_gravity(LAT, ALT), rtol=1e-14, atol=0)


def test_radii_equal_earth_radii_of_curvature():
    kernel = np.array([strapdown._radii(lat) for lat in LAT])
    rn, re = earth.radii_of_curvature(LAT)
    np.testing.assert_allclose(kernel[:, 0], rn, rtol=1e-14, atol=0)
    np.testing.assert_allclose(kernel[:, 1], re, rtol=1e-14, atol=0)


def test_earth_and_transport_rates_equal_earth_rates():
    w_ie, w_en = zip(*(strapdown._nav_rates(lat, h, v)
                       for lat, h, v in zip(LAT, ALT, V_NED, strict=True)), strict=True)
    np.testing.assert_allclose(np.array(w_ie), earth.earth_rate_ned(LAT), rtol=1e-14,
                               atol=1e-20)
    np.testing.assert_allclose(np.array(w_en), earth.transport_rate_ned(LAT, ALT, V_NED),
                               rtol=1e-13, atol=1e-20)
