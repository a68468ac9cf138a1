"""Recompute every verdict of a ``landnav reproduce`` run from its results.json, independently of
landnav's own evidence code (this script imports nothing from landnav).

For each claim with evidence it recomputes, from the per-seed values named by the evidence
(``a`` against ``b``, or ``a`` against ``threshold``):

* per seed whether the paper's direction holds (``better`` lower or higher), the ties and the
  seeds without a value (counted as seeds where the direction does not hold);
* the one-sided exact binomial sign test ``scipy.stats.binomtest(wins, n - ties, 0.5,
  alternative="greater")``;
* the median paired effect (difference a - b, ratio a / b, or the median value) and its own
  percentile-bootstrap 95 % interval (another generator and resample count than landnav's: the
  stored interval must agree within a tenth of the effects' range);
* whether the paper's magnitude (a bound low <= effect <= high) is met;
* the word: shown when p < alpha and the magnitude is met or absent, partly when p < alpha and
  it is not met, not shown otherwise;

and checks that the stored figures and word are those; a claim without evidence must be "not
shown" (or "not testable", with its reason and without evidence); the summary's tallies of paper
claims and checks (apart) must match the claims.

Usage::

    python tools/recompute_verdicts.py RUN/results.json

Prints one line per disagreement and a count; exit status 0 when every verdict is recomputed
identically, 1 otherwise, 2 when the file cannot be read.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np
from scipy.stats import binomtest

WORDS = ("shown", "partly", "not shown")
UNTESTABLE = "not testable"
RESAMPLES = 20_000
GENERATOR_SEED = 7


def _array(values: list) -> np.ndarray:
    return np.array([np.nan if v is None else v for v in values], float)


def _bootstrap(effects: np.ndarray) -> tuple[float, float]:
    rng = np.random.Generator(np.random.MT19937(GENERATOR_SEED))
    medians = np.median(rng.choice(effects, size=(RESAMPLES, len(effects)), replace=True),
                        axis=1)
    return float(np.quantile(medians, 0.025)), float(np.quantile(medians, 0.975))


def _close(x: float | None, y: float | None, tolerance: float) -> bool:
    if x is None or y is None:
        return x is None and y is None
    return abs(x - y) <= tolerance


def recompute(claim: dict, alpha: float) -> tuple[str, list[str]]:
    """The word the rule gives on ``claim``'s per-seed values and the disagreements found."""
    problems = []
    e = claim["evidence"]
    if claim["untestable"]:
        if e is not None or claim["kind"] != "paper":
            problems.append("an untestable claim has evidence or is not a paper claim")
        return UNTESTABLE, problems
    if e is None:
        return "not shown", problems
    a = _array(claim["per_seed"][e["a"]])
    if e["b"] is None:
        b = np.full(len(a), e["threshold"], float)
    else:
        b = _array(claim["per_seed"][e["b"]])
    if len(a) != len(b):
        return "not shown", [f"{e['a']} and {e['b']} differ in length"]
    present = np.isfinite(a) & np.isfinite(b)
    if e["kind"] == "ratio":
        present &= b != 0
    n = len(a)
    wins = int(sum(1 for x, y, ok in zip(a, b, present, strict=True)
                   if ok and (x < y if e["better"] == "lower" else x > y)))
    ties = int(sum(1 for x, y, ok in zip(a, b, present, strict=True) if ok and x == y))
    missing = int(n - present.sum())
    trials = n - ties
    p = binomtest(wins, trials, 0.5, alternative="greater").pvalue if trials else 1.0
    if e["kind"] == "difference":
        effects = a[present] - b[present]
    elif e["kind"] == "ratio":
        effects = a[present] / b[present]
    else:
        effects = a[present]
    effect = float(np.median(effects)) if len(effects) else None
    for name, mine in (("n", n), ("wins", wins), ("ties", ties), ("missing", missing)):
        if e[name] != mine:
            problems.append(f"{name} stored {e[name]}, recomputed {mine}")
    if not math.isclose(e["p_sign"], p, rel_tol=1e-9, abs_tol=1e-12):
        problems.append(f"p_sign stored {e['p_sign']:.6g}, recomputed {p:.6g}")
    if not _close(e["effect"], effect, 1e-9 * (1 + abs(effect or 0))):
        problems.append(f"effect stored {e['effect']}, recomputed {effect}")
    if len(effects) > 1:
        low, high = _bootstrap(effects)
        span = float(np.ptp(effects))
        if not (_close(e["ci_low"], low, 0.1 * span + 1e-12)
                and _close(e["ci_high"], high, 0.1 * span + 1e-12)):
            problems.append(f"interval stored {e['ci_low']}..{e['ci_high']}, recomputed "
                            f"{low:.6g}..{high:.6g}")
    magnitude = claim["magnitude"]
    ok = None
    if magnitude is not None:
        low = -math.inf if magnitude["low"] is None else magnitude["low"]
        high = math.inf if magnitude["high"] is None else magnitude["high"]
        ok = effect is not None and low <= effect <= high
    if not p < alpha:
        word = "not shown"
    else:
        word = "partly" if ok is False else "shown"
    return word, problems


def check(document: dict) -> list[str]:
    """Every disagreement between results.json and the recomputation, as lines."""
    alpha = document["rule"]["alpha"]
    out = []
    tallies: dict[str, dict[str, int]] = {"paper": {}, "check": {}, "variants": {}}
    for claim_id, claim in document["claims"].items():
        if claim["kind"] not in ("paper", "check"):
            out.append(f"{claim_id}: kind {claim['kind']!r}")
        if not isinstance(claim["conditions"], list):
            out.append(f"{claim_id}: conditions is not a list")
        word, problems = recompute(claim, alpha)
        out += [f"{claim_id}: {p}" for p in problems]
        if word != claim["verdict"]:
            out.append(f"{claim_id}: verdict stored {claim['verdict']!r}, the rule gives "
                       f"{word!r}")
        group = "variants" if claim["variant_of"] else claim["kind"]
        tallies[group][claim["verdict"]] = tallies[group].get(claim["verdict"], 0) + 1
    for group, counts in tallies.items():
        stored = {w: c for w, c in document["summary"][group].items() if c}
        if stored != counts:
            out.append(f"summary {group}: stored {stored}, counted {counts}")
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("results", type=Path, help="results.json of a landnav reproduce run")
    args = parser.parse_args(argv)
    try:
        document = json.loads(args.results.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        print(f"{args.results}: cannot be read: {exc}", file=sys.stderr)
        return 2
    problems = check(document)
    for line in problems:
        print(line)
    claims = document["claims"]
    judged = sum(1 for c in claims.values() if c["evidence"] is not None)
    print(f"{len(claims)} claims, {judged} with evidence recomputed: "
          f"{len(problems)} disagreement(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
