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

What the states carry, from the receiver's datasheet (the simulator draws the same terms,
docs/gnss-errors.md; ``simulator.datasheet``):

* ``iono_residual``: the broadcast ionosphere's relative residual, its part common to the
  satellites |scale - 1| and the field's 1-sigma (``KLOBUCHAR_RESIDUAL`` and 0 without a
  datasheet: the broadcast model leaves about half the delay, Klobuchar 1987). The common part
  is one scale state on each pseudorange's broadcast delay I (``broadcast_iono_delay``),
  a Gauss-Markov state of ``IONO_CORRELATION_TIME_S``.
* ``satellite_sigma``: each satellite's own slowly varying error, the channel's prior
  sqrt(sis^2 + (s field I)^2): the signal-in-space error (``SIS_ERROR_M`` without a datasheet,
  the IS-GPS-200 URA) and the satellite's own share s of the ionosphere field
  (``IONO_FIELD_OWN_SHARE``).

``RangeErrorStates`` is the block of both after a filter's own states: the ionosphere scale
(when its prior is not zero) and ``RANGE_BIAS_CHANNELS`` channels, their estimates (closed
loop: the filter feeds its corrections back), transition and noise, each pseudorange's
correction and row entries, and the share of the reported variance they carry
(``carried_variance``: the rest stays in R).

Public names
------------
RangeBiasChannels, RangeErrorStates, iono_residual, broadcast_iono_delay, satellite_sigma,
RANGE_BIAS_CHANNELS, RANGE_BIAS_TIME_S, SIS_ERROR_M, IONO_CORRELATION_TIME_S,
KLOBUCHAR_RESIDUAL, PSEUDORANGE_STD_FLOOR_M.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from estimators.toolbox import gnss_model
from simulator.datasheet import IONO_FIELD_OWN_SHARE, iono_residual_fractions

RANGE_BIAS_CHANNELS = 16  # per-satellite range-error states of a datasheet tuning
RANGE_BIAS_TIME_S = 1800.0  # s: their correlation time (signal in space, ionosphere field)
SIS_ERROR_M = 0.5  # m: the signal-in-space error without a receiver datasheet (IS-GPS-200 URA)
IONO_CORRELATION_TIME_S = 1800.0  # s: the broadcast ionosphere residual's (docs/gnss-errors.md)
KLOBUCHAR_RESIDUAL = 0.5  # the broadcast model leaves about half the delay (Klobuchar 1987)
PSEUDORANGE_STD_FLOOR_M = 0.1  # what is left of a pseudorange's 1-sigma at least, m


def iono_residual(receiver: Mapping[str, Any]) -> tuple[float, float]:
    """The broadcast ionosphere's relative residual from the receiver's datasheet block
    (``simulator.datasheet.iono_residual_fractions``): its part common to the satellites and
    the 1-sigma of the field's (``KLOBUCHAR_RESIDUAL`` and 0 without ``iono_scale``)."""
    if "iono_scale" not in receiver:
        return KLOBUCHAR_RESIDUAL, 0.0
    return iono_residual_fractions(receiver)


def broadcast_iono_delay(epoch: gnss_model.RawEpoch) -> np.ndarray:
    """The broadcast ionosphere delay of each satellite (m; 0 where the stream has none)."""
    if epoch.iono is None:
        return np.zeros(len(epoch.sv))
    return np.nan_to_num(epoch.iono)


def satellite_sigma(sis_m: float, iono_field: float, iono_delay: np.ndarray) -> np.ndarray:
    """Prior 1-sigma (m) of each satellite's range-error state: the signal-in-space error and
    the satellite's own share of the ionosphere field, sqrt(sis^2 + (s field I)^2), s =
    ``IONO_FIELD_OWN_SHARE``, I the broadcast delay (m)."""
    return np.hypot(sis_m, IONO_FIELD_OWN_SHARE * iono_field * iono_delay)


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


