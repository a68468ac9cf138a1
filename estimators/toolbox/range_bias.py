"""Per-satellite range-error states of a tightly coupled filter: the slowly varying part of each
pseudorange's error (the broadcast orbit and clock error, the ionosphere's residual where it
differs between satellites) carried as a first-order Gauss-Markov state per receiver channel,
instead of as white noise that the filter would average away.

A pseudorange error that stays constant over a drive (the signal-in-space error of a
satellite, its share of the ionosphere residual) is not reduced by averaging epochs: treated
as white, it makes the position sigma shrink as 1 / sqrt(epochs) while the error stays. The
textbook remedy for coloured measurement noise is to augment the state with it (Brown &
Hwang, *Introduction to Random Signals and Applied Kalman Filtering*, 4th ed.; for the
ranging errors of INS/GNSS, Groves 2013, chapter 14): one correlated range error per
satellite, each row of the pseudorange measurement carrying a 1 on its satellite's state.

``RangeBiasChannels`` keeps the channel bookkeeping: a fixed number of states (the filter's
dimension must not change: a UKF's sigma points), given to satellites as they appear; a
satellite keeps its channel while it is not needed by another (so an outage does not forget
its error); a new satellite takes the channel whose satellite was seen longest ago, whose
state is reset to zero with the new satellite's prior variance and no correlation. A
satellite that finds no free channel is left out of that epoch.

Public names
------------
RangeBiasChannels.
"""

from __future__ import annotations

import numpy as np


class RangeBiasChannels:
    """Channel bookkeeping of ``n`` range-error states starting at state index ``first``.

    Parameters
    ----------
    first : index of the first channel state in the filter's state vector.
    n : number of channels.
    correlation_time_s : the states' Gauss-Markov correlation time, s.
    """

    def __init__(self, first: int, n: int, correlation_time_s: float):
        self.first = first
        self.n = n
        self.tau = float(correlation_time_s)
        self.sv = np.full(n, -1.0)  # satellite of each channel (-1: free)
        self.last_seen = np.full(n, -np.inf)
        self.sigma = np.zeros(n)  # steady-state 1-sigma of each channel's state

    def assign(self, sv: np.ndarray, t: float, sigma: np.ndarray, p: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
        """State indices of the satellites ``sv`` (m,) at time ``t`` (-1 where no channel is
        free) and which of them are new to their channel: those reset it in the covariance
        ``p``, in place, to the prior 1-sigma ``sigma`` (m,) without correlation (the caller
        zeroes the channel's estimate)."""
        out = np.full(len(sv), -1, dtype=int)
        new = np.zeros(len(sv), dtype=bool)
        in_use = np.isin(self.sv, sv)
        for i, s in enumerate(sv):
            have = np.flatnonzero(self.sv == s)
            if have.size:
                c = int(have[0])
            else:
                free = np.flatnonzero(~in_use)
                if free.size == 0:
                    continue
                c = int(free[np.argmin(self.last_seen[free])])
                in_use[c] = True
                self.sv[c] = s
                self.sigma[c] = sigma[i]
                k = self.first + c
                p[k, :] = 0.0
                p[:, k] = 0.0
                p[k, k] = sigma[i] ** 2
                new[i] = True
            self.last_seen[c] = t
            out[i] = self.first + c
        return out, new

    def transition(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Diagonal transition factors exp(-dt / tau) and process variances
        sigma^2 (1 - exp(-2 dt / tau)) of the n channels over ``dt`` (Brown & Hwang,
        section 2.9)."""
        phi = np.exp(-dt / self.tau)
        return np.full(self.n, phi), self.sigma**2 * (1.0 - phi * phi)
