"""The Kalman filter's linear algebra, the one home for every estimator: prediction, the
Joseph-form measurement update, and the closed- or open-loop handling of an error state.

* ``predict``: x <- Phi x, P <- Phi P Phi^T + Q_d (Groves 2013, section 3.2.2, steps 1-2).
* ``update``: K = P H^T (H P H^T + R)^-1, x <- x + K nu, P <- (I - K H) P (I - K H)^T + K R K^T,
  the Joseph form, which keeps P symmetric and positive semi-definite for any gain (Groves
  section 3.2.2, steps 4-7, with the Joseph covariance update of Brown & Hwang, *Introduction
  to Random Signals and Applied Kalman Filtering*, 4th ed., section 4.2).
* ``predict_blocks``: the same prediction for a transition that is block diagonal, a full
  block A followed by uncoupled scalar states B (first-order Gauss-Markov or constant: the
  extra states of an INS filter, the ambiguities of a carrier-phase filter): P_AA <- Phi_A
  P_AA Phi_A^T + Q_A, P_AB <- Phi_A P_AB diag(phi_B), P_BB <- phi_B phi_B^T * P_BB + diag(q_B),
  the products of ``predict`` without the zero blocks (O(a^2 n) instead of O(n^3)).
* ``predict_static``: ``predict_blocks`` for a state vector whose B states are mostly static
  (phi = 1, no noise: the ambiguities of a carrier-phase filter): only the rows and columns
  of the B states that move are touched, O(a n + b_moving n) instead of O(n^2).
* ``update_sparse``: ``update`` for a measurement matrix with few non-zero columns c (the
  rows of a carrier-phase filter's double differences, an odometer's rows on the INS block):
  P H^T = P[:, c] H_c^T, and only the states correlated with those columns (rows r of P with
  a non-zero in P[:, c]) change; on that block the Joseph form's products in the order
  (I - K H) P = P - K (P H^T)^T, then ((I - K H) P) (I - K H)^T = B - (B H^T) K^T, plus
  K R K^T: the same form, its zero terms skipped (O(r^2 m) instead of O(n^3)).
* ``ErrorState``: the estimate of errors of a nominal (total-state) solution. Errors are defined
  as estimate minus truth, and a measurement enters as dz = h(nominal) - z ~ H dx + noise. In
  closed loop (Groves section 14.1.1) the estimated errors are fed back into the nominal solution
  after each update and the error estimate is reset to zero, so it need not be propagated; in
  open loop the nominal solution is never corrected, the error estimate is propagated with the
  transition matrix and subtracted from the nominal solution only for output. ``set_closed_loop``
  switches mid-run (Tan et al. 2008: closed loop while GPS aids, open loop in outages).

``predict`` and ``update`` are plain numpy: with 15 states a prediction takes about 12 us and an
update about 50 us, so an hour of 100 Hz predictions costs about 4 s (900 times real time);
numba would save little of that and cost every process 20 s of compilation.

Public names
------------
predict, predict_blocks, predict_static, update, update_sparse, ErrorState.
"""

from __future__ import annotations

import numpy as np


