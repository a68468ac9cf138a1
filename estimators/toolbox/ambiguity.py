"""Integer ambiguity resolution: the LAMBDA method, its validation and partial fixing.

Given float ambiguities ``a`` (cycles) with covariance ``Q``, the integer least-squares (ILS)
problem is ``min_z (a - z)^T Q^-1 (a - z)`` over integer vectors z. The LAMBDA method (Teunissen
1995; de Jonge & Tiberius 1996, LGR series no. 12) solves it in two steps, written here after the
modified form MLAMBDA of Chang, Yang & Zhou (J. Geodesy 79, 552-565, 2005):

* **Reduction** (``decorrelate``): ``Q = L^T D L`` (L unit lower triangular, D diagonal,
  factorised from the last row up; Chang et al. eq. 3), then integer Gauss transformations
  (their section 3.1, eq. 9) and symmetric permutations (eqs. 11-14, applied when
  ``D[j] + L[j+1, j]^2 D[j+1] < D[j+1]``) give a unimodular Z with ``Z^T Q Z = L'^T D' L'``,
  nearly diagonal and with the conditional variances in ``D'`` as close to decreasing order as
  the reduction allows: the transformed ambiguities are decorrelated.
* **Search** (``search``): a depth-first enumeration of the integer lattice in the decorrelated
  space from the last (most precise) component to the first, visiting each level's integers in
  the Schnorr-Euchner zig-zag order about its conditional estimate and shrinking the search
  ellipsoid as candidates are found (Chang et al. section 4, Algorithm SEARCH), so the ``m``
  best candidates are exact ILS solutions.

Validation and partial fixing: ``ratio`` is the ratio test (second-best squared norm over best,
accepted at or above a threshold such as 3; Euler & Schaffrin 1991, as used by RTKLIB),
``bootstrap_success_rate`` the integer bootstrapping success rate of the decorrelated problem,
a sharp lower bound of the ILS success rate (Teunissen 1998, J. Geodesy 72, eq. 14:
``prod_i (2 Phi(1 / (2 sqrt(D_i))) - 1)``), and ``resolve`` fixes the largest subset of
decorrelated ambiguities whose bootstrapped success rate reaches a threshold and whose ratio
test passes (partial ambiguity resolution, Teunissen, Joosten & Tiberius 1999, ION GPS).

Public names
------------
decorrelate, search, ils, ratio, bootstrap_success_rate, ratio_failure_rate, resolve, Resolution.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.special import erf


@njit(cache=True)
def _ltdl_kernel(q: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool]:
    """``Q = L^T diag(d) L`` (``_ltdl``); the flag is False when Q is not positive definite."""
    a = q.copy()
    n = a.shape[0]
    low = np.zeros((n, n))
    d = np.zeros(n)
    for i in range(n - 1, -1, -1):
        d[i] = a[i, i]
        if not d[i] > 0.0:
            return low, d, False
        root = np.sqrt(d[i])
        row = a[i, : i + 1] / root
        for r in range(i):
            for c in range(i):
                a[r, c] -= row[r] * row[c]
        for c in range(i + 1):
            low[i, c] = row[c] / row[i]
    return low, d, True


def _ltdl(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``Q = L^T diag(d) L`` with L unit lower triangular, factorised from the last row up
    (Chang et al. 2005, eq. 3; de Jonge & Tiberius 1996, section 3.3)."""
    low, d, positive = _ltdl_kernel(np.ascontiguousarray(q, dtype=float))
    if not positive:
        raise np.linalg.LinAlgError("ambiguity covariance is not positive definite")
    return low, d


