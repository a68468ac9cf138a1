"""A generic sigma-point (unscented) Kalman filter driver, shared by every sigma-point estimator.

The filter carries a nominal state ``x`` (shape (n_x,)) and the covariance ``P`` (shape (n, n))
of an error ``dx`` around it, joined by two manifold hooks (Hertzberg et al., "Integrating
generic sensor fusion algorithms with sound state representations through encapsulation of
manifolds", Information Fusion 14, 2013, the boxplus / boxminus operators):

* ``boxplus(x, dx)``: the state displaced by the error(s) ``dx`` (shape (k, n)) -> (k, n_x);
* ``boxminus(X, x)``: the error(s) taking ``x`` to the states ``X`` (shape (k, n_x)) -> (k, n).

With the default hooks (plain addition and subtraction) n_x = n and this is the textbook UKF;
``angle_hooks`` wraps chosen components to (-pi, pi], and ``quaternion_hooks`` carries a
quaternion attitude as a three-parameter rotation error around the mean (composing rotations).

One filter cycle (Cho & Choi 2006, eqs. 19-32; Wan & van der Merwe 2000, Algorithm 3.1):

1. ``draw``: sigma points of N(0, P_a) (``estimators.toolbox.sigma_points``: the symmetric
   2L + 1 set of Chan et al., or the scaled simplex L + 2 set of Cho & Choi eqs. 21-23), mapped
   onto the state with ``boxplus``. With ``augment=True`` the process noise is part of the
   sigma-point state (Cho & Choi eqs. 19-20): L = n + r with P_a = diag(P, Lambda), where
   Q = U Lambda U^T keeps only the r eigen-directions of Q with non-zero variance, so the
   augmented covariance is not singular when Q has zero entries (Cho & Choi's eq. 34 has five).
   The noise of each point, W = w U^T (shape (k, n_q)), is handed to the transition function.
2. ``propagate(fx, ...)``: each point through the transition, vectorised over the point set:
   ``fx(X, W, *args) -> X'`` with X of shape (k, n_x) and W of shape (k, n_q), or None without
   augmentation. May be called several times between draws: Cho & Choi propagate at 10 Hz and
   form the covariance only at the 1 Hz GPS epochs (text after eq. 25). Returns the mean
   (eq. 25), the weighted manifold mean of the points.
3. ``covariance(q)``: P from the spread of the points around the mean (eq. 26), plus an
   additive process-noise covariance ``q`` (n, n) when the noise is not augmented.
4. ``update(hx, z, r)``: the measurement points h(X) (shape (k, m)), their mean (eq. 27), the
   innovation covariance P_yy with R added (eq. 30), the cross-covariance P_xy (eq. 31, no R),
   K = P_xy P_yy^-1 (eq. 32), x <- x boxplus K (z - y) (eq. 28), P <- P - K P_yy K^T (eq. 29).
   ``z_residual`` wraps angular measurement residuals (a course, a heading).
   An update follows a ``covariance()``. With augmented noise it uses the propagated points,
   which carry the noise, as in Cho & Choi eqs. 27 and 30-31; with an additive Q the points do
   not carry it, so they are redrawn from (x, P) first (Wan & van der Merwe 2000; FilterPy's
   ``UnscentedKalmanFilter`` does the same). After the update the points are stale; the next
   ``propagate`` draws fresh ones.

Square root of P_a: Cholesky when it succeeds, otherwise the symmetric eigen-decomposition with
the eigenvalues clipped at ``1e-12`` times the largest (and at least 1e-300), which survives
singular and slightly indefinite covariances (Higham 1988, "Computing a nearest symmetric
positive semidefinite matrix"), so a P that lost definiteness in eq. 29's subtraction still
yields points.

Public names
------------
SigmaPointFilter, angle_hooks, quaternion_hooks, psd_sqrt.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from estimators.toolbox.sigma_points import simplex_points, symmetric_points
from simulator.earth import quat_multiply, quat_to_rotvec, rotvec_to_quat, wrap_angle

Boxplus = Callable[[np.ndarray, np.ndarray], np.ndarray]
Boxminus = Callable[[np.ndarray, np.ndarray], np.ndarray]

_CLIP_RELATIVE = 1e-12  # smallest eigenvalue kept, relative to the largest
_MEAN_ITERATIONS = 5  # manifold mean: Gauss-Newton steps at most (one when Euclidean)
_MEAN_TOLERANCE = 1e-12  # stop when the mean's correction is below this (state units)


def psd_sqrt(p: np.ndarray) -> np.ndarray:
    """A lower-triangular or eigen square root L of a symmetric P, L L^T = P (clipped).

    Parameters
    ----------
    p : (n, n) symmetric covariance, possibly singular or slightly indefinite.

    Returns
    -------
    (n, n) matrix L with L L^T = P when P is positive definite (the Cholesky factor); otherwise
    V diag(sqrt(max(lambda, eps))) with eps = 1e-12 max(lambda), the square root of the nearest
    positive-definite matrix in the Frobenius norm (Higham 1988) up to the clip.
    """
    p = 0.5 * (p + p.T)
    try:
        return np.linalg.cholesky(p)
    except np.linalg.LinAlgError:
        lam, vec = np.linalg.eigh(p)
        floor = max(_CLIP_RELATIVE * float(lam.max(initial=0.0)), 1e-300)
        return vec * np.sqrt(np.maximum(lam, floor))


def _euclid_plus(x: np.ndarray, dx: np.ndarray) -> np.ndarray:
    return x + dx


def _euclid_minus(xs: np.ndarray, x: np.ndarray) -> np.ndarray:
    return xs - x


def angle_hooks(angles: Sequence[int]) -> tuple[Boxplus, Boxminus]:
    """``boxplus`` / ``boxminus`` for a vector state whose components ``angles`` (indices) are
    angles in rad: sums are wrapped to (-pi, pi], differences are the shortest turn."""
    idx = np.asarray(angles, dtype=int)

    def plus(x: np.ndarray, dx: np.ndarray) -> np.ndarray:
        out = x + dx
        out[..., idx] = wrap_angle(out[..., idx])
        return out

    def minus(xs: np.ndarray, x: np.ndarray) -> np.ndarray:
        d = xs - x
        d[..., idx] = wrap_angle(d[..., idx])
        return d

    return plus, minus


def quaternion_hooks(start: int) -> tuple[Boxplus, Boxminus]:
    """``boxplus`` / ``boxminus`` for a state with a scalar-first unit quaternion in
    ``x[start:start + 4]``, carried as a rotation-vector error in ``dx[start:start + 3]``
    (the other components plain; the error has one component fewer than the state). The error
    is on the right, in the body frame: q = q_mean * exp(dtheta) (Hertzberg et al. 2013,
    section 3.6; so a quaternion never enters a covariance, whose rank it would lower)."""
    q_end, e_end = start + 4, start + 3

    def plus(x: np.ndarray, dx: np.ndarray) -> np.ndarray:
        x, dx = np.asarray(x, dtype=float), np.asarray(dx, dtype=float)
        out = np.empty((*dx.shape[:-1], x.shape[-1]))
        out[..., :start] = x[..., :start] + dx[..., :start]
        out[..., q_end:] = x[..., q_end:] + dx[..., e_end:]
        q = quat_multiply(x[..., start:q_end], rotvec_to_quat(dx[..., start:e_end]))
        out[..., start:q_end] = q / np.linalg.norm(q, axis=-1, keepdims=True)
        return out

    def minus(xs: np.ndarray, x: np.ndarray) -> np.ndarray:
        xs, x = np.asarray(xs, dtype=float), np.asarray(x, dtype=float)
        d = np.empty((*xs.shape[:-1], xs.shape[-1] - 1))
        d[..., :start] = xs[..., :start] - x[..., :start]
        d[..., e_end:] = xs[..., q_end:] - x[..., q_end:]
        conj = x[..., start:q_end] * np.array([1.0, -1.0, -1.0, -1.0])
        d[..., start:e_end] = quat_to_rotvec(quat_multiply(conj, xs[..., start:q_end]))
        return d

    return plus, minus


class SigmaPointFilter:
    """Sigma-point Kalman filter on a state with manifold hooks (see the module docstring).

    Parameters
    ----------
    x0 : (n_x,) initial nominal state.
    p0 : (n, n) initial covariance of its error.
    points : ``"symmetric"`` (2L + 1 points, Chan et al.) or ``"simplex"`` (L + 2 points,
        Cho & Choi eqs. 21-23).
    alpha, beta : spread and prior-distribution parameters of either set.
    kappa : secondary scaling of the symmetric set.
    w0 : central weight of the simplex set before scaling, 0 <= w0 < 1.
    boxplus, boxminus : manifold hooks (default: addition, subtraction).
    augment : carry the non-zero process-noise terms in the sigma points (``propagate`` then
        needs ``q``; ``fx`` receives their noise) instead of adding Q in ``covariance``.
    """

    def __init__(self, x0: np.ndarray, p0: np.ndarray, *, points: str = "symmetric",
                 alpha: float = 1.0, beta: float = 2.0, kappa: float = 0.0, w0: float = 0.0,
                 boxplus: Boxplus | None = None, boxminus: Boxminus | None = None,
                 augment: bool = False):
        if points not in ("symmetric", "simplex"):
            raise ValueError(f"points must be 'symmetric' or 'simplex', got {points!r}")
        self.x = np.array(x0, dtype=float)
        self.p = np.array(p0, dtype=float)
        self.n = self.p.shape[0]
        self._kind = points
        self._alpha, self._beta, self._kappa, self._w0 = alpha, beta, kappa, w0
        self._plus = boxplus or _euclid_plus
        self._minus = boxminus or _euclid_minus
        self.augment = augment
        self.sigma: np.ndarray | None = None  # (k, n_x) current points, None when stale
        self._noise: np.ndarray | None = None  # (k, n_q) their process noise (augmented)
        self._wm = self._wc = np.empty(0)
        self._p_stale = False  # points propagated since P was last formed

    def _unit_points(self, p_a: np.ndarray) -> np.ndarray:
        """Offsets of the points of N(0, p_a), shape (k, L); sets the weights."""
        zero = np.zeros(p_a.shape[0])
        root = psd_sqrt(p_a)
        cov = root @ root.T  # positive definite by construction, so Cholesky succeeds
        if self._kind == "symmetric":
            offsets, self._wm, self._wc = symmetric_points(zero, cov, self._alpha, self._beta,
                                                           self._kappa)
        else:
            offsets, self._wm, self._wc = simplex_points(zero, cov, self._alpha, self._beta,
                                                         self._w0)
        return offsets

    def draw(self, q: np.ndarray | None = None) -> np.ndarray:
        """Sigma points of the current (x, P), with the noise of ``q`` (n_q, n_q) augmented
        when the filter augments (Cho & Choi eqs. 19-23). Returns the points (k, n_x)."""
        if self.augment:
            if q is None:
                raise ValueError("an augmented filter needs the process noise q to draw")
            lam, vec = np.linalg.eigh(0.5 * (q + q.T))
            keep = lam > _CLIP_RELATIVE * max(float(lam.max(initial=0.0)), 0.0)
            r = int(keep.sum())
            p_a = np.zeros((self.n + r, self.n + r))
            p_a[:self.n, :self.n] = self.p
            p_a[self.n:, self.n:] = np.diag(lam[keep])
            offsets = self._unit_points(p_a)
            self._noise = offsets[:, self.n:] @ vec[:, keep].T
        else:
            offsets = self._unit_points(self.p)
            self._noise = None
        self.sigma = self._plus(self.x, offsets[:, :self.n])
        return self.sigma

    def mean(self, points: np.ndarray) -> np.ndarray:
        """Weighted manifold mean of ``points`` (k, n_x): Gauss-Newton iteration from the
        central point, x <- x boxplus sum_i W_i^(m) (X_i boxminus x) (exact in one step when
        the hooks are Euclidean)."""
        x = points[0].copy()
        for _ in range(_MEAN_ITERATIONS):
            step = self._wm @ self._minus(points, x)
            x = self._plus(x, step)
            if np.max(np.abs(step)) < _MEAN_TOLERANCE:
                break
        return x

    def propagate(self, fx: Callable[..., np.ndarray], *args, q: np.ndarray | None = None
                  ) -> np.ndarray:
        """Move every sigma point through ``fx(X, W, *args)`` (drawing them first if stale);
        set and return the mean state (Cho & Choi eq. 24, 25)."""
        if self.sigma is None:
            self.draw(q)
        self.sigma = fx(self.sigma, self._noise, *args)
        self.x = self.mean(self.sigma)
        self._p_stale = True
        return self.x

    def covariance(self, q: np.ndarray | None = None, redraw: bool = False) -> np.ndarray:
        """P from the propagated points (Cho & Choi eq. 26), plus an additive ``q`` (n, n).
        With ``redraw`` (or a ``q``) the points are released: the next ``propagate`` or
        ``update`` draws fresh ones from (x, P)."""
        if self.sigma is None:
            raise RuntimeError("covariance() needs propagated sigma points")
        d = self._minus(self.sigma, self.x)
        p = (self._wc[:, None] * d).T @ d
        self._p_stale = False
        if q is not None:
            p = p + q  # the points do not carry q: they are redrawn
        if q is not None or redraw:
            self.sigma = None
            self._noise = None
        self.p = 0.5 * (p + p.T)
        return self.p

    def predict(self, fx: Callable[..., np.ndarray], *args, q: np.ndarray | None = None
                ) -> None:
        """One standard time update: draw, propagate, covariance (Q augmented or added)."""
        self.draw(q)
        self.propagate(fx, *args, q=q)
        self.covariance(None if self.augment else q)

    def predict_measurement(self, hx: Callable[..., np.ndarray], *args
                            ) -> tuple[np.ndarray, np.ndarray]:
        """Mean (m,) and covariance (m, m, without R) of ``hx(X, *args)`` over the points the
        next ``update`` uses (drawn now if stale), to screen measurements before it (an
        innovation gate, for instance)."""
        self._points_for_update()
        zs = np.atleast_2d(hx(self.sigma, *args))
        z_hat = self._wm @ zs
        d = zs - z_hat
        return z_hat, (self._wc[:, None] * d).T @ d

    def _points_for_update(self) -> None:
        if self._p_stale:
            raise RuntimeError("call covariance() after propagate() and before update()")
        if self.sigma is None:
            saved, self.augment = self.augment, False
            self.draw()
            self.augment = saved

    def update(self, hx: Callable[..., np.ndarray], z: np.ndarray, r: np.ndarray, *args,
               z_residual: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None
               ) -> tuple[np.ndarray, np.ndarray]:
        """Measurement update with ``hx(X, *args)`` -> (k, m) (Cho & Choi eqs. 27-32).

        Uses the current points if they carry the prediction, else draws them from (x, P)
        without noise. ``z_residual(Z, z)`` gives Z - z for rows Z (default: subtraction).
        Returns the innovation (m,) and its covariance P_yy (m, m).
        """
        self._points_for_update()
        minus_z = z_residual or _euclid_minus
        zs = np.atleast_2d(hx(self.sigma, *args))
        # the measurement mean taken as one step from the central point's (exact if linear)
        z_hat = zs[0] + self._wm @ minus_z(zs, zs[0])
        dz = minus_z(zs, z_hat)
        dx = self._minus(self.sigma, self.x)
        p_yy = (self._wc[:, None] * dz).T @ dz + np.atleast_2d(r)
        p_yy = 0.5 * (p_yy + p_yy.T)
        p_xy = (self._wc[:, None] * dx).T @ dz
        gain = np.linalg.solve(p_yy, p_xy.T).T
        innovation = minus_z(np.atleast_2d(np.asarray(z, dtype=float)), z_hat)[0]
        self.x = self._plus(self.x, gain @ innovation)
        p = self.p - gain @ p_yy @ gain.T
        self.p = 0.5 * (p + p.T)
        self.sigma = None
        self._noise = None
        return innovation, p_yy
