"""Verdicts of the Chan, Karamat and Park claims from their per-seed figures by the documented
rule (``simulator.reproduce.evidence``: paired effect, bootstrap 95 % interval, one-sided sign
test in the paper's direction, ``verdict_word``), with the figures in words and the per-seed
values the verdict follows from; the NEES figures of a solution; and the claim shapes these
papers share (a sweep over a deciding condition, an untestable claim).

A claim swept over a deciding condition is one claim per value (``sweep``): the value closest
to the paper is the claim itself, the others name it in ``variant_of``, so the summary counts
the paper's claim once and the report shows the word at every value.

Public names
------------
paired, one_sample, worst, untestable, sweep, around, nees_figures.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence

import numpy as np
import pandas as pd

from simulator.reproduce import measures as m
from simulator.reproduce.evidence import (
    Magnitude,
    evidence_text,
    one_sample_evidence,
    paired_evidence,
    verdict_word,
)
from simulator.reproduce.paper import Claim, Verdict
from simulator.scoring.consistency import consistency_scores

__all__ = ["around", "nees_figures", "one_sample", "paired", "sweep", "untestable", "worst"]


def _seeds(values: Iterable[float]) -> tuple[np.ndarray, list[float | None]]:
    v = np.asarray(list(values), float)
    return v, [float(x) if np.isfinite(x) else None for x in v]


def around(text: str, value: float, tolerance: float) -> Magnitude:
    """A printed magnitude met when the effect lies within ``tolerance`` of ``value``."""
    return Magnitude(text, value - tolerance, value + tolerance)


def _reason(word: str, magnitude: Magnitude | None, analysis: str) -> str:
    if word == "shown":
        text = "the paper's direction holds significantly (one-sided sign test p < 0.05)"
        return text + (f" and its magnitude too ({magnitude.text})" if magnitude else "")
    if word == "partly":
        text = (f"the direction holds significantly, the paper's magnitude does not "
                f"({magnitude.text if magnitude else ''})")
    else:
        text = "the paper's direction does not hold significantly over the seeds"
    return f"{text}. {analysis}".strip()


def paired(a: Iterable[float], b: Iterable[float], *, names: tuple[str, str], unit: str = "",
           better: str = "lower", kind: str = "difference", magnitude: Magnitude | None = None,
           analysis: str = "") -> Verdict:
    """The verdict on "``names[0]``'s figure is ``better`` than ``names[1]``'s", paired per
    seed (``kind``: the difference a - b or the ratio a / b); ``magnitude``: the paper's
    printed size as a bound on the median effect (None: the paper prints none)."""
    a, a_seeds = _seeds(a)
    b, b_seeds = _seeds(b)
    ev = paired_evidence(a, b, better=better, kind=kind, unit=unit)
    word = verdict_word(ev, magnitude_ok=magnitude.holds(ev) if magnitude else None)
    measured = (f"{names[0]} {m.spread_text(a, unit)}; {names[1]} {m.spread_text(b, unit)}; "
                f"{evidence_text(ev)}")
    return Verdict(word, measured, _reason(word, magnitude, analysis), evidence=ev,
                   per_seed={names[0]: a_seeds, names[1]: b_seeds}, magnitude=magnitude,
                   compared=names)


def one_sample(values: Iterable[float], *, name: str, threshold: float, better: str,
               unit: str = "", magnitude: Magnitude | None = None,
               analysis: str = "") -> Verdict:
    """The verdict on "``name`` is ``better`` (lower / higher) than ``threshold``" over seeds;
    ``magnitude`` bounds the median value."""
    v, v_seeds = _seeds(values)
    ev = one_sample_evidence(v, threshold=threshold, better=better, unit=unit)
    word = verdict_word(ev, magnitude_ok=magnitude.holds(ev) if magnitude else None)
    measured = f"{name} {m.spread_text(v, unit)}; {evidence_text(ev)}"
    return Verdict(word, measured, _reason(word, magnitude, analysis), evidence=ev,
                   per_seed={name: v_seeds}, magnitude=magnitude, compared=(name,))


_ORDER = {"shown": 0, "partly": 1, "not shown": 2}


def worst(verdicts: Sequence[Verdict]) -> Verdict:
    """Several verdicts of one claim (several printed values, several baselines) as one: the
    worst word with its evidence, every figure and reason, every per-seed list (named by the
    part they come from when two parts share a name)."""
    bad = max(range(len(verdicts)), key=lambda k: _ORDER[verdicts[k].status])
    per_seed: dict[str, list[float | None]] = {}
    compared: tuple[str, ...] = ()
    for k, verdict in enumerate(verdicts):
        rename = {name: name if name not in per_seed else f"{name} ({k + 1})"
                  for name in verdict.per_seed}
        per_seed.update({rename[name]: values for name, values in verdict.per_seed.items()})
        if k == bad:
            compared = tuple(rename[name] for name in verdict.compared)
    chosen = verdicts[bad]
    return Verdict(chosen.status, " / ".join(v.measured for v in verdicts),
                   " / ".join(v.reason for v in verdicts), evidence=chosen.evidence,
                   per_seed=per_seed, magnitude=chosen.magnitude, compared=compared)


def untestable(key: str, text: str, paper_figure: str, reason: str,
               conditions: Sequence[str] = ()) -> Claim:
    """A paper claim the project cannot test, with the reason."""
    return Claim(key, text, paper_figure, tuple(conditions), untestable=reason)


def sweep(key: str, text: str, paper_figure: str, conditions: Sequence[str],
          values: Mapping[str, Callable[[Mapping[str, pd.DataFrame]], Verdict]], default: str,
          why_default: str, condition: str, kind: str = "paper",
          reads: Mapping[str, Sequence[str]] | None = None) -> list[Claim]:
    """One claim per value of a deciding ``condition``: ``values`` maps the value in words
    ("0.5 %") to its judge, ``reads`` to the experiments that judge reads (default: every
    experiment of the paper, ``Claim.experiments``); ``default``, the value closest to the
    paper (``why_default``), is the claim ``key``, the other values are its variants
    ``KEY@N``."""
    out = []
    for n, (value, judge) in enumerate(values.items()):
        experiments = tuple((reads or {}).get(value, ()))
        if value == default:
            out.insert(0, Claim(key, text, paper_figure, (
                *conditions, f"{condition}: {value} (the default: {why_default})"), judge,
                kind=kind, experiments=experiments))
        else:
            out.append(Claim(f"{key}@{n}", text, paper_figure, (
                *conditions, f"{condition}: {value} (swept; the claim itself is judged at "
                             f"{default})"), judge, kind=kind, variant_of=key,
                variant=f"{condition} {value}", experiments=experiments))
    return out


def nees_figures(label: str, errors: pd.DataFrame) -> dict[str, float]:
    """``LABEL.nees_position`` (or ``LABEL.nees_horizontal`` for a 2-D solution): the time
    average of the position NEES over the drive after its start-up (expected 3, or 2;
    ``simulator.scoring.consistency``), NaN when the solution writes no sigma."""
    scores = consistency_scores(errors) or {}
    out = {f"{label}.nees_{block}": float(scores[block]["nees"])
           for block in ("position", "horizontal") if scores.get(block) is not None}
    return out or {f"{label}.nees_position": math.nan}