@njit(cache=True)
def _reduce(low: np.ndarray, d: np.ndarray) -> np.ndarray:
    """The integer Gauss transformations and permutations of ``decorrelate`` on its factors
    (updated in place); returns Z."""
    n = d.size
    z = np.eye(n)
    j = n - 2
    k = n - 2
    while j >= 0:
        if j <= k:
            for i in range(j + 1, n):
                mu = np.rint(low[i, j])
                if mu != 0.0:  # integer Gauss transformation, Chang et al. eq. 9
                    for r in range(i, n):
                        low[r, j] -= mu * low[r, i]
                    for r in range(n):
                        z[r, j] -= mu * z[r, i]
        delta = d[j] + low[j + 1, j] ** 2 * d[j + 1]
        if delta + 1e-6 < d[j + 1]:  # permutation of j and j+1, Chang et al. eqs. 11-14
            eta = d[j] / delta
            lam = d[j + 1] * low[j + 1, j] / delta
            d[j] = eta * d[j + 1]
            d[j + 1] = delta
            for c in range(j):
                upper = low[j, c]
                lower = low[j + 1, c]
                low[j, c] = -low[j + 1, j] * upper + lower
                low[j + 1, c] = eta * upper + lam * lower
            low[j + 1, j] = lam
            for r in range(j + 2, n):
                low[r, j], low[r, j + 1] = low[r, j + 1], low[r, j]
            for r in range(n):
                z[r, j], z[r, j + 1] = z[r, j + 1], z[r, j]
            k = j
            j = n - 2
        else:
            j -= 1
    return z