def predict(x: np.ndarray, p: np.ndarray, phi: np.ndarray,
            q_d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Time update of a linear(ised) discrete system.

    Parameters
    ----------
    x : (n,) state estimate.
    p : (n, n) its covariance.
    phi : (n, n) transition matrix over the step.
    q_d : (n, n) discrete process-noise covariance of the step.

    Returns
    -------
    x : (n,) predicted state; p : (n, n) predicted covariance (symmetrised).
    """
    p_new = phi @ p @ phi.T + q_d
    return phi @ x, 0.5 * (p_new + p_new.T)


def predict_blocks(x: np.ndarray, p: np.ndarray, phi_a: np.ndarray, q_a: np.ndarray,
                   phi_b: np.ndarray, q_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``predict`` with Phi = diag(phi_a, diag(phi_b)) and Q_d = diag(q_a, diag(q_b)).

    Parameters
    ----------
    x : (n,); p : (n, n).
    phi_a, q_a : (a, a) transition and noise of the first a states.
    phi_b, q_b : (n - a,) the diagonal transition and noise of the rest.
    """
    a = phi_a.shape[0]
    p_new = np.empty_like(p)
    p_new[:a, :a] = phi_a @ p[:a, :a] @ phi_a.T + q_a
    p_new[:a, a:] = (phi_a @ p[:a, a:]) * phi_b
    p_new[a:, :a] = p_new[:a, a:].T
    p_new[a:, a:] = p[a:, a:] * np.outer(phi_b, phi_b)
    p_new[a:, a:] += np.diag(q_b)
    x_new = np.concatenate([phi_a @ x[:a], phi_b * x[a:]])
    return x_new, 0.5 * (p_new + p_new.T)


def predict_static(x: np.ndarray, p: np.ndarray, phi_a: np.ndarray, q_a: np.ndarray,
                   phi_b: np.ndarray, q_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``predict_blocks`` (same arguments) touching only the B states that move (phi_b not 1
    or q_b not 0): P_BB[i, j] = phi_i phi_j P_BB[i, j] + q_i delta_ij is P_BB[i, j] itself
    where both are static. The result is symmetric; P must be."""
    a = phi_a.shape[0]
    p_new = p.copy()
    p_aa = phi_a @ p[:a, :a] @ phi_a.T + q_a
    p_new[:a, :a] = 0.5 * (p_aa + p_aa.T)
    p_new[:a, a:] = (phi_a @ p[:a, a:]) * phi_b
    p_new[a:, :a] = p_new[:a, a:].T
    moving = np.flatnonzero((phi_b != 1.0) | (q_b != 0.0))
    if len(moving):
        rows = a + moving
        block = p[rows, a:] * (phi_b[moving, None] * phi_b)  # phi_i phi_j: symmetric
        block[np.arange(len(moving)), moving] += q_b[moving]
        p_new[rows, a:] = block
        p_new[a:, rows] = block.T
    return np.concatenate([phi_a @ x[:a], phi_b * x[a:]]), p_new


def update_sparse(x: np.ndarray, p: np.ndarray, innovation: np.ndarray, h: np.ndarray,
                  r: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``update`` (same arguments and results, the Joseph form) computed on H's non-zero
    columns and the states correlated with them (module docstring); the other states' rows
    and columns of P are returned unchanged, as the dense form leaves them."""
    h = np.atleast_2d(h)
    r = np.atleast_2d(r)
    cols = np.flatnonzero(np.any(h != 0.0, axis=0))
    touched = np.any(p[:, cols] != 0.0, axis=1)
    touched[cols] = True
    rows = np.flatnonzero(touched)
    h_c = h[:, cols]
    at = np.searchsorted(rows, cols)  # the columns' places among the rows
    p_rr = p.take(rows, axis=0).take(rows, axis=1)
    pht = p_rr[:, at] @ h_c.T  # P H^T on the rows
    s = h_c @ pht[at] + r
    s = 0.5 * (s + s.T)
    k = np.linalg.solve(s, pht.T).T
    b = p_rr - k @ pht.T  # (I - K H) P
    p_rr = b + (k @ r - b[:, at] @ h_c.T) @ k.T  # B (I - K H)^T + K R K^T
    p_new = p.copy()
    p_new[np.ix_(rows, rows)] = 0.5 * (p_rr + p_rr.T)
    x_new = x.copy()
    x_new[rows] += k @ innovation
    return x_new, p_new, s


def update(x: np.ndarray, p: np.ndarray, innovation: np.ndarray, h: np.ndarray,
           r: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Measurement update in Joseph form.

    Parameters
    ----------
    x : (n,) state estimate; p : (n, n) its covariance.
    innovation : (m,) measurement minus its prediction, nu = z - H x (linear case).
    h : (m, n) measurement matrix.
    r : (m, m) measurement-noise covariance.

    Returns
    -------
    x : (n,) updated state; p : (n, n) updated covariance; s : (m, m) innovation covariance
    H P H^T + R (for gating: nu^T S^-1 nu is chi-square with m degrees of freedom).
    """
    h = np.atleast_2d(h)
    r = np.atleast_2d(r)
    s = h @ p @ h.T + r
    s = 0.5 * (s + s.T)
    k = np.linalg.solve(s, h @ p).T  # P H^T S^-1 with S and P symmetric
    a = np.eye(p.shape[0]) - k @ h
    p_new = a @ p @ a.T + k @ r @ k.T
    return x + k @ innovation, 0.5 * (p_new + p_new.T), s


class ErrorState:
    """Error estimate and covariance of a nominal solution, in closed or open loop.

    Parameters
    ----------
    p0 : (n, n) initial error covariance (the initial error estimate is zero).
    closed_loop : bool
        True: call ``feedback()`` after each update and remove the returned errors from the
        nominal solution. False: never correct the nominal solution; output nominal minus
        ``estimate``.
    sparse : bool
        Update with ``update_sparse`` and predict blockwise with ``predict_static`` (the same
        filter to rounding, faster when H has few columns and the extra states are mostly
        static); False: ``update`` and ``predict_blocks``.
    """

    def __init__(self, p0: np.ndarray, closed_loop: bool = True, sparse: bool = False):
        self.p = np.array(p0, dtype=float)
        self.x = np.zeros(self.p.shape[0])
        self.closed_loop = closed_loop
        self._update = update_sparse if sparse else update
        self._predict_blocks = predict_static if sparse else predict_blocks

    @property
    def estimate(self) -> np.ndarray:
        """The current error estimate (estimate minus truth), shape (n,)."""
        return self.x

    def predict(self, phi: np.ndarray, q_d: np.ndarray) -> None:
        """Propagate the covariance (and in open loop the error estimate) over one step."""
        self.x, self.p = predict(self.x, self.p, phi, q_d)

    def predict_blocks(self, phi_a: np.ndarray, q_a: np.ndarray, phi_b: np.ndarray,
                       q_b: np.ndarray) -> None:
        """``predict`` with a block-diagonal transition (module function ``predict_blocks``,
        or ``predict_static`` for a sparse filter)."""
        self.x, self.p = self._predict_blocks(self.x, self.p, phi_a, q_a, phi_b, q_b)

    def update(self, dz: np.ndarray, h: np.ndarray, r: np.ndarray) -> np.ndarray:
        """Update with dz = h(nominal) - z (shape (m,)); returns the innovation covariance."""
        h = np.atleast_2d(np.asarray(h, dtype=float))
        self.x, self.p, s = self._update(self.x, self.p, np.asarray(dz, float) - h @ self.x, h,
                                         r)
        return s

    def feedback(self) -> np.ndarray:
        """Closed loop: the estimated errors to remove from the nominal solution; the error
        estimate is reset to zero (its covariance is unchanged)."""
        if not self.closed_loop:
            raise RuntimeError("feedback() is for closed-loop error states; in open loop "
                               "subtract `estimate` from the nominal solution for output")
        dx, self.x = self.x, np.zeros_like(self.x)
        return dx

    def set_closed_loop(self, closed: bool) -> np.ndarray:
        """Switch between closed and open loop mid-run.

        Returns the errors to remove from the nominal solution now: on closing the loop, the
        error estimate accumulated in open loop (which is then reset to zero, as after a
        feedback); otherwise zeros.
        """
        dx = np.zeros_like(self.x)
        if closed and not self.closed_loop:
            dx, self.x = self.x, dx
        self.closed_loop = closed
        return dx
