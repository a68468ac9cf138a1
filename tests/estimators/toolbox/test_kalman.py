"""Kalman filter blocks against problems with known answers: the steady-state Riccati solution
(scipy.linalg.solve_discrete_are), batch least squares for a static state, and the equivalence of
closed-loop, open-loop and total-state filtering on a linear system."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import solve_discrete_are

from estimators.toolbox.kalman import ErrorState, predict, update

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
