"""Paired comparison of a campaign's estimators: every estimator of a run scores on the same
dataset, so two estimators are compared seed by seed, which removes the spread between
seeds (the drive-long GNSS errors of one seed weigh on both).

Per sweep point, pair of labels (a, b) in the scenario's order and score of ``PAIRED_SCORES``
that both have: over the seeds where both runs succeeded and both have the score, the median
of the differences a - b with its 95 % percentile-bootstrap interval (Efron & Tibshirani
1993, *An Introduction to the Bootstrap*, chapter 13: ``BOOTSTRAP_RESAMPLES`` resamples of
the seeds with a fixed generator, so the same runs give the same interval), the number of
seeds where a is smaller, and the two-sided sign test's p-value of "a and b equally likely
smaller" (ties left out; Conover 1999, *Practical Nonparametric Statistics*, section 3.4).
Seeds where one of the two lacks the score (an outage end where a solution was silent) are
counted as ``missing``, never dropped silently.

Public names
------------
PAIRED_SCORES, BOOTSTRAP_RESAMPLES, median_interval, paired_comparisons.
"""

from __future__ import annotations

import math
from itertools import combinations
from typing import Any

import numpy as np
import pandas as pd

from simulator.campaign.worker import STATUS_OK

# the scores compared seed by seed: the drive's horizontal RMS error and the outages' mean
# end and largest horizontal errors (docs/scores.md)
PAIRED_SCORES = ("horizontal.rms", "outages.end_horizontal", "outages.max_horizontal")
BOOTSTRAP_RESAMPLES = 2000
_BOOTSTRAP_SEED = 0


def median_interval(values: np.ndarray, resamples: int = BOOTSTRAP_RESAMPLES,
                    seed: int = _BOOTSTRAP_SEED) -> tuple[float, float, float]:
    """The median of ``values`` and its 95 % percentile-bootstrap interval (Efron & Tibshirani
    1993, ch. 13: the 2.5 and 97.5 percentiles of the medians of ``resamples`` resamples drawn
    with the generator of ``seed``); NaN for no values. Also the reproduction's
    (``simulator.reproduce.evidence``)."""
    if not len(values):
        return math.nan, math.nan, math.nan
    rng = np.random.default_rng(seed)
    draws = rng.integers(0, len(values), size=(resamples, len(values)))
    medians = np.median(values[draws], axis=1)
    low, high = np.percentile(medians, [2.5, 97.5])
    return float(np.median(values)), float(low), float(high)


def _compare(a: pd.Series, b: pd.Series) -> dict[str, Any]:
    """The paired statistics of two labels' values indexed by seed (module docstring)."""
    both = a.index.intersection(b.index)
    a, b = a.loc[both].to_numpy(float), b.loc[both].to_numpy(float)
    finite = np.isfinite(a) & np.isfinite(b)
    d = a[finite] - b[finite]
    out: dict[str, Any] = {"seeds": int(d.size), "missing": int((~finite).sum()),
                           "median_difference": None, "interval": None,
                           "a_smaller": int((d < 0).sum()), "b_smaller": int((d > 0).sum()),
                           "sign_test_p": None}
    if d.size:
        median, low, high = median_interval(d)
        out["median_difference"] = median
        out["interval"] = [low, high]
    decided = out["a_smaller"] + out["b_smaller"]
    if decided:
        from scipy.stats import binomtest  # here: scipy.stats costs a second to import

        out["sign_test_p"] = float(binomtest(out["a_smaller"], decided, 0.5).pvalue)
    return out


def paired_comparisons(runs: pd.DataFrame, labels: list[str], points: list[dict[str, Any]]
                       ) -> list[dict[str, Any]]:
    """Every pair of ``labels`` at every sweep point ``points`` on each of ``PAIRED_SCORES``
    that the runs table has: ``{a, b, sweep, score, seeds, missing, median_difference (a -
    b), interval [low, high], a_smaller, b_smaller, sign_test_p}`` (None where no seed has
    both values)."""
    scores = [s for s in PAIRED_SCORES if s in runs.columns]
    out = []
    for point in points:
        at = np.ones(len(runs), dtype=bool)
        for key, value in point.items():
            at &= (runs[key] == value).to_numpy()
        ok = runs[at & (runs["status"] == STATUS_OK).to_numpy()]
        for a, b in combinations(labels, 2):
            rows_a = ok[ok["label"] == a].set_index("seed")
            rows_b = ok[ok["label"] == b].set_index("seed")
            for score in scores:
                stats = _compare(rows_a[score], rows_b[score])
                out.append({"a": a, "b": b, "sweep": dict(point), "score": score, **stats})
    return out
