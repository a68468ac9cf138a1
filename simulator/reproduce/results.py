"""``results.json``: every claim of a reproduction run with what its verdict came from, for a
reader or a script to check (``tools/recompute_verdicts.py`` recomputes every word from it).

Layout::

    {"software": "landnav 0.1.0, commit abc1234, Python 3.12.3", "quick": false,
     "seeds": [1, ..., 10],
     "rule": {"alpha": 0.05, "bootstrap_resamples": 10000, "bootstrap_seed": ...,
              "text": "shown when ..."},
     "summary": {"paper": {"shown": 9, "partly": 2, "not shown": 5, "not testable": 3},
                 "check": {...}, "variants": {...},
                 "per_paper": {"cho2006": {"paper": {...}, "check": {...}}, ...}},
     "claims": {"cho2006.situation1_scale_factor": {
         "paper": "cho2006", "claim": "situation1_scale_factor", "kind": "paper",
         "variant_of": "", "variant": "", "statement": "...", "paper_figure": "Fig. 7(d) ...",
         "conditions": ["...", "..."], "untestable": "",
         "per_seed": {"spkf": [41.0, null, ...], "ekf": [...]},
         "evidence": {"a": "spkf", "b": "ekf", "better": "lower", "kind": "difference",
                      "unit": "s", "threshold": null, "n": 10, "wins": 8, "ties": 0,
                      "missing": 1, "effect": -9.5, "ci_low": -14.0, "ci_high": -2.0,
                      "p_sign": 0.0547},
         "magnitude": {"text": "...", "low": null, "high": 0.0} or null,
         "verdict": "not shown", "measured": "...", "reason": "..."}}}

Non-finite numbers are written as null (JSON has no NaN or infinity): a per-seed value without a
figure, an open side of a magnitude bound. A claim without evidence has "evidence": null (only
"not shown" or "not testable" follow from none).

Public names
------------
RESULTS_FILE, UNTESTABLE, results_document, write_results.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from simulator.reproduce import evidence as ev
from simulator.reproduce.paper import STATUSES, Claim, Verdict

if TYPE_CHECKING:  # the runner imports this module; its types only annotate here
    from simulator.reproduce.runner import PaperResult, Settings

__all__ = ["RESULTS_FILE", "UNTESTABLE", "results_document", "write_results"]

RESULTS_FILE = "results.json"
UNTESTABLE = "not testable"  # the word of a paper claim landnav cannot test
RULE_TEXT = ("per seed the paper's direction holds or not (a missing value counts as not); "
             "p_sign is the one-sided exact binomial sign test in the paper's direction with "
             "ties dropped; the effect is the median paired difference or ratio (or the median "
             "value against a fixed threshold) with a percentile-bootstrap 95 % interval; "
             "shown when p_sign < alpha and the paper's printed magnitude (a bound on the "
             "effect) is met or none is printed; partly when p_sign < alpha and the magnitude "
             "is not met; not shown otherwise")


def _number(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


def _evidence(verdict: Verdict) -> dict | None:
    e = verdict.evidence
    if e is None:
        return None
    compared = verdict.compared
    return {"a": compared[0], "b": compared[1] if len(compared) > 1 else None,
            "better": e.better, "kind": e.effect_kind, "unit": e.unit,
            "threshold": _number(e.threshold), "n": e.n, "wins": e.wins, "ties": e.ties,
            "missing": e.missing, "effect": _number(e.effect), "ci_low": _number(e.ci_low),
            "ci_high": _number(e.ci_high), "p_sign": e.p_sign}


def _claim(paper: str, claim: Claim, verdict: Verdict | None) -> dict:
    out = {"paper": paper, "claim": claim.key, "kind": claim.kind,
           "variant_of": claim.variant_of, "variant": claim.variant, "statement": claim.text,
           "paper_figure": claim.paper_figure, "conditions": list(claim.conditions),
           "untestable": claim.untestable}
    if verdict is None or claim.untestable:
        return {**out, "per_seed": {} if verdict is None else {
                    k: [_number(x) for x in v] for k, v in verdict.per_seed.items()},
                "evidence": None, "magnitude": None, "verdict": UNTESTABLE,
                "measured": "" if verdict is None else verdict.measured,
                "reason": claim.untestable}
    magnitude = verdict.magnitude
    return {**out,
            "per_seed": {k: [_number(x) for x in v] for k, v in verdict.per_seed.items()},
            "evidence": _evidence(verdict),
            "magnitude": None if magnitude is None else {
                "text": magnitude.text, "low": _number(magnitude.low),
                "high": _number(magnitude.high)},
            "verdict": verdict.status, "measured": verdict.measured, "reason": verdict.reason}


def _tally(claims: Sequence[dict]) -> dict[str, int]:
    return {word: sum(c["verdict"] == word for c in claims) for word in (*STATUSES, UNTESTABLE)}


def results_document(results: Sequence[PaperResult], settings: Settings) -> dict:
    """The content of results.json (module docstring)."""
    claims = {f"{r.paper.key}.{c.key}": _claim(r.paper.key, c, r.verdicts.get(c.key))
              for r in results for c in r.paper.claims}
    rows = list(claims.values())
    main = [c for c in rows if not c["variant_of"]]
    summary = {"paper": _tally([c for c in main if c["kind"] == "paper"]),
               "check": _tally([c for c in main if c["kind"] == "check"]),
               "variants": _tally([c for c in rows if c["variant_of"]]),
               "per_paper": {r.paper.key: {kind: _tally([c for c in main if c["paper"] ==
                                                         r.paper.key and c["kind"] == kind])
                                           for kind in ("paper", "check")}
                             for r in results}}
    return {"software": settings.version, "quick": settings.quick,
            "seeds": list(settings.seeds),
            "rule": {"alpha": ev.ALPHA, "bootstrap_resamples": ev.BOOTSTRAP_RESAMPLES,
                     "bootstrap_seed": ev.BOOTSTRAP_SEED, "text": RULE_TEXT},
            "summary": summary, "claims": claims}


def write_results(path: Path, results: Sequence[PaperResult], settings: Settings) -> Path:
    """Write results.json (strict JSON: no NaN) to ``path``; the path."""
    path.write_text(json.dumps(results_document(results, settings), indent=1,
                               allow_nan=False) + "\n", encoding="utf-8")
    return path
