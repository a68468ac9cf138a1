"""Between-receiver and between-satellite differences of a rover's and a base station's GNSS
measurements: the one home of the double-difference bookkeeping of relative positioning.

A signal is keyed by its system, satellite and band (``signal_keys``): the same key in the
rover's and the base's epochs is the same signal. Single differences (rover minus base) of a
signal remove the satellite's clock and most of its orbit and atmosphere errors; the double
difference of two satellites of one system on one band removes the two receivers' clocks
(Misra & Enge 2011, section 7.2; Teunissen & Montenbruck 2017, Springer Handbook of GNSS,
chapter 26). With n single differences of a group and reference r, the m = n - 1 double
differences are ``D sd`` with D = [I, -1] rearranged (``difference_matrix``); if each single
difference has the independent variance s_i, the double differences have the covariance
``D diag(s) D^T``: s_i + s_r on the diagonal and s_r off it, the reference's share
(``double_difference_covariance``).

The reference of each group (system and band, ``group_of``; ``references``) is the signal of
highest priority (for a filter: a held ambiguity before an established one before a new one),
and of those the highest.

Public names
------------
signal_keys, group_of, references, difference_matrix, double_difference_covariance.
"""

from __future__ import annotations

import numpy as np

MHZ = 1e6


def signal_keys(system_code: np.ndarray, sv: np.ndarray, frequency_hz: np.ndarray
                ) -> np.ndarray:
    """Integer keys (system code x 10^7 + satellite x 10^4 + band in whole MHz) of signals;
    the band's MHz tells the bands of GPS, Galileo and BeiDou apart (1575, 1228, 1176, 1207,
    1561, 1269). Signals of one group (``group_of``) share the system and band."""
    return (np.asarray(system_code, dtype=np.int64) * 10_000_000
            + np.asarray(sv, dtype=np.int64) * 10_000
            + np.rint(np.asarray(frequency_hz, dtype=float) / MHZ).astype(np.int64))


def group_of(keys: np.ndarray) -> np.ndarray:
    """The group (system and band) of each key: the key without its satellite."""
    keys = np.asarray(keys, dtype=np.int64)
    return (keys // 10_000_000) * 10_000 + keys % 10_000


def references(groups: np.ndarray, elevation: np.ndarray, priority: np.ndarray | None = None
               ) -> np.ndarray:
    """For each signal (m,), the index of its group's reference: the signal of the group's
    highest ``priority`` (small integers; none: equal) and of those the highest elevation
    (rad)."""
    groups = np.asarray(groups)
    score = np.asarray(elevation, dtype=float)
    if priority is not None:
        score = score + 10.0 * np.asarray(priority, dtype=float)
    # by group, then by falling score (a stable sort: of equal scores the first signal)
    order = np.lexsort((-score, groups))
    first = np.r_[True, groups[order][1:] != groups[order][:-1]]
    ref = np.empty(len(groups), dtype=np.int64)
    ref[order] = order[first][np.cumsum(first) - 1]
    return ref


def difference_matrix(ref: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The double-difference operator of signals whose references are ``ref`` (m,):
    D (k, m) with a row +1 at each non-reference signal i and -1 at its reference, and the
    indices i of those rows (k = m minus the number of groups)."""
    ref = np.asarray(ref, dtype=np.int64)
    rows = np.flatnonzero(ref != np.arange(len(ref)))
    d = np.zeros((len(rows), len(ref)))
    d[np.arange(len(rows)), rows] = 1.0
    d[np.arange(len(rows)), ref[rows]] = -1.0
    return d, rows


def double_difference_covariance(d: np.ndarray, sd_variance: np.ndarray) -> np.ndarray:
    """Covariance D diag(s) D^T of double differences of independent single differences of
    variances ``sd_variance`` (m,)."""
    return (d * np.asarray(sd_variance, dtype=float)) @ d.T
