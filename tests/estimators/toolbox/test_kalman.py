"""Kalman filter blocks against problems with known answers: the steady-state Riccati solution
(scipy.linalg.solve_discrete_are), batch least squares for a static state, and the equivalence of
closed-loop, open-loop and total-state filtering on a linear system; the sparse update and the
static-block prediction against the dense ones on random problems."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import block_diag, solve_discrete_are

from estimators.toolbox.kalman import (
    ErrorState,
    predict,
    predict_blocks,
    predict_static,
    update,
    update_sparse,
)

DT = 0.1
PHI = np.array([[1.0, DT], [0.0, 1.0]])  # position-velocity, white acceleration
Q = 0.5 * np.array([[DT**3 / 3, DT**2 / 2], [DT**2 / 2, DT]])
H = np.array([[1.0, 0.0]])
R = np.array([[4.0]])


def test_covariance_converges_to_the_riccati_solution():
    p = np.diag([100.0, 10.0])
    x = np.zeros(2)
    for _ in range(2000):
        x, p = predict(x, p, PHI, Q)
        x, p, _ = update(x, p, np.zeros(1), H, R)
    p_prior = solve_discrete_are(PHI.T, H.T, Q, R)  # steady-state a-priori covariance
    k = p_prior @ H.T @ np.linalg.inv(H @ p_prior @ H.T + R)
    p_post = (np.eye(2) - k @ H) @ p_prior
    np.testing.assert_allclose(p, p_post, rtol=1e-9)


def test_static_state_equals_batch_least_squares():
    rng = np.random.default_rng(1)
    truth = np.array([3.0, -1.0, 0.5])
    hs = rng.normal(size=(40, 2, 3))
    r = np.diag([0.3, 0.7])
    zs = hs @ truth + rng.normal(size=(40, 2)) * np.sqrt(np.diag(r))
    p0 = np.eye(3) * 1e3
    x, p = np.zeros(3), p0.copy()
    for h, z in zip(hs, zs, strict=True):
        x, p, s = update(x, p, z - h @ x, h, r)
    # the same information in one batch (with the prior as a pseudo-measurement of zero)
    a = np.vstack(hs)
    w = np.kron(np.eye(40), np.linalg.inv(r))
    info = a.T @ w @ a + np.linalg.inv(p0)
    x_ls = np.linalg.solve(info, a.T @ w @ zs.ravel())
    np.testing.assert_allclose(x, x_ls, rtol=1e-10)
    np.testing.assert_allclose(p, np.linalg.inv(info), rtol=1e-8)
    assert s.shape == (2, 2)


def test_joseph_form_stays_symmetric_with_a_suboptimal_gain_use():
    p = np.array([[2.0, 0.3], [0.3, 1.0]])
    x, p_new, s = update(np.zeros(2), p, np.array([1.0]), H, np.array([[1e-12]]))
    assert np.allclose(p_new, p_new.T)
    assert np.all(np.linalg.eigvalsh(p_new) >= -1e-12)
    np.testing.assert_allclose(s, H @ p @ H.T + 1e-12)


@pytest.mark.parametrize("schedule", ["closed", "open", "closed-open-closed"])
def test_error_state_matches_total_state_filter(schedule):
    """On a linear system an error-state filter, closed or open loop, or switching mid-run
    (closed, open for an outage, closed again), gives the output of the total-state filter
    (errors are estimate minus truth; dz = h(nominal) - z); closing the loop hands back the
    open-loop estimate once."""
    def closed_at(k: int) -> bool:
        return {"closed": True, "open": False}.get(schedule, not 50 <= k < 100)

    rng = np.random.default_rng(7)
    x_true = np.array([0.0, 1.0])
    nominal = np.array([5.0, 0.0])  # a wrong start: 5 m and -1 m/s off
    p0 = np.diag([25.0, 1.0])
    x_total, p_total = nominal.copy(), p0.copy()
    es = ErrorState(p0, closed_loop=closed_at(0))
    for k in range(200):
        if closed_at(k) != es.closed_loop:
            nominal = nominal - es.set_closed_loop(closed_at(k))
            assert not es.estimate.any()
        x_true = PHI @ x_true + rng.multivariate_normal(np.zeros(2), Q)
        z = H @ x_true + rng.normal(0.0, 2.0, 1)
        x_total, p_total = predict(x_total, p_total, PHI, Q)
        x_total, p_total, _ = update(x_total, p_total, z - H @ x_total, H, R)
        nominal = PHI @ nominal
        es.predict(PHI, Q)
        es.update(H @ nominal - z, H, R)
        if es.closed_loop:
            nominal = nominal - es.feedback()
            assert not es.estimate.any()
        np.testing.assert_allclose(nominal - es.estimate, x_total, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(es.p, p_total, rtol=1e-9)
    if es.closed_loop:
        assert not es.set_closed_loop(True).any()  # already closed: nothing to hand back
    else:
        with pytest.raises(RuntimeError, match="closed-loop"):
            es.feedback()


def _random_filter_problem(rng: np.random.Generator, n: int, idle: int
                           ) -> tuple[np.ndarray, np.ndarray]:
    """A state and a covariance whose scales span 1e-3..1e2 (a carrier-phase filter's metres,
    radians, cycles), the last ``idle`` states unused (zero rows and columns)."""
    scale = 10.0 ** rng.uniform(-3, 2, n)
    a = rng.normal(size=(n, 2 * n))
    p = (a @ a.T / (2 * n)) * np.outer(scale, scale)
    p[n - idle:, :] = 0.0
    p[:, n - idle:] = 0.0
    x = rng.normal(size=n) * scale
    x[n - idle:] = 0.0
    return x, p


def _close(actual: np.ndarray, expected: np.ndarray, p: np.ndarray, relative: float = 1e-12
           ) -> None:
    """Equal to ``relative`` of each element's scale sqrt(P_ii P_jj) (of the prior
    covariance; sqrt(P_ii) for a state)."""
    sigma = np.sqrt(np.diag(p))
    scale = np.outer(sigma, sigma) if actual.ndim == 2 else sigma
    assert np.all(np.abs(actual - expected) <= relative * scale + 1e-300)


@pytest.mark.parametrize("seeds", [range(0, 100), range(100, 200)])
def test_sparse_update_equals_the_dense_update(seeds):
    """Random problems: 20-60 states of which some are idle, 1-12 rows on a few columns (a
    random subset, or an INS block), correlated R; the updated state, covariance and
    innovation covariance of ``update_sparse`` equal ``update``'s to 1e-12 of each element's
    scale, and rows and columns the measurement does not reach are returned unchanged. The
    state goes through the solve with S, whose rounding is bounded by eps cond(S) (Golub & Van
    Loan, section 3.5; up to 1e7 here): its tolerance is the larger of 1e-12 and 4 eps cond(S);
    the Joseph covariance is first-order insensitive to the gain's rounding."""
    for seed in seeds:
        _check_sparse_update(seed)