def decorrelate(q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The LAMBDA reduction of an ambiguity covariance.

    Parameters
    ----------
    q : (n, n) symmetric positive-definite covariance of the float ambiguities (cycles^2).

    Returns
    -------
    z : (n, n) integer unimodular matrix; the decorrelated ambiguities are ``z.T @ a``.
    low : (n, n) unit lower-triangular factor and d : (n,) conditional variances of the
        decorrelated covariance, ``z.T @ q @ z = low.T @ diag(d) @ low``.
    """
    low, d = _ltdl(q)
    z = _reduce(low, d)
    return z, low, d


@njit(cache=True)
def _search_kernel(z_float: np.ndarray, low: np.ndarray, d: np.ndarray,
                   candidates: int) -> tuple[np.ndarray, np.ndarray]:
    """``search`` (Chang et al. 2005, Algorithm SEARCH), unsorted."""
    n = d.size
    best = np.full((candidates, n), np.nan)
    norms = np.full(candidates, np.inf)
    found = 0
    worst = 0
    max_dist = np.inf
    cond = np.zeros(n)      # conditional estimates zb_k
    z = np.zeros(n)
    step = np.zeros(n)
    dist = np.zeros(n)
    s = np.zeros((n, n))    # s[k, :k+1]: accumulated corrections of levels above k
    k = n - 1
    cond[k] = z_float[k]
    z[k] = np.rint(cond[k])
    y = cond[k] - z[k]
    step[k] = 1.0 if y > 0.0 else -1.0
    while True:
        new_dist = dist[k] + y * y / d[k]
        if new_dist < max_dist:
            if k != 0:
                k -= 1
                dist[k] = new_dist
                for c in range(k + 1):
                    s[k, c] = s[k + 1, c] + (z[k + 1] - cond[k + 1]) * low[k + 1, c]
                cond[k] = z_float[k] + s[k, k]
                z[k] = np.rint(cond[k])
                y = cond[k] - z[k]
                step[k] = 1.0 if y > 0.0 else -1.0
            else:
                if found < candidates:
                    if found == 0 or new_dist > norms[worst]:
                        worst = found
                    best[found] = z
                    norms[found] = new_dist
                    found += 1
                    if found == candidates:
                        max_dist = norms[worst]
                else:
                    best[worst] = z
                    norms[worst] = new_dist
                    worst = np.argmax(norms)
                    max_dist = norms[worst]
                z[0] += step[0]
                y = cond[0] - z[0]
                step[0] = -step[0] - np.sign(step[0])
        else:
            if k == n - 1:
                break
            k += 1
            z[k] += step[k]
            y = cond[k] - z[k]
            step[k] = -step[k] - np.sign(step[k])
    return best, norms


def search(z_float: np.ndarray, low: np.ndarray, d: np.ndarray,
           candidates: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """The ``candidates`` integer vectors nearest to ``z_float`` in the metric
    ``(z_float - z)^T (low^T diag(d) low)^-1 (z_float - z)`` (Chang et al. 2005, Algorithm SEARCH).

    Returns
    -------
    z_int : (candidates, n) integer vectors, best first; norms : (candidates,) their squared
        distances, increasing. With fewer lattice points than asked (impossible in practice),
        the missing rows are NaN.
    """
    best, norms = _search_kernel(np.ascontiguousarray(z_float, dtype=float),
                                 np.ascontiguousarray(low, dtype=float),
                                 np.ascontiguousarray(d, dtype=float), int(candidates))
    order = np.argsort(norms)
    return best[order], norms[order]


def ils(a_float: np.ndarray, q: np.ndarray,
        candidates: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """Integer least-squares solutions of float ambiguities by LAMBDA.

    Parameters
    ----------
    a_float : (n,) float ambiguities (cycles); q : (n, n) their covariance (cycles^2).
    candidates : how many of the best integer vectors to return (2 for the ratio test).

    Returns
    -------
    a_int : (candidates, n) integer vectors (as floats), best first; norms : (candidates,) their
        squared distances ``(a - a_int)^T Q^-1 (a - a_int)``, increasing.
    """
    a_float = np.asarray(a_float, dtype=float)
    z, low, d = decorrelate(q)
    shift = np.floor(a_float)  # search on the fractional part, add the integers back after
    z_float = z.T @ (a_float - shift)
    z_int, norms = search(z_float, low, d, candidates)
    a_int = np.linalg.solve(z.T, z_int.T).T
    return np.round(a_int) + shift, norms


@njit(cache=True)
def _ratio_failures_kernel(samples: np.ndarray, low: np.ndarray, d: np.ndarray,
                           threshold: float) -> int:
    """How many of the float vectors ``samples`` (rows, errors about the true integers 0)
    pass the ratio test at ``threshold`` with a best integer vector other than 0."""
    failures = 0
    for k in range(samples.shape[0]):
        best, norms = _search_kernel(samples[k], low, d, 2)
        first = 0 if norms[0] <= norms[1] else 1
        wrong = False
        for i in range(best.shape[1]):
            if best[first, i] != 0.0:
                wrong = True
                break
        if wrong and norms[1 - first] >= threshold * norms[first]:
            failures += 1
    return failures


def ratio_failure_rate(low: np.ndarray, d: np.ndarray, threshold: float,
                       samples: int = 2000) -> float:
    """The failure rate of ILS with the ratio test at ``threshold``: the probability that the
    test accepts an integer vector other than the true one, for the decorrelated problem
    ``low``, ``d`` (``decorrelate``), by Monte Carlo (``samples`` float vectors drawn from
    N(0, low^T diag(d) low), a fixed generator: the same problem gives the same rate). The
    fixed failure-rate ratio test accepts a fix when this is below a chosen rate (Teunissen &
    Verhagen 2009, J. Geodesy 83; Verhagen & Teunissen 2013, J. Geodesy 87, section 3)."""
    rng = np.random.default_rng(0)
    draws = rng.standard_normal((int(samples), d.size)) * np.sqrt(d)  # in the L^T-space
    floats = draws @ low  # each row x = L^T u, covariance L^T diag(d) L
    failures = _ratio_failures_kernel(np.ascontiguousarray(floats),
                                      np.ascontiguousarray(low, dtype=float),
                                      np.ascontiguousarray(d, dtype=float), float(threshold))
    return failures / float(samples)


def ratio(norms: np.ndarray) -> float:
    """The ratio test statistic: second-best over best squared norm (inf if the best is 0)."""
    if norms[0] <= 0.0:
        return float("inf")
    return float(norms[1] / norms[0])


def bootstrap_success_rate(d: np.ndarray) -> float:
    """Integer bootstrapping success rate from the conditional variances of a decorrelated
    problem (Teunissen 1998, eq. 14); a lower bound of the ILS success rate."""
    return float(np.prod(_bootstrap_factors(d)))


def _bootstrap_factors(d: np.ndarray) -> np.ndarray:
    """Each conditional variance's factor of ``bootstrap_success_rate``."""
    return erf(1.0 / (2.0 * np.sqrt(2.0 * np.asarray(d, dtype=float))))


@dataclass(frozen=True)
class Resolution:
    """Outcome of ``resolve``.

    ``fixed``: whether any ambiguity was fixed; ``a_fixed``: (n,) the float ambiguities
    conditioned on the fixed subset (integers where the subset fixes all, the full vector in
    any case; equal to the float input when nothing is fixed); ``q_fixed``: (n, n) its
    covariance; ``n_fixed``: how many decorrelated ambiguities were fixed; ``ratio``: the ratio
    test statistic of the accepted subset (or of the full set when nothing is fixed);
    ``success_rate``: the bootstrapped success rate of the accepted subset.
    """

    fixed: bool
    a_fixed: np.ndarray
    q_fixed: np.ndarray
    n_fixed: int
    ratio: float
    success_rate: float


def resolve(a_float: np.ndarray, q: np.ndarray, ratio_threshold: float = 3.0,
            min_success_rate: float = 0.999, min_fixed: int = 4,
            failure_samples: int = 0) -> Resolution:
    """Full, then partial, ambiguity resolution with validation.

    The decorrelated ambiguities are fixed from the most precise (last) one upward: the largest
    subset ``z[p:]`` whose bootstrapped success rate reaches ``min_success_rate`` is searched
    (ILS on that subset, conditioned on nothing else), and accepted when its ratio test reaches
    ``ratio_threshold``; if not, the subset shrinks by one until fewer than ``min_fixed``
    remain. With ``failure_samples`` > 0 the bootstrapped rate is the sufficient condition, not
    the necessary one: the largest subset whose ratio test passes though its bootstrapped rate
    falls short is accepted when the test's failure rate at ``ratio_threshold``
    (``ratio_failure_rate`` with that many samples) is at most 1 - ``min_success_rate`` (the
    fixed failure-rate ratio test; one such Monte Carlo per call, the largest subset's). The
    accepted integers ``z_s`` constrain the whole vector by the conditional
    (least-squares) update ``a = a_float - Q_{a z_s} Q_{z_s}^-1 (z_s_float - z_s)``, ``Q_a|z =
    Q - Q_{a z_s} Q_{z_s}^-1 Q_{z_s a}`` (Teunissen 1995, eq. 9 of the fixed solution).
    """
    a_float = np.asarray(a_float, dtype=float)
    q = np.asarray(q, dtype=float)
    n = a_float.size
    z, low, d = decorrelate(q)
    shift = np.floor(a_float)
    z_float_all = z.T @ (a_float - shift)
    q_z = z.T @ q @ z
    last_ratio = 0.0
    factors = _bootstrap_factors(d)
    monte_carlo = failure_samples > 0
    for start in range(n - min_fixed + 1 if n >= min_fixed else 0):
        sub = slice(start, n)
        rate = float(np.prod(factors[sub]))
        if rate < min_success_rate and not monte_carlo:
            continue
        low_s, d_s = _ltdl(q_z[sub, sub])
        z_int, norms = search(z_float_all[sub], low_s, d_s, 2)
        last_ratio = ratio(norms)
        if last_ratio < ratio_threshold:
            continue
        if rate < min_success_rate:
            monte_carlo = False  # this subset's test is the one Monte Carlo of the call
            failure = ratio_failure_rate(low_s, d_s, ratio_threshold, failure_samples)
            if failure > 1.0 - min_success_rate:
                continue
        z_sel = z[:, sub]  # a -> z_s = z_sel^T a
        cross = q @ z_sel
        gain = np.linalg.solve(q_z[sub, sub], cross.T).T
        a_fixed = a_float - gain @ (z_float_all[sub] - z_int[0])
        q_fixed = q - gain @ cross.T
        if start == 0:
            a_fixed = np.round(a_fixed)
            q_fixed = np.zeros_like(q)
        return Resolution(True, a_fixed, 0.5 * (q_fixed + q_fixed.T), n - start, last_ratio,
                          rate)
    return Resolution(False, a_float.copy(), q.copy(), 0, last_ratio, float(np.prod(factors)))
