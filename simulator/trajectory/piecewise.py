"""Piecewise polynomials: the representation of every road profile (light, fast, and
interchangeable with ``scipy.interpolate.PPoly``, whose ``c``/``x`` layout it shares).

Public names
------------
PiecewisePolynomial.
"""

from __future__ import annotations

import numpy as np


class PiecewisePolynomial:
    """p(x) = sum_k c[k, i] (x - x[i])^(K-1-k) on [x[i], x[i+1]); extrapolates the end pieces.

    Parameters
    ----------
    c : array, shape (K, m)
        Coefficients, highest power first (the ``scipy.interpolate.PPoly`` convention).
    x : array, shape (m + 1,)
        Increasing breakpoints.
    """

    def __init__(self, c: np.ndarray, x: np.ndarray):
        self.c = np.asarray(c, dtype=float)
        self.x = np.asarray(x, dtype=float)

    @classmethod
    def from_ppoly(cls, ppoly) -> PiecewisePolynomial:
        """Wrap a ``scipy.interpolate.PPoly`` (or anything with ``c`` and ``x``)."""
        return cls(ppoly.c, ppoly.x)

    def piece_index(self, x: np.ndarray) -> np.ndarray:
        """Index of the piece holding each x (pieces are [x[i], x[i+1]); ends extrapolate).

        For many increasing x (a time grid, the distance along it) the pieces' starts are
        looked up in x instead (one search per piece rather than one per x), with the same
        result.
        """
        x = np.asarray(x, dtype=float)
        m = self.c.shape[1]
        if x.ndim == 1 and len(x) > 8 * m and (x[1:] >= x[:-1]).all():
            first = np.searchsorted(x, self.x[1:m], side="left")  # first x in pieces 1 ... m-1
            return np.repeat(np.arange(m), np.diff(first, prepend=0, append=len(x)))
        return np.clip(np.searchsorted(self.x, x, side="right") - 1, 0, m - 1)

    def evaluate(self, x: np.ndarray, orders: tuple[int, ...] = (0,),
                 index: np.ndarray | None = None) -> list[np.ndarray]:
        """Values of the requested derivatives at x (one search for all of them; ``index``
        from ``piece_index`` skips it, for curves that share these breakpoints).

        Horner's scheme in place, the coefficients of each sample's piece gathered with
        ``take`` (much cheaper than fancy indexing of the 2-D coefficient array).
        """
        x = np.asarray(x, dtype=float)
        idx = self.piece_index(x) if index is None else index
        dx = x - self.x.take(idx)
        out = []
        for nu in orders:
            c = self._coefficients(nu)
            acc = c[0].take(idx)
            for row in c[1:]:
                acc *= dx
                acc += row.take(idx)
            out.append(acc)
        return out

    def _coefficients(self, nu: int) -> np.ndarray:
        """Coefficients of the nu-th derivative, computed once."""
        cache = self.__dict__.setdefault("_derivatives", {0: self.c})
        if nu not in cache:
            cache[nu] = self.derivative(nu).c
        return cache[nu]

    def __call__(self, x: np.ndarray, nu: int = 0) -> np.ndarray:
        return self.evaluate(x, (nu,))[0]

    def derivative(self, nu: int = 1) -> PiecewisePolynomial:
        c = self.c
        for _ in range(nu):
            k = c.shape[0] - 1
            if k == 0:
                return PiecewisePolynomial(np.zeros((1, c.shape[1])), self.x)
            c = c[:-1] * np.arange(k, 0, -1)[:, None]
        return PiecewisePolynomial(c, self.x)

    def antiderivative(self) -> PiecewisePolynomial:
        """The continuous antiderivative that is zero at x[0]."""
        k = self.c.shape[0]
        c = np.zeros((k + 1, self.c.shape[1]))
        c[:-1] = self.c / np.arange(k, 0, -1)[:, None]
        widths = np.diff(self.x)
        ends = np.zeros(self.c.shape[1])
        for j in range(k):  # value of each piece's integral at its right end
            ends = ends * widths + c[j]
        ends *= widths
        c[-1] = np.concatenate([[0.0], np.cumsum(ends)[:-1]])
        return PiecewisePolynomial(c, self.x)
