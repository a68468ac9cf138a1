"""Innovation gating and adaptive measurement noise, the opt-in robustness blocks of the filter
toolbox (off unless a paper's filter uses them).

* Chi-square gating: with a consistent filter the innovation nu of an m-row measurement has
  covariance S = H P H^T + R, so its normalised innovation squared d^2 = nu^T S^-1 nu is
  chi-square distributed with m degrees of freedom (Bar-Shalom, Li & Kirubarajan, *Estimation
  with Applications to Tracking and Navigation*, 2001, section 5.4.2; Groves 2013, section
  17.3.1). A measurement whose d^2 exceeds the chi-square quantile of the chosen probability
  is rejected.
* Threshold adaptation of R (Park et al. 2019, section III-D): a measurement's noise variance
  is raised from its nominal to an inflated value while a test statistic (the accelerometer's
  specific-force norm minus gravity, the vehicle speed, the innovation) is beyond a threshold.
  ``threshold_variance`` gives the variance for one such rule; the rules themselves, with the
  paper's thresholds, live with the filter that uses them.
* Re-acquisition after a lock-out: a gate tests each measurement against the filter's own
  covariance, so a filter whose error has outgrown its covariance (an outage its process noise
  under-describes) rejects every returning measurement and never recovers. Outliers (multipath,
  NLOS) strike satellites one by one; when most rows of an epoch fail, the prediction is the
  more likely culprit. ``matching_variance`` gives the variance that, added to every row's S,
  makes the median row's innovation one sigma (covariance matching, Mehra, "Approaches to
  adaptive filtering", IEEE Trans. Autom. Control 17, 1972, section III-B): the filter adds it
  to the states the rows observe and gates again, so the consistent majority passes and a row
  still far beyond it stays rejected.

``update`` of ``estimators.toolbox.kalman`` returns S, so a filter gates by computing the
prediction, calling ``passes_gate(nu, s)`` with S = H P H^T + R (``innovation_covariance``), and
updating only when it passes.

Public functions
----------------
chi2_threshold, innovation_covariance, innovation_variances, matching_variance,
normalised_innovation_squared, passes_gate, rows_passing, threshold_variance, FixNoiseMatching.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np


@lru_cache(maxsize=64)
def chi2_threshold(dof: int, probability: float = 0.999) -> float:
    """The chi-square quantile: P(d^2 <= threshold) = ``probability`` for ``dof`` degrees of
    freedom (scipy.stats.chi2.ppf; cached, as a filter asks for the same few values).

    Parameters
    ----------
    dof : int
        Degrees of freedom, the number of measurement rows (>= 1).
    probability : float
        Probability of accepting a measurement that fits the model, in (0, 1).
    """
    from scipy.stats import chi2  # imported here: scipy.stats costs 0.2 s and gating is opt-in

    if dof < 1 or not 0.0 < probability < 1.0:
        raise ValueError(f"chi2_threshold needs dof >= 1 and 0 < probability < 1, "
                         f"got {dof}, {probability}")
    return float(chi2.ppf(probability, dof))


def innovation_covariance(p: np.ndarray, h: np.ndarray, r: np.ndarray) -> np.ndarray:
    """S = H P H^T + R, shape (m, m), symmetrised (Groves 2013, eq. 3.25's denominator)."""
    h = np.atleast_2d(h)
    s = h @ p @ h.T + np.atleast_2d(r)
    return 0.5 * (s + s.T)


def innovation_variances(p: np.ndarray, h: np.ndarray, r: np.ndarray) -> np.ndarray:
    """The diagonal of S = H P H^T + R, shape (m,), from H's non-zero columns only (a
    carrier-phase filter's rows touch a few of its states)."""
    h = np.atleast_2d(h)
    cols = np.flatnonzero(np.any(h != 0.0, axis=0))
    h_c = h[:, cols]
    p_c = p.take(cols, axis=0).take(cols, axis=1)
    return np.einsum("ij,ij->i", h_c @ p_c, h_c) + np.diag(np.atleast_2d(r))


def normalised_innovation_squared(nu: np.ndarray, s: np.ndarray) -> float:
    """d^2 = nu^T S^-1 nu for an innovation ``nu`` (m,) with covariance ``s`` (m, m)."""
    nu = np.atleast_1d(np.asarray(nu, dtype=float))
    return float(nu @ np.linalg.solve(np.atleast_2d(s), nu))


def passes_gate(nu: np.ndarray, s: np.ndarray, probability: float = 0.999) -> bool:
    """True when the innovation is consistent with its covariance at ``probability``
    (d^2 <= chi-square quantile with len(nu) degrees of freedom)."""
    nu = np.atleast_1d(nu)
    return normalised_innovation_squared(nu, s) <= chi2_threshold(nu.size, probability)


def rows_passing(nu: np.ndarray, s_diag: np.ndarray, probability: float = 0.999) -> np.ndarray:
    """Boolean mask of the rows whose own innovation passes a one-degree-of-freedom gate:
    nu_i^2 <= chi2_1(probability) S_ii, for ``nu`` (m,) and the variances ``s_diag`` (m,)
    (the per-measurement outlier test of Groves 2013, section 17.3.1)."""
    return np.asarray(nu, float) ** 2 <= chi2_threshold(1, probability) * np.asarray(s_diag)


def matching_variance(nu: np.ndarray, s_diag: np.ndarray) -> float:
    """The variance q >= 0 to add to every row's S_ii so that the median row's innovation is
    one sigma: median(nu_i^2 - S_ii) (covariance matching, Mehra 1972; module docstring), for
    ``nu`` (m,) and the variances ``s_diag`` (m,)."""
    excess = np.asarray(nu, float) ** 2 - np.asarray(s_diag, float)
    return max(0.0, float(np.median(excess)))


def threshold_variance(statistic: float, threshold: float, sigma_nominal: float,
                       sigma_inflated: float, above: bool = True) -> float:
    """The measurement variance of a threshold adaptation rule (Park et al. 2019, section
    III-D): ``sigma_inflated``^2 when ``statistic`` is beyond ``threshold`` (above it, or below
    it with ``above=False``), else ``sigma_nominal``^2."""
    beyond = statistic > threshold if above else statistic < threshold
    return (sigma_inflated if beyond else sigma_nominal) ** 2


MATCHING_FIXES = 20.0  # fixes in the covariance-matching average (its e-folding length)


class FixNoiseMatching:
    """Covariance matching of the fixes' position noise (Mehra 1972; Mohamed & Schwarz 1999,
    "Adaptive Kalman filtering for INS/GPS", J. Geodesy 73): the fix's real variance per axis
    is estimated as the running mean of nu^2 - (H P H^T) over the position rows (innovation
    nu, predicted covariance H P H^T), and the HDOP-based variance is scaled up to it
    (never down). A street canyon's reflected signals leave HDOP unchanged while the fixes
    move by metres: without this the filter believes them to a metre. The same on one axis of
    a fix's velocity (``ins_lkf``): a reflected Doppler."""

    def __init__(self) -> None:
        self.scale = 1.0
        self._excess = 0.0  # running mean of the ratio (nu^2 - HPH^T) / R, per axis
        self._weight = 0.0

    def add(self, nu: np.ndarray, hph: np.ndarray, white_var: float) -> None:
        """Learn from one fix's position rows: innovations ``nu`` (2,), the predicted
        covariance ``hph`` (2, 2) and the fix's HDOP variance per axis ``white_var``
        (``Tuning.white_position_var``)."""
        ratio = float(np.mean(nu**2 - np.diag(hph))) / white_var
        self._weight = min(self._weight + 1.0, MATCHING_FIXES)
        self._excess += (ratio - self._excess) / self._weight
        self.scale = max(1.0, self._excess)