class RangeErrorStates:
    """The ionosphere-scale state and the per-satellite range-error channels of a tightly
    coupled filter, states ``first`` onwards (module docstring), from the receiver's datasheet
    block ``receiver``.

    The filter adds ``correction`` to each predicted pseudorange and ``fill_rows`` to its
    row, predicts the block with ``transition``, decays the estimates with ``predict`` and
    removes its corrections with ``feedback``; ``n`` states in all, ``prior_variance`` their
    initial variances (the channels get theirs when a satellite takes them)."""

    def __init__(self, first: int, receiver: Mapping[str, Any],
                 n_channels: int = RANGE_BIAS_CHANNELS):
        self.iono_common, self._field = iono_residual(receiver)
        self._sis = float(receiver.get("sis_error", SIS_ERROR_M))
        self.iono_sigma = math.hypot(self.iono_common, self._field)
        self._iono = first if self.iono_sigma > 0.0 else None
        n_iono = int(self._iono is not None)
        self.channels = RangeBiasChannels(first + n_iono, n_channels, RANGE_BIAS_TIME_S)
        self.first = first
        self.n = n_iono + n_channels
        self.estimate = np.zeros(self.n)
        self._tau = np.r_[np.full(n_iono, IONO_CORRELATION_TIME_S),
                          np.full(n_channels, RANGE_BIAS_TIME_S)]

    def prior_variance(self) -> np.ndarray:
        """Initial variances of the block's states: the ionosphere scale's; the channels' are
        set when a satellite takes them (``assign``)."""
        out = np.zeros(self.n)
        if self._iono is not None:
            out[0] = self.iono_sigma**2
        return out

    def satellite_sigma(self, epoch: gnss_model.RawEpoch) -> np.ndarray:
        """Prior 1-sigma of each satellite's channel (``satellite_sigma``), m."""
        return satellite_sigma(self._sis, self._field, broadcast_iono_delay(epoch))

    def carried_variance(self, epoch: gnss_model.RawEpoch) -> np.ndarray:
        """The share of each pseudorange's variance the states carry, m^2: the common
        ionosphere residual's (iono_common I)^2 and the satellite's channel's prior."""
        common = self.iono_common * broadcast_iono_delay(epoch) if self._iono is not None else 0.0
        return common**2 + self.satellite_sigma(epoch) ** 2

    def remaining_variance(self, epoch: gnss_model.RawEpoch, reported: np.ndarray
                           ) -> np.ndarray:
        """The reported pseudorange variances ``reported`` (m^2) less what the states carry,
        at least ``PSEUDORANGE_STD_FLOOR_M`` squared."""
        return np.maximum(reported - self.carried_variance(epoch), PSEUDORANGE_STD_FLOOR_M**2)

    def assign(self, epoch: gnss_model.RawEpoch, t: float, p: np.ndarray) -> np.ndarray:
        """State indices of the epoch's satellites' channels (-1 where none is free: leave the
        satellite out); a satellite new to its channel resets it (estimate zero, its prior
        variance in ``p``, in place)."""
        idx, new = self.channels.assign(epoch.sv, t, self.satellite_sigma(epoch), p)
        self.estimate[idx[new] - self.first] = 0.0
        return idx

    def correction(self, epoch: gnss_model.RawEpoch, idx: np.ndarray) -> np.ndarray:
        """What the estimates add to each predicted pseudorange of the satellites with the
        channels ``idx``, m."""
        out = self.estimate[idx - self.first].copy()
        if self._iono is not None:
            out += self.estimate[0] * broadcast_iono_delay(epoch)
        return out

    def fill_rows(self, h: np.ndarray, epoch: gnss_model.RawEpoch, idx: np.ndarray) -> None:
        """The pseudorange rows' entries of the block, in place: the broadcast delay on the
        ionosphere scale, 1 on each satellite's channel."""
        if self._iono is not None:
            h[:, self._iono] = broadcast_iono_delay(epoch)
        h[np.arange(len(idx)), idx] = 1.0

    def transition(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Diagonal transition factors and process variances of the block over ``dt`` (the
        ionosphere scale's as the channels', Brown & Hwang section 2.9)."""
        phi_ch, q_ch = self.channels.transition(dt)
        if self._iono is None:
            return phi_ch, q_ch
        phi = math.exp(-dt / IONO_CORRELATION_TIME_S)
        return (np.r_[phi, phi_ch], np.r_[self.iono_sigma**2 * (1.0 - phi * phi), q_ch])

    def predict(self, dt: float) -> None:
        """The estimates' mean decay over ``dt``."""
        self.estimate *= np.exp(-dt / self._tau)

    def feedback(self, dx: np.ndarray) -> None:
        """Remove the filter's estimated errors of the block (estimate minus truth)."""
        self.estimate -= dx
