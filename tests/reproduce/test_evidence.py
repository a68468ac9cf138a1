"""The evidence behind a verdict (``simulator.reproduce.evidence``) against values worked out by
hand: the exact binomial sign test, ties and missing seeds, the median paired effect and its
bootstrap interval, and the rule's three words."""

from __future__ import annotations

import math

import numpy as np
import pytest

from simulator.reproduce import evidence as ev


def test_sign_test_is_the_exact_binomial_tail():
    """9 of 10 seeds in the direction: p = (C(10,9) + C(10,10)) / 2^10 = 11/1024."""
    a = [1.0] * 9 + [3.0]
    b = [2.0] * 10
    e = ev.paired_evidence(a, b, better="lower", kind="difference", unit="m")
    assert (e.n, e.wins, e.ties, e.missing) == (10, 9, 0, 0)
    assert e.p_sign == pytest.approx(11 / 1024, rel=1e-12)
    assert e.effect == -1.0 and e.effect_kind == "difference" and e.unit == "m"
    assert e.ci_low == e.ci_high == -1.0  # nine of ten effects are -1: every median is -1


def test_ties_are_dropped_and_missing_seeds_count_against_the_direction():
    """Seeds: 6 wins, 2 ties, 2 missing: the test is 6 of 8 trials (the two missing ones
    losses): p = (C(8,6) + C(8,7) + C(8,8)) / 2^8 = 37/256."""
    a = [1.0] * 6 + [2.0, 2.0, np.nan, None]
    b = [2.0] * 8 + [2.0, 2.0]
    e = ev.paired_evidence(a, b, better="lower", kind="difference")
    assert (e.n, e.wins, e.ties, e.missing) == (10, 6, 2, 2)
    assert e.p_sign == pytest.approx(37 / 256, rel=1e-12)


def test_ratio_and_higher_direction():
    a = np.array([2.0, 3.0, 4.0, 6.0, 10.0])
    b = np.array([1.0, 1.0, 2.0, 2.0, 5.0])
    e = ev.paired_evidence(a, b, better="higher", kind="ratio", unit="m")
    assert e.effect == 2.0 and e.unit == "" and e.wins == 5
    assert e.p_sign == pytest.approx(1 / 32)
    assert e.ci_low <= e.effect <= e.ci_high
    # a ratio without a denominator is a missing seed
    e0 = ev.paired_evidence([1.0, 2.0], [0.0, 1.0], better="higher", kind="ratio")
    assert e0.missing == 1 and e0.wins == 1


def test_bootstrap_interval_is_reproducible_and_covers_the_median():
    rng = np.random.default_rng(1)
    a, b = rng.normal(0, 1, 20), rng.normal(0.5, 1, 20)
    first = ev.paired_evidence(a, b, better="lower", kind="difference")
    again = ev.paired_evidence(a, b, better="lower", kind="difference")
    assert first == again
    assert first.ci_low < first.effect < first.ci_high
    assert first.effect == pytest.approx(np.median(a - b))


def test_one_sample_against_a_threshold():
    e = ev.one_sample_evidence([10.0, 20.0, 30.0, 40.0, 50.0, None], threshold=3.0,
                               better="higher", unit="deg")
    assert (e.wins, e.missing, e.threshold) == (5, 1, 3.0)
    assert e.p_sign == pytest.approx(7 / 64)  # 5 or 6 of 6
    assert e.effect == 30.0 and e.effect_kind == "value"


@pytest.mark.parametrize("wins, magnitude_ok, word", [
    (10, None, "shown"), (10, True, "shown"), (10, False, "partly"),
    (8, None, "not shown"), (8, False, "not shown"), (5, True, "not shown")])
def test_the_rule(wins, magnitude_ok, word):
    e = ev.paired_evidence([1.0] * wins + [3.0] * (10 - wins), [2.0] * 10, better="lower",
                           kind="difference")
    assert ev.verdict_word(e, magnitude_ok=magnitude_ok) == word
    assert ev.verdict_word(None, magnitude_ok=None) == "not shown"


def test_magnitude_bounds_the_effect_and_the_text_has_every_word():
    e = ev.paired_evidence([1.0] * 10, [2.0] * 10, better="lower", kind="difference", unit="m")
    assert ev.Magnitude("at least 0.5 m lower", high=-0.5).holds(e)
    assert not ev.Magnitude("at least 2 m lower", high=-2.0).holds(e)
    text = ev.evidence_text(e)
    assert "direction held in 10 of 10 seeds" in text
    assert "95 % bootstrap interval -1 to -1 m" in text and "sign test p = 0.000977" in text
    assert math.isnan(ev.paired_evidence([np.nan], [1.0], better="lower",
                                         kind="difference").effect)


def test_bad_arguments_are_refused():
    with pytest.raises(ValueError, match="better"):
        ev.paired_evidence([1.0], [2.0], better="smaller", kind="difference")
    with pytest.raises(ValueError, match="paired"):
        ev.paired_evidence([1.0], [2.0, 3.0], better="lower", kind="difference")
