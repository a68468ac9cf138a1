"""Verdicts of the Chan, Karamat and Park claims from their per-seed figures, by the documented
rule of ``simulator.reproduce.evidence`` (paired effect, bootstrap 95 % interval, one-sided sign
test in the paper's direction; ``verdict_word``), with the figures in words and the per-seed
values the verdict follows from; and the NEES figures of a solution.

A claim swept over a deciding condition is one claim per value: the value closest to the paper
is the paper claim, the others are checks (``sweep``), so the tally counts the paper's claim
once and the report still shows the word at every value.

Public names
------------
paired, one_sample, worst, untestable, sweep, nees_figures, effect_text.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence

import numpy as np
import pandas as pd

from simulator.reproduce import measures as m
from simulator.reproduce.evidence import (
    Evidence,
    one_sample_evidence,
    paired_evidence,
    verdict_word,
)
from simulator.reproduce.paper import Claim, Verdict
from simulator.scoring.consistency import consistency_scores

__all__ = ["effect_text", "nees_figures", "one_sample", "paired", "sweep", "untestable", "worst"]

Magnitude = Callable[[Evidence], "bool | None"]


def effect_text(ev: Evidence, kind: str, unit: str = "") -> str:
    """``ratio 0.62 (95 % CI 0.55-0.70), 9/10 seeds in the paper's direction, sign test
    p = 0.011`` (``difference`` in ``unit`` for a paired difference)."""
    u = f" {unit}" if unit and kind == "difference" else ""
    what = "ratio" if kind == "ratio" else "difference"
    missing = f", {ev.missing} seed(s) without a figure" if ev.missing else ""
    return (f"{what} {ev.effect:.3g}{u} (95 % CI {ev.ci_low:.3g} to {ev.ci_high:.3g}), "
            f"{ev.wins}/{ev.n} seeds in the paper's direction, sign test p = {ev.p_sign:.2g}"
            f"{missing}")


def _as_array(values: Iterable[float]) -> np.ndarray:
    return np.asarray(list(values), float)


def paired(a: Iterable[float], b: Iterable[float], *, names: tuple[str, str], unit: str = "",
           better: str = "lower", kind: str = "difference", magnitude: Magnitude | None = None,
           magnitude_text: str = "", analysis: str = "") -> Verdict:
    """The verdict on "``names[0]``'s figure is ``better`` than ``names[1]``'s" paired per
    seed (``kind``: the paired difference a - b or the ratio a / b); ``magnitude`` judges the
    paper's printed size on the evidence (None: the paper prints none), ``magnitude_text``
    says what it asks."""
    a, b = _as_array(a), _as_array(b)
    ev = paired_evidence(a, b, better=better, kind=kind)
    ok = magnitude(ev) if magnitude is not None and ev.n else None
    word = verdict_word(ev, magnitude_ok=ok)
    measured = (f"{names[0]} {m.spread_text(a, unit)}; {names[1]} {m.spread_text(b, unit)}; "
                f"{effect_text(ev, kind, unit)}")
    reason = _reason(word, ok, magnitude_text, analysis)
    return Verdict(word, measured, reason, evidence=ev,
                   per_seed={names[0]: a.tolist(), names[1]: b.tolist()})


def one_sample(values: Iterable[float], *, name: str, threshold: float, better: str,
               unit: str = "", magnitude: Magnitude | None = None, magnitude_text: str = "",
               analysis: str = "") -> Verdict:
    """The verdict on "``name`` is ``better`` (lower / higher) than ``threshold``" over seeds."""
    v = _as_array(values)
    ev = one_sample_evidence(v, threshold=threshold, better=better)
    ok = magnitude(ev) if magnitude is not None and ev.n else None
    word = verdict_word(ev, magnitude_ok=ok)
    side = "below" if better == "lower" else "above"
    measured = (f"{name} {m.spread_text(v, unit)}; {ev.wins}/{ev.n} seeds {side} {threshold:g}"
                f"{' ' + unit if unit else ''} (median minus threshold {ev.effect:.3g}, 95 % CI "
                f"{ev.ci_low:.3g} to {ev.ci_high:.3g}; sign test p = {ev.p_sign:.2g})")
    return Verdict(word, measured, _reason(word, ok, magnitude_text, analysis), evidence=ev,
                   per_seed={name: v.tolist()})


def _reason(word: str, magnitude_ok: bool | None, magnitude_text: str, analysis: str) -> str:
    if word == "shown":
        text = "the paper's direction holds significantly (sign test p < 0.05)"
        if magnitude_ok:
            text += f" and its magnitude too ({magnitude_text})"
        return text
    if word == "partly":
        text = (f"the direction holds significantly, the paper's magnitude does not "
                f"({magnitude_text})")
    else:
        text = "the paper's direction does not hold significantly over the seeds"
    return f"{text}. {analysis}".strip()


def untestable(key: str, text: str, paper_figure: str, reason: str,
               conditions: Sequence[str] = ()) -> Claim:
    """A paper claim the project cannot test, with the reason (no experiment, no judge)."""
    return Claim(key, text, paper_figure, list(conditions), judge=None, kind="paper",
                 untestable=reason)


def sweep(key: str, text: str, paper_figure: str, conditions: Sequence[str],
          values: Mapping[str, Callable[[Mapping[str, pd.DataFrame]], Verdict]], default: str,
          why_default: str, condition: str) -> list[Claim]:
    """One claim per value of a deciding ``condition``: ``values`` maps the value's words
    ("0.5 %") to its judge; ``default``, the value closest to the paper (``why_default``), is
    the paper claim, the other values are checks named ``KEY@VALUE``."""
    out = []
    for value, judge in values.items():
        is_default = value == default
        cond = [*conditions, f"{condition}: {value}" + (
            f" (the default: {why_default})" if is_default else
            f" (swept; the paper claim is judged at {default})")]
        out.append(Claim(key if is_default else f"{key}@{value}",
                         text if is_default else f"{text} [at {condition} {value}]",
                         paper_figure, cond, judge, kind="paper" if is_default else "check"))
    return out


def nees_figures(label: str, errors: pd.DataFrame) -> dict[str, float]:
    """``LABEL.nees_position`` (or ``LABEL.nees_horizontal`` for a 2-D solution): the time
    average of the position NEES over the drive after its start-up (expected 3, or 2;
    ``simulator.scoring.consistency``), NaN when the solution writes no sigma."""
    scores = consistency_scores(errors) or {}
    out = {}
    for block in ("position", "horizontal"):
        row = scores.get(block)
        if row is not None:
            out[f"{label}.nees_{block}"] = float(row["nees"])
    if not out:
        out[f"{label}.nees_position"] = math.nan
    return out


def worst(verdicts: Sequence[Verdict]) -> Verdict:
    """Several verdicts of one claim (its several printed values) as one: the worst word with
    its evidence, every figure and reason, every per-seed list."""
    order = {"shown": 0, "partly": 1, "not shown": 2}
    bad = max(verdicts, key=lambda v: order[v.status])
    per_seed = {k: v for verdict in verdicts for k, v in (verdict.per_seed or {}).items()}
    return Verdict(bad.status, " / ".join(v.measured for v in verdicts),
                   " / ".join(v.reason for v in verdicts), evidence=bad.evidence,
                   per_seed=per_seed)
