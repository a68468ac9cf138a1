"""The evidence behind a reproduction verdict: per-seed values, the paired effect, its bootstrap
interval, a sign test in the paper's direction, and the one word that follows from them.

A claim compares, seed by seed, what the paper says is better (``a``) with what it says is
worse (``b``), or one figure with a fixed value (a paper's threshold, "no effect"):

* per seed the **direction** holds when ``a`` is below ``b`` (``better="lower"``) or above it
  (``better="higher"``); a seed where the two are equal is a **tie**; a seed where either value
  is missing (NaN or None: a failed run, a filter silent at the instant) is **missing** and
  counts as a seed where the direction does *not* hold (never dropped);
* the **effect** is the median over seeds of the paired effect, ``a - b`` (``kind=
  "difference"``, in the figures' unit) or ``a / b`` (``kind="ratio"``, no unit); for a claim
  against a fixed value it is the median of the values (``effect_kind="value"``);
* its **95 % interval** is the percentile bootstrap of that median: the seeds' paired effects
  resampled with replacement ``BOOTSTRAP_RESAMPLES`` times with the fixed generator seed
  ``BOOTSTRAP_SEED`` (the same values always give the same interval), the 2.5th and 97.5th
  percentiles of the resampled medians;
* **p_sign** is the one-sided exact binomial sign test in the paper's direction: under "no
  effect" each seed is as likely to go either way, so p = P(X >= wins) for X ~ Binomial(n -
  ties, 1/2), ties dropped (and counted), missing seeds counted as seeds against the direction.

The rule (``verdict_word``), the same for every claim and every paper:

* **shown**: the direction holds significantly (p_sign < 0.05) and, where the paper prints a
  magnitude, the effect meets it (``magnitude_ok`` True; None when the paper prints none);
* **partly**: the direction holds significantly but the printed magnitude is not met;
* **not shown**: otherwise (the direction is not significant; with three seeds nothing can be:
  the smallest one-sided p of three seeds is 1/8).

A paper's magnitude is a bound on the effect (``Magnitude``: ``low <= effect <= high``), so
the word follows from the per-seed values alone and an independent script can recompute it
(``tools/recompute_verdicts.py``).

Public names
------------
Evidence, Magnitude, Better, paired_evidence, one_sample_evidence, verdict_word, evidence_text,
ALPHA, BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from simulator.campaign.paired import median_interval

__all__ = ["ALPHA", "BOOTSTRAP_RESAMPLES", "BOOTSTRAP_SEED", "Better", "Evidence", "Magnitude",
           "evidence_text", "one_sample_evidence", "paired_evidence", "verdict_word"]

ALPHA = 0.05  # significance of the one-sided sign test
BOOTSTRAP_RESAMPLES = 10_000  # resamples of the median's percentile bootstrap
BOOTSTRAP_SEED = 20_060_402  # generator seed of the bootstrap: reproducible intervals

Better = Literal["lower", "higher"]


@dataclass(frozen=True)
class Evidence:
    """What the per-seed values say about a claim's direction (module docstring).

    ``n`` seeds in all (missing ones included), ``wins`` where the paper's direction holds,
    ``ties`` where the two are equal (dropped from the sign test), ``missing`` without a value
    (counted against the direction). ``effect`` is the median paired effect (``effect_kind``
    "difference" in ``unit``, "ratio" without unit, or "value" in ``unit`` against
    ``threshold``), ``ci_low``/``ci_high`` its bootstrap 95 % interval (NaN without values),
    ``p_sign`` the one-sided sign test's p-value."""

    n: int
    wins: int
    ties: int
    missing: int
    effect: float
    effect_kind: Literal["difference", "ratio", "value"]
    unit: str
    ci_low: float
    ci_high: float
    p_sign: float
    better: Better
    threshold: float | None = None  # the fixed value of a one-sample claim

    @property
    def significant(self) -> bool:
        """The direction holds with p_sign < ``ALPHA``."""
        return self.p_sign < ALPHA


@dataclass(frozen=True)
class Magnitude:
    """A magnitude the paper prints, as a bound on the effect: met when ``low <= effect <=
    high`` (either side open). ``text`` says it in words ("the paper's cut of 52.6 %, within a
    factor of two")."""

    text: str
    low: float = -math.inf
    high: float = math.inf

    def holds(self, evidence: Evidence) -> bool:
        """The evidence's effect lies within the bound (False without an effect)."""
        return bool(np.isfinite(evidence.effect) and self.low <= evidence.effect <= self.high)


def _values(values: Sequence[float | None] | np.ndarray) -> np.ndarray:
    return np.array([math.nan if v is None else v for v in values], float)


