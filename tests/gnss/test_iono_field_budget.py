"""The receivers' model of the ionosphere field's residual (``simulator.datasheet.
iono_field_covariance``, read by the fix's reported accuracy and by ``gnss_wls``) against the
simulator's own draw of that field (``simulator.gnss.errors.IonoField``: random plane waves over
the Klobuchar pierce points), which it does not call: an ensemble of independent draws at one
epoch of an open sky, each satellite's residual f g_i I_i (f = 1.5 x 0.2, I_i its broadcast
delay), and the position error a weighted least squares makes of it.

Tolerance from the sample: the variance of N draws of a Gaussian has a relative standard error
sqrt(2 / N), 0.05 for N = 800; the bounds are four of them. The satellites-independent model
(the field's variance on each satellite alone, the receivers' model before) misses the
ensemble's position variance by more than three times the bound on this sky (east: 1.8 times
the variance; on the quickstart's sky north 2.1 times, docs/scores.md)."""

from __future__ import annotations

import numpy as np

from simulator.datasheet import iono_field_covariance, pierce_chord_km
from simulator.earth import ned_to_ecef_matrix
from simulator.gnss.errors import IonoField, pierce_points_km

DRAWS = 800
FIELD = 1.5 * 0.2  # the automotive receiver's field 1-sigma fraction (iono_scale iono_residual)
LAT, LON = np.radians(37.5), np.radians(127.0)
# a sky of nine satellites (azimuth, elevation in deg), from the quickstart's at t = 100 s
SKY = np.radians([[60, 84], [154, 23], [214, 29], [300, 45], [20, 15], [110, 55],
                  [250, 12], [330, 20], [180, 65]])


def _sky():
    az, el = SKY[:, 0], SKY[:, 1]
    # a daytime broadcast delay: 4 m at the zenith times the thin shell's obliquity factor
    iono = 4.0 / np.sqrt(1.0 - (6371.0 / 6721.0 * np.cos(el)) ** 2)
    enu = np.column_stack([np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)])
    c_ne = ned_to_ecef_matrix(LAT, LON)
    los_ecef = np.column_stack([enu[:, 1], enu[:, 0], -enu[:, 2]]) @ c_ne.T
    h = np.column_stack([-(los_ecef @ c_ne), np.ones(len(az))])
    weight = 1.0 / (0.5**2 + (0.5 * iono) ** 2)  # the independent share a receiver weights by
    gain = np.linalg.solve(h.T @ (h * weight[:, None]), (h * weight[:, None]).T)[:3]
    return az, el, iono, gain


def _drawn_residuals(az, el, iono) -> np.ndarray:
    """The simulator's field at the sky's pierce points, DRAWS independent drives."""
    pierce = pierce_points_km(LAT, LON, az, el)[:, :, None]
    rng = np.random.default_rng(11)
    return np.array([FIELD * iono * IonoField(rng, 1, 1.0)(pierce)[:, 0]
                     for _ in range(DRAWS)])


def test_the_field_covariance_is_the_simulated_fields():
    az, el, iono, gain = _sky()
    drawn = _drawn_residuals(az, el, iono)
    model = iono_field_covariance(FIELD, iono, az, el)
    bound = 4.0 * np.sqrt(2.0 / DRAWS)
    # each satellite's variance, and the position error the least squares makes of the field
    np.testing.assert_allclose(np.mean(drawn**2, axis=0) / np.diag(model), 1.0, atol=bound)
    position = drawn @ gain.T
    expected = np.diag(gain @ model @ gain.T)
    ratio = np.mean(position**2, axis=0) / expected
    assert np.all(np.abs(ratio - 1.0) < bound), ratio
    independent = np.diag(gain @ np.diag(np.diag(model)) @ gain.T)
    assert np.any(np.abs(independent / np.mean(position**2, axis=0) - 1.0) > 3.0 * bound)


def test_the_pierce_chords_are_the_simulators_within_its_approximation():
    """The receivers' thin-shell chords against the distances between the simulator's
    Klobuchar pierce points (its approximate psi = 0.0137 / (E + 0.11) - 0.022 semicircles):
    within 5 % or 20 km."""
    az, el = SKY[:, 0], SKY[:, 1]
    points = pierce_points_km(LAT, LON, az, el)
    distance = np.linalg.norm(points[:, :, None] - points[:, None, :], axis=0)
    chord = pierce_chord_km(az, el)
    assert np.all(np.abs(chord - distance) <= np.maximum(0.05 * distance, 20.0))
