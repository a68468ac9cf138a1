"""LAMBDA against exhaustive integer search and the published example of the method.

Exhaustive search: every integer vector in the box that must contain the two best candidates
(the ellipsoid ``(a - z)^T Q^-1 (a - z) <= chi`` lies within ``|a_i - z_i| <= sqrt(chi Q_ii)``,
with chi the second-smallest norm among a few simple integer candidates), evaluated in full.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import norm, ortho_group

from estimators.toolbox.ambiguity import (
    bootstrap_success_rate,
    decorrelate,
    ils,
    ratio,
    ratio_failure_rate,
    resolve,
)


def _norms(a: np.ndarray, q_inv: np.ndarray, z: np.ndarray) -> np.ndarray:
    e = a - z
    return np.einsum("ki,ij,kj->k", e, q_inv, e)


def _bootstrap(a: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Sequential conditional rounding in the original order (integer bootstrapping)."""
    a = a.copy()
    q = q.copy()
    z = np.zeros_like(a)
    for i in range(a.size):
        z[i] = np.round(a[i])
        gain = q[i:, i] / q[i, i]
        a[i:] -= gain * (a[i] - z[i])
        q[i:, i:] -= np.outer(gain, q[i, i:])
    return z


def _exhaustive(a: np.ndarray, q: np.ndarray,
                bound: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The two best integer vectors: every integer vector inside the ellipsoid
    ``(a - z)^T Q^-1 (a - z) <= chi`` listed and evaluated (Fincke & Pohst 1985 enumeration in
    the original coordinates: no reduction, no ordering, no shrinking), with chi the
    second-smallest norm among distinct integer vectors (rounding, bootstrapping, their unit
    neighbours and, when given, ``bound``: any further integer vectors, e.g. the candidates under
    test, which only set the radius)."""
    n = a.size
    q_inv = np.linalg.inv(q)
    simple = []
    for start in (np.round(a), _bootstrap(a, q)):
        simple += [start] + [start + s * np.eye(n)[i] for i in range(n) for s in (-1.0, 1.0)]
    if bound is not None:
        simple += list(bound)
    simple = np.unique(np.array(simple), axis=0)
    chi = np.sort(_norms(a, q_inv, simple))[1] * 1.001 + 1e-9  # margin for rounding
    r = np.linalg.cholesky(q_inv).T  # Q^-1 = R^T R, R upper triangular
    points = np.zeros((1, 0))         # z[k+1:] of every partial vector, last component last
    partial = np.zeros(1)             # its share of the norm
    for k in range(n - 1, -1, -1):
        tail = a[k + 1:] - points
        centre = a[k] + tail @ r[k, k + 1:] / r[k, k]
        half = np.sqrt(np.maximum(chi - partial, 0.0)) / r[k, k]
        low = np.ceil(centre - half)
        count = (np.floor(centre + half) - low + 1).astype(int).clip(min=0)
        owner = np.repeat(np.arange(points.shape[0]), count)
        offset = np.arange(owner.size) - np.repeat(np.cumsum(count) - count, count)
        value = low[owner] + offset
        partial = partial[owner] + (r[k, k] * (centre[owner] - value)) ** 2
        points = np.column_stack([value, points[owner]])
        assert points.shape[0] < 5_000_000, "ellipsoid too large for exhaustive listing"
    norms = _norms(a, q_inv, points)
    order = np.argsort(norms)[:2]
    return points[order], norms[order]


def _max_correlation(q: np.ndarray) -> float:
    sigma = np.sqrt(np.diag(q))
    corr = np.abs(q / np.outer(sigma, sigma))
    return float(np.max(corr[np.triu_indices(q.shape[0], 1)]))


def _problem(rng: np.random.Generator, n: int, ill: bool) -> tuple[np.ndarray, np.ndarray]:
    """A random float-ambiguity problem: well-conditioned (eigenvalues within a factor of 10),
    or ill-conditioned (eigenvalues spread over 4-6 decades, as in double-differenced
    ambiguities of a short observation span), variances at most 1 cycle^2."""
    spread = rng.uniform(4.0, 6.0) if ill else 1.0
    eig = 10.0 ** np.concatenate([[0.0, -spread], rng.uniform(-spread, 0.0, n)])[:n]
    basis = ortho_group.rvs(n, random_state=rng) if n > 1 else np.ones((1, 1))
    q = basis @ np.diag(eig) @ basis.T
    q *= rng.uniform(0.05, 1.0) / np.max(np.diag(q))
    q = 0.5 * (q + q.T)
    a = rng.integers(-1000, 1000, n) + rng.multivariate_normal(np.zeros(n), q)
    return a, q


@pytest.mark.parametrize("ill", [False, True], ids=["well-conditioned", "ill-conditioned"])
def test_lambda_finds_the_exhaustive_search_solutions(ill):
    rng = np.random.default_rng(20051 + int(ill))
    conditions = []
    for trial in range(500):
        n = 1 + trial % 6
        a, q = _problem(rng, n, ill)
        if n > 1:
            conditions.append(np.linalg.cond(q))
        best, norms = ils(a, q, candidates=2)
        ref, ref_norms = _exhaustive(a, q, bound=best)
        np.testing.assert_array_equal(best[0], ref[0], err_msg=f"trial {trial}, n={n}")
        np.testing.assert_allclose(norms, ref_norms, rtol=1e-8, atol=1e-10)
        if not np.isclose(ref_norms[0], ref_norms[1]):  # ties may come in either order
            np.testing.assert_array_equal(best[1], ref[1])
    if ill:
        assert np.min(conditions) > 1e4
    else:
        assert np.max(conditions) < 11.0


def test_decorrelation_is_unimodular_and_exact():
    rng = np.random.default_rng(7)
    for n in range(2, 9):
        _, q = _problem(rng, n, ill=True)
        z, low, d = decorrelate(q)
        assert np.all(z == np.round(z))
        assert abs(abs(np.linalg.det(z)) - 1.0) < 1e-9
        np.testing.assert_allclose(z.T @ q @ z, low.T @ np.diag(d) @ low, rtol=1e-9,
                                   atol=1e-12 * np.max(np.abs(q)))
        np.testing.assert_allclose(np.diag(low), 1.0)
        assert np.allclose(np.triu(low, 1), 0.0)
        # decorrelation: the transformed correlations are no larger than the original ones
        qz = z.T @ q @ z
        assert _max_correlation(qz) <= _max_correlation(q) + 1e-12


def test_published_example_of_de_jonge_and_tiberius():
    """LGR series no. 12 (de Jonge & Tiberius 1996), the three-dimensional example: float
    ambiguities (5.45, 3.10, 2.97) with the printed covariance; the integer least-squares
    solution is (5, 3, 4). The reduction leaves the determinant (the volume of the search
    ellipsoid) unchanged and makes the conditional variances far less spread (their printed
    decorrelated covariance has diagonal 4.476, 1.146, 0.626)."""
    q = np.array([[6.290, 5.978, 0.544], [5.978, 6.292, 2.340], [0.544, 2.340, 6.288]])
    a = np.array([5.45, 3.10, 2.97])
    best, norms = ils(a, q)
    np.testing.assert_array_equal(best[0], [5.0, 3.0, 4.0])
    np.testing.assert_array_equal(_exhaustive(a, q)[0][0], [5.0, 3.0, 4.0])
    z, low, d = decorrelate(q)
    qz = z.T @ q @ z
    np.testing.assert_allclose(np.linalg.det(qz), np.linalg.det(q), rtol=1e-9)
    np.testing.assert_allclose(np.sort(np.diag(qz)), [0.626, 1.146, 4.476], atol=2e-3)


def test_ratio_and_success_rate():
    assert ratio(np.array([0.5, 2.0])) == pytest.approx(4.0)
    # one ambiguity with sigma 0.1 cycle: P(|e| < 0.5) = erf(0.5 / (0.1 sqrt 2)) = 0.9999994
    assert bootstrap_success_rate(np.array([0.01])) == pytest.approx(0.99999943, abs=1e-8)
    assert bootstrap_success_rate(np.array([0.01, 0.25])) == pytest.approx(
        0.99999943 * 0.68268949, rel=1e-7)


def test_resolve_fixes_precise_problems_and_refuses_vague_ones():
    rng = np.random.default_rng(3)
    n = 8
    basis = ortho_group.rvs(n, random_state=rng)
    z_true = rng.integers(-50, 50, n).astype(float)
    q_precise = basis @ np.diag(10.0 ** rng.uniform(-4, -2.5, n)) @ basis.T
    a = z_true + rng.multivariate_normal(np.zeros(n), q_precise)
    res = resolve(a, q_precise)
    assert res.fixed and res.n_fixed == n
    np.testing.assert_array_equal(res.a_fixed, z_true)
    assert res.ratio >= 3.0 and res.success_rate >= 0.999

    q_vague = basis @ np.diag(np.full(n, 4.0)) @ basis.T
    res = resolve(z_true + 0.5, q_vague)
    assert not res.fixed and res.n_fixed == 0
    np.testing.assert_array_equal(res.a_fixed, z_true + 0.5)


def test_partial_fixing_fixes_the_precise_subset_and_conditions_the_rest():
    """Four precise ambiguities and four vague ones, uncorrelated: partial resolution fixes the
    precise four to their integers and leaves the vague ones at their float values."""
    rng = np.random.default_rng(11)
    z_true = rng.integers(-20, 20, 8).astype(float)
    var = np.array([1e-4] * 4 + [9.0] * 4)
    q = np.diag(var)
    a = z_true + rng.normal(0.0, np.sqrt(var))
    res = resolve(a, q, min_fixed=4)
    assert res.fixed and res.n_fixed == 4
    precise = var < 1.0
    np.testing.assert_allclose(res.a_fixed[precise], z_true[precise], atol=1e-9)
    np.testing.assert_allclose(res.a_fixed[~precise], a[~precise], atol=1e-9)
    np.testing.assert_allclose(np.diag(res.q_fixed)[precise], 0.0, atol=1e-12)
    np.testing.assert_allclose(np.diag(res.q_fixed)[~precise], 9.0)


@pytest.mark.parametrize(("sigma", "threshold"), [(0.2, 3.0), (0.3, 1.5), (0.4, 3.0)])
def test_ratio_failure_rate_of_one_ambiguity_is_the_analytic_one(sigma, threshold):
    """One ambiguity of 1-sigma s: the float a = e ~ N(0, s^2) rounds to k with residual
    r = a - k, the second best is 1 - |r| away, so the test passes a wrong k when
    |a - k| <= c = 1 / (1 + sqrt(threshold)): the failure rate is
    sum over k != 0 of Phi((k + c) / s) - Phi((k - c) / s). The Monte Carlo estimate within
    four of its binomial sigmas."""
    c = 1.0 / (1.0 + np.sqrt(threshold))
    k = np.arange(1, 20)
    exact = 2.0 * np.sum(norm.cdf((k + c) / sigma) - norm.cdf((k - c) / sigma))
    _, low, d = decorrelate(np.array([[sigma**2]]))
    samples = 20_000
    estimate = ratio_failure_rate(low, d, threshold, samples)
    assert abs(estimate - exact) <= 4.0 * np.sqrt(exact * (1.0 - exact) / samples)


def test_ratio_failure_rate_against_a_monte_carlo_of_lambda():
    """A correlated 4-D problem: the kernel's failure rate against an independent Monte Carlo
    of ``ils`` (itself checked against exhaustive search above) with its own draws, within
    four binomial sigmas of their difference."""
    rng = np.random.default_rng(5)
    basis = ortho_group.rvs(4, random_state=rng)
    q = basis @ np.diag([0.02, 0.05, 0.1, 0.3]) @ basis.T
    _, low, d = decorrelate(q)
    samples = 4000
    kernel = ratio_failure_rate(low, d, 2.0, samples)
    root = np.linalg.cholesky(q)
    failures = 0
    for _ in range(samples):
        z, norms = ils(root @ rng.standard_normal(4), q, 2)
        failures += bool(np.any(z[0] != 0.0) and ratio(norms) >= 2.0)
    python = failures / samples
    p = 0.5 * (kernel + python)
    assert p > 0.005  # a problem weak enough for failures to be counted
    assert abs(kernel - python) <= 4.0 * np.sqrt(2.0 * p * (1.0 - p) / samples)


def test_resolve_accepts_by_the_ratio_tests_failure_rate():
    """Six uncorrelated ambiguities: at 1-sigma 0.14 cycle the bootstrapped success rate is
    0.9975 (short of 0.999) but the ratio test at 3 fails in under 0.1 % of the draws, so the
    fixed failure-rate test fixes them; at 0.2 cycle (failure rate near 0.2 %) it does not."""
    z_true = np.arange(6.0)
    q_strong = np.diag(np.full(6, 0.02))
    _, _, d = decorrelate(q_strong)
    assert bootstrap_success_rate(d) < 0.999
    assert not resolve(z_true + 0.02, q_strong).fixed
    res = resolve(z_true + 0.02, q_strong, failure_samples=2000)
    assert res.fixed and res.n_fixed == 6
    np.testing.assert_array_equal(res.a_fixed, z_true)
    q_weak = np.diag(np.full(6, 0.04))
    _, low, d = decorrelate(q_weak)
    assert ratio_failure_rate(low, d, 3.0, 2000) > 0.001
    assert not resolve(z_true + 0.02, q_weak, failure_samples=2000).fixed
