"""Integrals of uniformly sampled smooth functions over each sample interval, from the samples
alone: the cubic (four-point) rule, and the estimate of its error that decides where an exact
quadrature of the analytic function must take over.

For the interval [t_k, t_k+1] of a uniform grid with step h, the cubic through the samples
k-1 ... k+2 integrates to h/24 (-f_k-1 + 13 f_k + 13 f_k+1 - f_k+2), exact for cubics, with the
error -(11/720) h^5 f'''' (Abramowitz & Stegun 25.4.6 family; the end intervals use the one-sided
cubics h/24 (9 f_0 + 19 f_1 - 5 f_2 + f_3) and its mirror image).

Three-point Gauss-Legendre (exact for polynomials up to degree 5) integrates the analytic
kinematics where the samples cannot: ``GL_NODES`` and ``GL_WEIGHTS`` on [0, 1]. Four-point
Gauss-Lobatto (Abramowitz & Stegun 25.4.32: nodes 0, (5 -+ sqrt 5) / 10, 1, weights 1/12,
5/12, 5/12, 1/12) is exact for the same degree, with an error term of the same order,
h^7 f^(6) / 1 512 000 against Gauss-Legendre's h^7 f^(6) / 2 016 000, and takes two of its
nodes at the interval's ends: on a grid whose samples are known it needs two new evaluations
per interval instead of three (``LOBATTO_INNER_NODES``, ``LOBATTO_INNER_WEIGHTS``,
``LOBATTO_END_WEIGHT``).

Public names
------------
cubic_interval_integrals, cubic_rule_error, GL_NODES, GL_WEIGHTS, LOBATTO_INNER_NODES,
LOBATTO_INNER_WEIGHTS, LOBATTO_END_WEIGHT.
"""

from __future__ import annotations

import numpy as np

_GL_X, _GL_W = np.polynomial.legendre.leggauss(3)
GL_NODES = 0.5 * (_GL_X + 1.0)  # Gauss-Legendre nodes on [0, 1]
GL_WEIGHTS = 0.5 * _GL_W  # and their weights
# four-point Gauss-Lobatto on [0, 1]: the two inner nodes and their weights, and the weight of
# each end
LOBATTO_INNER_NODES = np.array([0.5 - np.sqrt(5.0) / 10, 0.5 + np.sqrt(5.0) / 10])
LOBATTO_INNER_WEIGHTS = np.array([5.0 / 12, 5.0 / 12])
LOBATTO_END_WEIGHT = 1.0 / 12


def cubic_interval_integrals(f: np.ndarray, h: float) -> np.ndarray:
    """Integrals of the samples ``f`` (shape (n, ...), n >= 4) over the n - 1 intervals."""
    f = np.asarray(f, dtype=float)
    out = np.empty((len(f) - 1,) + f.shape[1:])
    inner = out[1:-1]  # h/24 (13 (f_k + f_k+1) - f_k-1 - f_k+2), in place
    np.add(f[1:-2], f[2:-1], out=inner)
    inner *= 13.0
    inner -= f[:-3]
    inner -= f[3:]
    inner *= h / 24
    out[0] = h / 24 * (9 * f[0] + 19 * f[1] - 5 * f[2] + f[3])
    out[-1] = h / 24 * (f[-4] - 5 * f[-3] + 19 * f[-2] + 9 * f[-1])
    return out


def cubic_rule_error(f: np.ndarray, h: float) -> np.ndarray:
    """Estimated error of ``cubic_interval_integrals`` on each interval, shape (n - 1,):
    (11/720) h |d4| with d4 the largest fourth difference of the samples around the interval,
    over every component of f (shape (n, ...)); infinite where the grid does not give one."""
    f = np.asarray(f, dtype=float)
    columns = f.reshape(len(f), -1).T  # one contiguous row per component for F-ordered f
    d4 = np.full(len(f), np.inf)
    if len(f) >= 5:
        inner = np.abs(columns[:, :-4] - 4 * columns[:, 1:-3] + 6 * columns[:, 2:-2]
                       - 4 * columns[:, 3:-1] + columns[:, 4:])
        d4[2:-2] = inner.max(axis=0) if len(columns) > 1 else inner[0]
    return 11.0 / 720.0 * h * np.maximum(d4[:-1], d4[1:])
