"""Sigma points and the unscented transform, in the two forms the seed papers use.

* Symmetric set of 2n + 1 points (Chan et al., "Robust Navigation System for a Land Vehicle",
  UKF steps 1-3; Wan & van der Merwe 2000): lambda = alpha^2 (n + kappa) - n,
  gamma = sqrt(n + lambda), X_0 = x, X_i = x +/- gamma (sqrt P)_i, weights
  W_m0 = lambda / (n + lambda), W_c0 = W_m0 + 1 - alpha^2 + beta,
  W_i = 1 / (2 (n + lambda)). (Chan et al. print W_i = lambda / (2 (n + lambda)); that does not
  sum to one and is a misprint of the standard weight used here.) Chan uses alpha = 0.99,
  beta = 2.
* Scaled spherical-simplex set of n + 2 points (Cho & Choi 2006, eqs. 21-23; Julier 2003):
  w_i = (1 - w0) / (n + 1), W_m0 = (w0 - 1) / alpha^2 + 1, W_c0 = (w0 - 1) / alpha^2 + 2 + beta
  - alpha^2, W_i = w_i / alpha^2; unit points built column by column (eq. 22b-c) and mapped by
  X_j = x + alpha S^T Z_j with S^T S = P (eqs. 22d, 23).
* ``unscented_transform``: mean, covariance and cross-covariance of y = f(x) from the points
  (Cho & Choi eqs. 25-26 and 30-31; Chan eqs. 9-10).

Public functions
----------------
symmetric_points, simplex_points, unscented_transform.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def _sqrt_cov(p: np.ndarray) -> np.ndarray:
    """Lower Cholesky factor L, L L^T = P (so S = L^T in Cho & Choi eq. 23)."""
    return np.linalg.cholesky(np.asarray(p, dtype=float))


def symmetric_points(x: np.ndarray, p: np.ndarray, alpha: float = 0.99, beta: float = 2.0,
                     kappa: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The symmetric 2n + 1 sigma points of N(x, P) and their weights.

    Parameters
    ----------
    x : (n,) mean; p : (n, n) covariance.
    alpha, beta, kappa : float
        Spread, prior-distribution and secondary scaling parameters (Chan et al.).

    Returns
    -------
    points : (2n + 1, n); wm : (2n + 1,) mean weights; wc : (2n + 1,) covariance weights.
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    lam = alpha**2 * (n + kappa) - n
    if n + lam <= 0:
        raise ValueError(f"alpha^2 (n + kappa) must be positive (n = {n}, kappa = {kappa})")
    offsets = np.sqrt(n + lam) * _sqrt_cov(p).T
    points = np.vstack([x, x + offsets, x - offsets])
    wm = np.full(2 * n + 1, 0.5 / (n + lam))
    wm[0] = lam / (n + lam)
    wc = wm.copy()
    wc[0] += 1.0 - alpha**2 + beta
    return points, wm, wc


def simplex_points(x: np.ndarray, p: np.ndarray, alpha: float = 1.0, beta: float = 2.0,
                   w0: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The scaled spherical-simplex n + 2 sigma points of N(x, P) and their weights.

    Parameters
    ----------
    x : (n,) mean; p : (n, n) covariance.
    alpha : float
        Scaling, 1e-4 <= alpha <= 1 (Cho & Choi eq. 21).
    beta : float
        Prior-distribution parameter (2 for a Gaussian).
    w0 : float
        Weight of the central point before scaling, 0 <= w0 < 1.

    Returns
    -------
    points : (n + 2, n); wm : (n + 2,) mean weights; wc : (n + 2,) covariance weights.
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    if not 0.0 <= w0 < 1.0:
        raise ValueError(f"w0 must be in [0, 1), got {w0}")
    w = (1.0 - w0) / (n + 1)
    unit = np.zeros((n, n + 2))  # column j is the unit point j (eq. 22a)
    for i in range(1, n + 1):
        scale = 1.0 / np.sqrt(i * (i + 1) * w)
        unit[i - 1, 1:i + 1] = -scale  # eq. 22b
        unit[i - 1, i + 1] = i * scale  # eq. 22c
    points = x + alpha * (_sqrt_cov(p) @ unit).T  # eq. 22d
    wm = np.full(n + 2, w / alpha**2)
    wc = wm.copy()
    wm[0] = (w0 - 1.0) / alpha**2 + 1.0
    wc[0] = (w0 - 1.0) / alpha**2 + 2.0 + beta - alpha**2
    return points, wm, wc


def unscented_transform(f: Callable[[np.ndarray], np.ndarray], points: np.ndarray,
                        wm: np.ndarray, wc: np.ndarray, noise_cov: np.ndarray | None = None
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Propagate sigma points through ``f``.

    Parameters
    ----------
    f : callable
        Maps one point, shape (n,), to shape (m,).
    points : (k, n) sigma points; wm, wc : (k,) their weights.
    noise_cov : (m, m), optional
        Additive noise covariance added to the output covariance (R or Q).

    Returns
    -------
    mean : (m,); cov : (m, m); cross : (n, m) cross-covariance of x and y;
    y_points : (k, m) the transformed points.
    """
    y = np.array([np.atleast_1d(f(pt)) for pt in points], dtype=float)
    mean = wm @ y
    x_mean = wm @ points
    dy = y - mean
    cov = (wc[:, None] * dy).T @ dy
    cross = (wc[:, None] * (points - x_mean)).T @ dy
    if noise_cov is not None:
        cov = cov + noise_cov
    return mean, 0.5 * (cov + cov.T), cross, y
