"""Tests of estimators.toolbox.gating: chi-square quantiles against a printed table, the gate's
acceptance rate on consistent innovations, and the threshold rule of Park et al. 2019."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.toolbox import gating

# chi-square upper critical values, NIST/SEMATECH e-Handbook of Statistical Methods, section
# 1.3.6.7.4 (table of the chi-square distribution): (dof, probability) -> value
PRINTED = {(1, 0.95): 3.841, (2, 0.95): 5.991, (3, 0.95): 7.815, (1, 0.99): 6.635,
           (2, 0.99): 9.210, (3, 0.999): 16.266, (5, 0.999): 20.515}


@pytest.mark.parametrize(("key", "value"), PRINTED.items())
def test_chi2_threshold_matches_printed_table(key: tuple[int, float], value: float) -> None:
    assert gating.chi2_threshold(*key) == pytest.approx(value, abs=6e-4)


def test_chi2_threshold_rejects_bad_arguments() -> None:
    with pytest.raises(ValueError, match="dof >= 1"):
        gating.chi2_threshold(0, 0.9)
    with pytest.raises(ValueError, match="probability"):
        gating.chi2_threshold(2, 1.0)


def test_gate_accepts_the_stated_fraction_of_consistent_innovations() -> None:
    rng = np.random.default_rng(3)
    a = np.array([[2.0, 0.0, 0.0], [0.5, 1.0, 0.0], [-0.3, 0.2, 0.4]])
    s = a @ a.T
    nus = rng.standard_normal((20000, 3)) @ a.T  # covariance S
    accepted = np.mean([gating.passes_gate(nu, s, 0.95) for nu in nus])
    # binomial 1-sigma of the fraction: sqrt(0.95 * 0.05 / 20000) = 0.0015
    assert accepted == pytest.approx(0.95, abs=0.005)


def test_normalised_innovation_squared_is_the_mahalanobis_distance() -> None:
    s = np.diag([4.0, 9.0])
    assert gating.normalised_innovation_squared(np.array([2.0, 3.0]), s) == pytest.approx(2.0)
    assert gating.normalised_innovation_squared(3.0, np.array([[9.0]])) == pytest.approx(1.0)


def test_innovation_covariance_is_hph_plus_r() -> None:
    p = np.array([[2.0, 0.5], [0.5, 1.0]])
    h = np.array([[1.0, 1.0]])
    # var(x1 + x2) = 2 + 1 + 2 * 0.5 = 4, plus R = 1
    assert gating.innovation_covariance(p, h, np.array([[1.0]]))[0, 0] == pytest.approx(5.0)


def test_innovation_variances_are_the_diagonal_of_s() -> None:
    """From H's non-zero columns only, the diagonal of the dense H P H^T + R."""
    rng = np.random.default_rng(4)
    a = rng.normal(size=(40, 60))
    p = a @ a.T
    h = np.zeros((6, 40))
    h[:, [2, 7, 30]] = rng.normal(size=(6, 3))
    b = rng.normal(size=(6, 6))
    r = b @ b.T
    np.testing.assert_allclose(gating.innovation_variances(p, h, r),
                               np.diag(gating.innovation_covariance(p, h, r)), rtol=1e-12)


def test_threshold_variance_inflates_beyond_the_threshold() -> None:
    # Park et al. 2019, section III-D: ||f|| - g beyond 0.059 m/s^2 inflates the tilt noise
    assert gating.threshold_variance(0.10, 0.059, 0.01, 0.2) == pytest.approx(0.04)
    assert gating.threshold_variance(0.02, 0.059, 0.01, 0.2) == pytest.approx(1e-4)
    # the low-speed rule: below 5 m/s the GPS velocity noise is inflated
    assert gating.threshold_variance(3.0, 5.0, 0.1, 1.0, above=False) == pytest.approx(1.0)
    assert gating.threshold_variance(8.0, 5.0, 0.1, 1.0, above=False) == pytest.approx(0.01)
