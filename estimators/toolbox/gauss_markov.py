"""Discretisation of continuous-time linear noise models: first-order Gauss-Markov processes in
closed form, and any linear system (F, G Q G^T) by Van Loan's method.

A first-order Gauss-Markov process x' = -x / tau + w, E[w(t) w(s)] = q_c delta(t - s) with
q_c = 2 sigma^2 / tau, keeps the steady-state standard deviation sigma. Over a step dt
(Brown & Hwang, *Introduction to Random Signals and Applied Kalman Filtering*, 4th ed.,
chapters 2 and 3; the same model as the Gauss-Markov sensor errors of Karamat et al. 2015):

    phi = exp(-dt / tau),    q_d = sigma^2 (1 - exp(-2 dt / tau)).

Van Loan (1978), "Computing integrals involving the matrix exponential", IEEE TAC 23(3):
with M = [[-F, G Q G^T], [0, F^T]] dt and exp(M) = [[., M12], [0, M22]],
Phi = M22^T and Q_d = Phi M12 (Brown & Hwang section 3.9).

Public functions
----------------
van_loan; gauss_markov_continuous and gauss_markov_discrete (the closed forms, whose home is
``simulator.stochastic``: the sensors draw the same processes).
"""

from __future__ import annotations

import numpy as np

from simulator.stochastic import gauss_markov_continuous, gauss_markov_discrete

__all__ = ["gauss_markov_continuous", "gauss_markov_discrete", "van_loan"]


def van_loan(f: np.ndarray, gqg: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Transition matrix and discrete process-noise covariance of x' = F x + G w.

    Parameters
    ----------
    f : (n, n) system matrix F.
    gqg : (n, n) G Q G^T, Q the power spectral density of the white noise w.
    dt : float
        Step, s.

    Returns
    -------
    phi : (n, n) exp(F dt); q_d : (n, n) integral over the step of
    exp(F s) G Q G^T exp(F s)^T ds (symmetrised).
    """
    from scipy.linalg import expm  # imported here: dataset generation uses only the closed form

    f = np.asarray(f, dtype=float)
    n = f.shape[0]
    m = np.zeros((2 * n, 2 * n))
    m[:n, :n] = -f
    m[:n, n:] = gqg
    m[n:, n:] = f.T
    e = expm(m * dt)
    phi = e[n:, n:].T
    q_d = phi @ e[:n, n:]
    return phi, 0.5 * (q_d + q_d.T)