def _median_interval(effects: np.ndarray) -> tuple[float, float, float]:
    """Median of ``effects`` and its percentile-bootstrap 95 % interval (``median_interval``
    with the reproduction's resamples and seed)."""
    return median_interval(effects, BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED)


def _sign_p(wins: int, trials: int) -> float:
    """One-sided exact binomial sign test: P(X >= wins), X ~ Binomial(trials, 1/2)."""
    if trials == 0:
        return 1.0
    from scipy.stats import binomtest  # here: scipy.stats costs more than a second to import

    return float(binomtest(wins, trials, 0.5, alternative="greater").pvalue)


def _evidence(direction: np.ndarray, tie: np.ndarray, present: np.ndarray, effects: np.ndarray,
              kind: str, unit: str, better: Better, threshold: float | None) -> Evidence:
    n = len(present)
    wins = int(np.sum(direction & present))
    ties = int(np.sum(tie & present))
    missing = int(np.sum(~present))
    effect, low, high = _median_interval(effects)
    return Evidence(n, wins, ties, missing, effect, kind, unit, low, high,
                    _sign_p(wins, n - ties), better, threshold)


def _check(better: str) -> None:
    if better not in ("lower", "higher"):
        raise ValueError(f"better must be 'lower' or 'higher', got {better!r}")


def paired_evidence(a: Sequence[float | None] | np.ndarray,
                    b: Sequence[float | None] | np.ndarray, *, better: Better,
                    kind: Literal["difference", "ratio"], unit: str = "") -> Evidence:
    """The evidence that ``a`` is better than ``b`` (``better``: lower or higher), paired by
    position (seed): per seed the effect ``a - b`` or ``a / b`` (``kind``; a ratio's ``unit``
    is ignored). A seed where a ratio's ``b`` is 0 has no ratio and is missing."""
    _check(better)
    if kind not in ("difference", "ratio"):
        raise ValueError(f"kind must be 'difference' or 'ratio', got {kind!r}")
    a, b = _values(a), _values(b)
    if a.shape != b.shape:
        raise ValueError(f"a and b are paired per seed: {len(a)} against {len(b)} values")
    present = np.isfinite(a) & np.isfinite(b) & ((b != 0) if kind == "ratio" else True)
    with np.errstate(divide="ignore", invalid="ignore"):
        effect = a - b if kind == "difference" else a / b
    direction = a < b if better == "lower" else a > b
    return _evidence(direction, a == b, present, effect[present], kind,
                     unit if kind == "difference" else "", better, None)


def one_sample_evidence(values: Sequence[float | None] | np.ndarray, *, threshold: float,
                        better: Better, unit: str = "") -> Evidence:
    """The evidence that ``values`` are better than the fixed ``threshold`` (below it for
    ``better="lower"``); the effect is the median value."""
    _check(better)
    v = _values(values)
    present = np.isfinite(v)
    direction = v < threshold if better == "lower" else v > threshold
    return _evidence(direction, v == threshold, present, v[present], "value", unit, better,
                     float(threshold))


def verdict_word(evidence: Evidence | None, *, magnitude_ok: bool | None,
                 alpha: float = ALPHA) -> Literal["shown", "partly", "not shown"]:
    """The rule (module docstring): shown when the direction holds significantly (p_sign <
    ``alpha``) and the magnitude is met or not printed (None); partly when it holds
    significantly and the magnitude is not met; not shown otherwise (and without evidence)."""
    if evidence is None or not evidence.p_sign < alpha:
        return "not shown"
    return "partly" if magnitude_ok is False else "shown"


def _number(x: float) -> str:
    return f"{x:.3g}" if np.isfinite(x) else "none"


def evidence_text(evidence: Evidence, who: str = "") -> str:
    """The evidence in words: ``direction held in 9 of 10 seeds (1 tie, none missing); median
    paired difference -1.2 m, 95 % bootstrap interval -2.0 to -0.4 m; one-sided sign test p =
    0.011``."""
    e = evidence
    unit = f" {e.unit}" if e.unit else ""
    what = {"difference": "median paired difference", "ratio": "median paired ratio",
            "value": "median value"}[e.effect_kind]
    against = (f" (paper's direction: {e.better} than {_number(e.threshold)}{unit})"
               if e.threshold is not None else "")
    extras = [f"{e.ties} tie{'s' * (e.ties != 1)}" if e.ties else "no tie",
              f"{e.missing} without a value" if e.missing else "none missing"]
    head = f"{who}: " if who else ""
    return (f"{head}direction held in {e.wins} of {e.n} seeds ({', '.join(extras)}){against}; "
            f"{what} {_number(e.effect)}{unit}, 95 % bootstrap interval {_number(e.ci_low)} "
            f"to {_number(e.ci_high)}{unit}; one-sided sign test p = {e.p_sign:.3g}")
