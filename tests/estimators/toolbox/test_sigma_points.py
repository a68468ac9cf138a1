"""Sigma points and the unscented transform against exact moments: linear maps, x^2 of a
Gaussian (mean mu^2 + sigma^2, variance 4 mu^2 sigma^2 + 2 sigma^4) and polar to Cartesian
(E[r cos t] = r cos(t0) exp(-s^2 / 2))."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.toolbox.sigma_points import simplex_points, symmetric_points, unscented_transform

RNG = np.random.default_rng(4)
A = RNG.normal(size=(4, 4))
P = A @ A.T + np.eye(4)
X = np.array([1.0, -2.0, 0.5, 3.0])

SETS = {
    "symmetric, Chan": lambda x, p: symmetric_points(x, p, alpha=0.99, beta=2.0, kappa=0.0),
    "symmetric, small alpha": lambda x, p: symmetric_points(x, p, alpha=1e-3, beta=2.0),
    "simplex, Cho": lambda x, p: simplex_points(x, p, alpha=1.0, beta=2.0, w0=0.0),
    "simplex, w0 and alpha": lambda x, p: simplex_points(x, p, alpha=0.5, beta=2.0, w0=0.3),
}


@pytest.mark.parametrize("make", SETS.values(), ids=SETS.keys())
def test_points_carry_the_mean_and_covariance(make):
    points, wm, wc = make(X, P)
    assert wm.sum() == pytest.approx(1.0)
    n = len(X)
    assert len(points) == (2 * n + 1 if len(points) > n + 2 else n + 2)
    np.testing.assert_allclose(wm @ points, X, atol=1e-10)
    d = points - X
    # the covariance weights differ from the mean weights only at the centre, where d = 0
    np.testing.assert_allclose((wc[:, None] * d).T @ d, P, rtol=1e-9, atol=1e-9)


def test_simplex_set_has_n_plus_2_points():
    points, wm, _ = simplex_points(X, P)
    assert points.shape == (6, 4) and wm.shape == (6,)
    np.testing.assert_allclose(points[0], X)


@pytest.mark.parametrize("make", SETS.values(), ids=SETS.keys())
def test_linear_map_is_exact(make):
    b = RNG.normal(size=(2, 4))
    c = np.array([0.3, -1.0])
    mean, cov, cross, _ = unscented_transform(lambda x: b @ x + c, *make(X, P),
                                              noise_cov=np.eye(2) * 0.1)
    np.testing.assert_allclose(mean, b @ X + c, rtol=1e-9)
    np.testing.assert_allclose(cov, b @ P @ b.T + np.eye(2) * 0.1, rtol=1e-8)
    np.testing.assert_allclose(cross, P @ b.T, rtol=1e-8, atol=1e-9)


@pytest.mark.parametrize("make", SETS.values(), ids=SETS.keys())
def test_square_of_a_gaussian_has_the_exact_mean(make):
    mu, sigma = 1.5, 0.7
    mean, _, _, _ = unscented_transform(lambda x: x**2, *make(np.array([mu]),
                                                              np.array([[sigma**2]])))
    assert mean[0] == pytest.approx(mu**2 + sigma**2, rel=1e-9)  # alpha = 1e-3: W0 ~ -1e6


def test_square_of_a_gaussian_has_the_exact_variance_with_kappa_3_minus_n():
    """alpha = 1, kappa = 3 - n matches the Gaussian kurtosis (Julier & Uhlmann 1997); beta = 0
    then adds nothing at the centre."""
    mu, sigma = 1.5, 0.7
    _, cov, _, _ = unscented_transform(lambda x: x**2, *symmetric_points(
        np.array([mu]), np.array([[sigma**2]]), alpha=1.0, beta=0.0, kappa=2.0))
    assert cov[0, 0] == pytest.approx(4 * mu**2 * sigma**2 + 2 * sigma**4, rel=1e-12)


def test_polar_to_cartesian_mean_beats_linearisation():
    r, theta, s_r, s_t = 100.0, 0.4, 2.0, 0.3
    exact = r * np.exp(-s_t**2 / 2) * np.array([np.cos(theta), np.sin(theta)])
    mean, _, _, _ = unscented_transform(
        lambda x: x[0] * np.array([np.cos(x[1]), np.sin(x[1])]),
        *symmetric_points(np.array([r, theta]), np.diag([s_r**2, s_t**2]), alpha=1.0,
                          beta=0.0, kappa=1.0))
    linearised = r * np.array([np.cos(theta), np.sin(theta)])
    assert np.linalg.norm(mean - exact) < 0.002 * r  # sixth-order error only
    assert np.linalg.norm(linearised - exact) > 0.04 * r


def test_bad_parameters_raise():
    with pytest.raises(ValueError, match="w0"):
        simplex_points(X, P, w0=1.0)
    with pytest.raises(ValueError, match="positive"):
        symmetric_points(X, P, alpha=1.0, kappa=-4.0)


def test_simplex_third_moments_are_not_a_gaussians():
    """A Gaussian's third central moments are zero, so a quadratic function of one variable is
    uncorrelated with every other (E[x_i^2 x_j] = 0 for independent zero-mean x). The
    symmetric set keeps that exactly; the spherical simplex set, built axis by axis with one
    far point per axis (Julier 2003), does not: with unit covariance its weighted E[x_i^2 x_j]
    is of order alpha for i < j (-0.91 alpha for the first pair, n = 4; -0.15 and -0.27 at
    alpha = 0.3). In Cho & Choi's SPKF this is what moves the z-gyro scale factor on a
    straight road under a wide heading prior (docs/reproduction_cho2006.md): the heading
    points' squared spread, mapped through cos(psi), correlates with the scale factor drawn
    beside them."""
    n = 4
    for alpha in (1.0, 0.3):
        sym, wm_s, _ = symmetric_points(np.zeros(n), np.eye(n), alpha=alpha, kappa=3.0 - n)
        simp, wm_p, _ = simplex_points(np.zeros(n), np.eye(n), alpha=alpha)
        for i, j in ((0, 1), (1, 3), (2, 3)):
            assert wm_s @ (sym[:, i] ** 2 * sym[:, j]) == pytest.approx(0.0, abs=1e-12)
            skew = wm_p @ (simp[:, i] ** 2 * simp[:, j])
            assert abs(skew) > 0.1, (alpha, i, j, skew)
