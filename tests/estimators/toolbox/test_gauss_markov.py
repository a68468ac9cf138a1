"""Gauss-Markov and Van Loan discretisation against closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.toolbox.gauss_markov import gauss_markov_continuous, gauss_markov_discrete, van_loan


def test_first_order_closed_form_and_van_loan_agree():
    tau, sigma, dt = np.array([300.0, 2.0]), np.array([1e-4, 0.05]), 0.01
    phi, q_d = gauss_markov_discrete(tau, sigma, dt)
    f, q_c = gauss_markov_continuous(tau, sigma)
    phi_vl, q_vl = van_loan(np.diag(f), np.diag(q_c), dt)
    np.testing.assert_allclose(np.diag(phi_vl), phi, rtol=1e-12)
    np.testing.assert_allclose(np.diag(q_vl), q_d, rtol=1e-9)
    np.testing.assert_allclose(phi, np.exp(-dt / tau))
    # q_d = integral of exp(-2 s / tau) q_c ds over the step
    np.testing.assert_allclose(q_d, q_c * tau / 2 * (1 - np.exp(-2 * dt / tau)), rtol=1e-12)


def test_first_order_keeps_the_steady_state_variance():
    phi, q_d = gauss_markov_discrete(50.0, 0.2, 0.1)
    variance = 0.2**2
    assert phi**2 * variance + q_d == pytest.approx(variance, rel=1e-12)


def test_white_acceleration_matches_the_closed_form():
    """x = [position, velocity], acceleration white with PSD q: Q_d = q [[dt^3/3, dt^2/2],
    [dt^2/2, dt]] (Brown & Hwang, 4th ed., section 3.9 example)."""
    q, dt = 0.3, 0.5
    phi, q_d = van_loan(np.array([[0.0, 1.0], [0.0, 0.0]]), np.diag([0.0, q]), dt)
    np.testing.assert_allclose(phi, [[1.0, dt], [0.0, 1.0]], atol=1e-15)
    np.testing.assert_allclose(q_d, q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]]),
                               rtol=1e-12)


def test_van_loan_of_a_coupled_system_matches_numerical_integration():
    f = np.array([[-0.5, 1.0], [-2.0, -0.1]])
    gqg = np.array([[0.2, 0.05], [0.05, 0.4]])
    dt = 0.7
    phi, q_d = van_loan(f, gqg, dt)
    from scipy.integrate import quad_vec
    from scipy.linalg import expm
    integral, _ = quad_vec(lambda s: expm(f * s) @ gqg @ expm(f * s).T, 0.0, dt, epsabs=1e-13)
    np.testing.assert_allclose(phi, expm(f * dt), rtol=1e-12)
    np.testing.assert_allclose(q_d, integral, rtol=1e-9)