def _check_sparse_update(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(20, 61))
    idle = int(rng.integers(0, n // 2))
    x, p = _random_filter_problem(rng, n, idle)
    m = int(rng.integers(1, 13))
    h = np.zeros((m, n))
    used = (np.arange(int(rng.integers(3, 16))) if seed % 2
            else rng.choice(n - idle, size=int(rng.integers(1, min(20, n - idle) + 1)),
                            replace=False))
    h[:, used] = rng.normal(size=(m, len(used))) * rng.uniform(0.1, 10.0)
    h[rng.random(h.shape) < 0.3] = 0.0
    b = rng.normal(size=(m, m))
    r = b @ b.T / m + np.eye(m) * 1e-2
    nu = rng.normal(size=m)
    x_d, p_d, s_d = update(x, p, nu, h, r)
    x_s, p_s, s_s = update_sparse(x, p, nu, h, r)
    _close(x_s, x_d, p, max(1e-12, 4 * np.finfo(float).eps * np.linalg.cond(s_d)))
    _close(p_s, p_d, p)
    np.testing.assert_allclose(s_s, s_d, rtol=1e-12)
    np.testing.assert_array_equal(p_s, p_s.T)
    assert np.all(np.linalg.eigvalsh(p_s[:n - idle, :n - idle]) > 0.0)
    assert not p_s[n - idle:].any() and not x_s[n - idle:].any()


def test_static_prediction_equals_the_block_prediction():
    """A 15-state block A (dense transition) and B states of which some are random constants
    (phi = 1, q = 0: ambiguities) and the rest Gauss-Markov (phi < 1, q > 0): ``predict_static``
    equals ``predict_blocks`` (and the dense ``predict``) to 1e-12 of each element's scale,
    on 50 random problems."""
    for seed in range(50):
        _check_static_prediction(np.random.default_rng(1000 + seed))


def _check_static_prediction(rng: np.random.Generator) -> None:
    a, n = 15, int(rng.integers(20, 80))
    x, p = _random_filter_problem(rng, n, int(rng.integers(0, (n - a) // 2)))
    phi_a = np.eye(a) + 0.1 * rng.normal(size=(a, a))
    g = rng.normal(size=(a, a))
    q_a = g @ g.T * 1e-3
    moving = rng.random(n - a) < 0.4
    phi_b = np.where(moving, rng.uniform(0.9, 1.0, n - a), 1.0)
    q_b = np.where(moving, rng.uniform(0.0, 1e-3, n - a), 0.0)
    x_b, p_b = predict_blocks(x, p, phi_a, q_a, phi_b, q_b)
    x_s, p_s = predict_static(x, p, phi_a, q_a, phi_b, q_b)
    phi = block_diag(phi_a, np.diag(phi_b))
    q = block_diag(q_a, np.diag(q_b))
    x_d, p_d = predict(x, p, phi, q)
    for expected_x, expected_p in ((x_b, p_b), (x_d, p_d)):
        scale = np.sqrt(np.diag(p) + np.diag(p_d))
        assert np.all(np.abs(x_s - expected_x) <= 1e-12 * np.abs(expected_x) + 1e-300)
        assert np.all(np.abs(p_s - expected_p) <= 1e-12 * np.outer(scale, scale) + 1e-300)
    np.testing.assert_array_equal(p_s, p_s.T)


def test_sparse_error_state_runs_the_dense_filter():
    """An ``ErrorState`` with ``sparse=True`` through 300 steps of block prediction and
    updates on a few columns keeps the dense filter's estimate and covariance (the rounding
    does not grow)."""
    rng = np.random.default_rng(5)
    a, n = 6, 30
    p0 = np.diag(np.r_[np.ones(a), np.full(n - a, 25.0)])
    dense, sparse = ErrorState(p0), ErrorState(p0, sparse=True)
    phi_a = np.eye(a) + np.diag(np.full(a - 1, 0.1), 1)
    q_a = np.eye(a) * 1e-4
    phi_b = np.r_[np.ones(n - a - 4), np.full(4, 0.99)]
    q_b = np.r_[np.zeros(n - a - 4), np.full(4, 1e-3)]
    for _ in range(300):
        cols = np.r_[np.arange(3), a + rng.choice(n - a, 5, replace=False)]
        h = np.zeros((4, n))
        h[:, cols] = rng.normal(size=(4, len(cols)))
        dz = rng.normal(size=4)
        for es in (dense, sparse):
            es.predict_blocks(phi_a, q_a, phi_b, q_b)
            es.update(dz, h, np.eye(4) * 0.01)
            es.feedback()
    np.testing.assert_allclose(sparse.p, dense.p, rtol=1e-9, atol=1e-12)
