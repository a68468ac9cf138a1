"""``toolbox.iono_field``: the pierce-point offsets against the simulator's own pierce points
(``simulator.gnss.errors``), and the split of the field against Gaussian conditioning done
numerically (the joint covariance of the field at the satellites, its value and its gradient
at the zenith pierce point, the gradient's covariances by finite differences of the
kernel)."""

from __future__ import annotations

import numpy as np

from estimators.toolbox.iono_field import field_gains, pierce_offsets_km
from simulator.datasheet import IONO_CORRELATION_LENGTH_KM as L_KM
from simulator.gnss.errors import IONO_SHELL_RADIUS_KM, pierce_points_km


def _sky(n: int = 12, seed: int = 4):
    rng = np.random.default_rng(seed)
    return rng.uniform(np.radians(8.0), np.radians(88.0), n), rng.uniform(0.0, 2 * np.pi, n)


def test_offsets_are_the_simulated_pierce_points():
    """Against the simulated pierce points (the broadcast model's, IS-GPS-200, on the shell,
    at 40 deg north where the model's latitude clip does not act): each offset's length is
    the chord to the receiver's zenith pierce point within 4 %, and the offsets' differences
    are the chords between the satellites' pierce points within 0.06 L (the model's step in
    longitude, psi sin A / cos of the pierce point's latitude, is not a great circle; the
    field's correlation exp(-d^2 / (2 L^2)) moves by under 0.04 for such a change of d)."""
    lat, lon = np.radians(40.0), np.radians(-74.0)
    zenith = IONO_SHELL_RADIUS_KM * np.array([np.cos(lat) * np.cos(lon),
                                              np.cos(lat) * np.sin(lon), np.sin(lat)])
    for seed in range(4):
        el, az = _sky(seed=seed)
        points = pierce_points_km(lat, lon, az, el).T
        offsets = pierce_offsets_km(el, az)
        np.testing.assert_allclose(np.linalg.norm(offsets, axis=1),
                                   np.linalg.norm(points - zenith, axis=1), rtol=0.04)
        chords = np.linalg.norm(points[:, None] - points[None], axis=-1)
        apart = np.linalg.norm(offsets[:, None] - offsets[None], axis=-1)
        assert np.max(np.abs(apart - chords)) < 0.06 * L_KM
        assert chords.max() > 1500.0  # the low satellites' pierce points are far apart


def _kernel(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d2 = np.sum((a[:, None, :] - b[None, :, :]) ** 2, axis=-1)
    return np.exp(-0.5 * d2 / L_KM**2)


def test_split_is_the_conditional_of_the_field():
    """The best linear predictor of the field at each pierce point from its value and gradient
    at the origin, and the remainder's variance, computed by generic Gaussian conditioning on
    covariances built by central differences of the kernel (step 1 km of L = 1000 km)."""
    el, az = _sky()
    x = pierce_offsets_km(el, az)
    h = 1.0
    origin = np.zeros((1, 2))
    steps = h * np.eye(2)

    def d_second(i: int, j: int) -> float:  # Cov(dg/dx_i, dg/dx_j) at the origin
        p, q = steps[i], steps[j]
        k = (_kernel((origin + p), (origin + q)) - _kernel((origin + p), (origin - q))
             - _kernel((origin - p), (origin + q)) + _kernel((origin - p), (origin - q)))
        return float(k[0, 0]) / (4 * h * h)

    # joint covariance of y = g(x_i) and z = [g(0), L dg/dn(0), L dg/de(0)]
    c_yz = np.zeros((len(x), 3))
    c_yz[:, 0] = _kernel(x, origin)[:, 0]
    for i in range(2):
        c_yz[:, 1 + i] = L_KM * (_kernel(x, origin + steps[i])[:, 0]
                                 - _kernel(x, origin - steps[i])[:, 0]) / (2 * h)
    c_zz = np.eye(3)
    c_zz[1:, 1:] = L_KM**2 * np.array([[d_second(i, j) for j in range(2)] for i in range(2)])
    coefficients = c_yz @ np.linalg.inv(c_zz)
    remainder = 1.0 - np.einsum("ij,jk,ik->i", coefficients, c_zz, coefficients)
    gains, own = field_gains(el, az)
    np.testing.assert_allclose(gains, coefficients, atol=1e-5)
    np.testing.assert_allclose(own, remainder, atol=1e-5)
    assert np.all((own >= 0.0) & (own <= 1.0))
