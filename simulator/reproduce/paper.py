"""What a paper's reproduction is made of: experiments (a scenario run over seeds, every
estimator entry replaying the same dataset of a seed), the figures each experiment measures per
seed, and the claims judged from those figures.

A paper module (``simulator/reproduce/cho2006.py``, ...) builds one ``Paper`` at import time and
names it ``PAPER``; ``simulator.reproduce.papers`` lists the modules. The runner
(``simulator.reproduce.runner``) runs every experiment's seeds, collects the figures into one
table per experiment (index seed, one column per figure name) and hands the tables to each
claim's ``judge``.

The experiments run the scenarios shipped in the repository's ``scenarios/`` folder
(``scenario_path``): the reproduction needs a checkout (installed with ``pip install -e``), as
the README's commands make; an installation without the folder is told so.

Public names
------------
Figures, Experiment, Verdict, Claim, ClaimKind, Paper, STATUSES, SCENARIO_DIR, scenario_path.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import pandas as pd

from simulator.dataset.io import Dataset
from simulator.errors import InputError, Problem
from simulator.reproduce.evidence import Evidence, Magnitude

if TYPE_CHECKING:  # annotations only: the paper modules import no plotting library
    from matplotlib.figure import Figure

__all__ = ["SCENARIO_DIR", "STATUSES", "Claim", "ClaimKind", "Experiment", "Figures", "Paper",
           "Verdict", "scenario_path"]

SCENARIO_DIR = Path(__file__).resolve().parents[2] / "scenarios"


def scenario_path(name: str) -> Path:
    """The shipped scenario ``name`` (a file of the checkout's ``scenarios/``).

    Raises
    ------
    InputError
        The installation has no such file (a wheel install carries no scenarios).
    """
    path = SCENARIO_DIR / name
    if not path.is_file():
        raise InputError([Problem(str(path), None, "", (
            "the paper reproductions run the scenarios shipped in a landnav checkout and this "
            "installation has none; clone the repository and install it with "
            "'pip install -e .' (README), then run landnav reproduce from there"))])
    return path

Figures = dict[str, float]  # one seed's figures, flat: {"tc_ukf_nhc.w0.mean_3d_m": 12.3, ...}
STATUSES = ("shown", "partly", "not shown")


@dataclass(frozen=True)
class Experiment:
    """One scenario run over seeds; each seed's dataset is shared by all entries.

    ``measure`` is a module-level function (picklable for process and Dask workers) of the
    dataset and each label's solution table, returning that seed's figures."""

    key: str                        # unique within the paper, e.g. "partial_outages"
    scenario: str                   # file name in scenarios/, e.g. "chan_partial_outages.yaml"
    entries: Mapping[str, Mapping]  # label -> estimator entry {"name": ..., "config": {...}}
    measure: Callable[[Dataset, Mapping[str, pd.DataFrame]], Figures]
    overrides: tuple[str, ...] = ()        # --set overrides of the full run
    quick_overrides: tuple[str, ...] = ()  # shortened drive for --quick (added to overrides)
    # the time histories of the run's first seed for the paper's figures: a module-level
    # function of the dataset and the solutions giving a table with a "t" column (s)
    history: Callable[[Dataset, Mapping[str, pd.DataFrame]], pd.DataFrame] | None = None
    # seeds of a run without --quick when more than the run's: where a verdict sits at an edge
    full_runs: int | None = None
    # the labels --quick replays (empty: every entry); the others are read only by claims left
    # to the full run (``Claim.full_only``)
    quick_entries: tuple[str, ...] = ()


@dataclass(frozen=True)
class Verdict:
    """The one word on a claim, landnav's figure(s) in words, why, and the evidence it follows
    from (``simulator.reproduce.evidence``).

    ``per_seed`` holds the named per-seed values the verdict came from (one list per name, in
    seed order, None where a seed has no value). When ``evidence`` is given, ``compared`` names
    the entries of ``per_seed`` it was computed from: ``(a, b)`` of a paired claim (``a`` the
    side the paper calls better), ``(values,)`` of a claim against a fixed value; by default the
    first one or two entries. ``magnitude`` is the paper's printed magnitude as a bound on the
    effect (None when the paper prints none). ``status`` must be the word the documented rule
    gives (``evidence.verdict_word``): the runner refuses any other."""

    status: Literal["shown", "partly", "not shown"]
    measured: str  # "median 17.8 % (IQR 12-25), 7/10 seeds"
    reason: str    # why this word; for partly / not shown the analysis in a sentence or two
    evidence: Evidence | None = None
    per_seed: Mapping[str, list[float | None]] = field(default_factory=dict)
    magnitude: Magnitude | None = None
    compared: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.evidence is None:
            return
        names = list(self.per_seed)
        compared = self.compared or tuple(names[:1 if self.evidence.threshold is not None
                                                else 2])
        unknown = [c for c in compared if c not in self.per_seed]
        if unknown or len(compared) != (1 if self.evidence.threshold is not None else 2):
            raise ValueError(f"a verdict's evidence must name its per-seed values: compared "
                             f"{compared}, per_seed has {names}")
        object.__setattr__(self, "compared", compared)


ClaimKind = Literal["paper", "check"]


@dataclass(frozen=True)
class Claim:
    """A claim of the paper, or one of landnav's own checks and controls, and how to judge it.

    ``kind``: "paper" for what the paper claims (quoted with its figure or table, judged as the
    paper states it), "check" for landnav's own checks (a filter works, a control); the report
    tallies the two apart. ``conditions`` lists every condition of the experiment that differs
    from the paper. A paper claim landnav cannot test says why in ``untestable``; its ``judge``,
    if any, only gives landnav's figure for it (the word is "not testable", never one from
    evidence). A claim judged again under another value of a deciding condition names the
    default claim in ``variant_of`` and the value in ``variant`` ("fix noise 1.5 m"); the
    summary tallies the default rows only. A check that reads entries ``--quick`` does not
    replay (``Experiment.quick_entries``) is ``full_only``.

    ``experiments`` names the experiments whose tables the judge reads (it is given those only,
    so a judge reading another one fails); empty: every experiment of the paper. ``landnav
    reproduce --quick`` runs the experiments of the claims that are no variant and leaves the
    variants to the full run."""

    key: str
    text: str          # the claim as the paper makes it (a check: what landnav checks)
    paper_figure: str  # the number(s) the paper prints, with table / figure / section
    conditions: tuple[str, ...]  # every condition that differs from the paper
    judge: Callable[[Mapping[str, pd.DataFrame]], Verdict] | None = None
    # judge: experiment key -> DataFrame (index seed, columns figure names) -> Verdict
    kind: ClaimKind = field(default="paper", kw_only=True)
    untestable: str = field(default="", kw_only=True)  # why the paper claim cannot be tested
    variant_of: str = field(default="", kw_only=True)  # key of the default claim of a sweep
    variant: str = field(default="", kw_only=True)     # the swept condition's value, in words
    experiments: tuple[str, ...] = field(default=(), kw_only=True)  # keys the judge reads
    full_only: bool = field(default=False, kw_only=True)  # a check --quick leaves to the full run

    def __post_init__(self) -> None:
        if isinstance(self.conditions, str) or not all(isinstance(c, str)
                                                       for c in self.conditions):
            raise TypeError(f"claim {self.key}: conditions is a tuple of strings")
        if self.kind not in ("paper", "check"):
            raise ValueError(f"claim {self.key}: kind is 'paper' or 'check', got {self.kind!r}")
        if self.untestable and self.kind != "paper":
            raise ValueError(f"claim {self.key}: only a paper claim can be untestable")
        if not self.untestable and self.judge is None:
            raise ValueError(f"claim {self.key}: a testable claim needs a judge")
        if bool(self.variant_of) != bool(self.variant):
            raise ValueError(f"claim {self.key}: variant_of and variant go together")
        if self.full_only and self.kind != "check":
            raise ValueError(f"claim {self.key}: only a check is left to the full run")
        object.__setattr__(self, "experiments", tuple(self.experiments))


@dataclass(frozen=True)
class Paper:
    """One seed paper: its experiments and its claims."""

    key: str  # "cho2006", "park2019", "tan2008", "chan", "karamat2015"
    title: str
    citation: str
    experiments: tuple[Experiment, ...]
    claims: tuple[Claim, ...]
    # figures in the layout of the paper's own: (experiment key -> the first seed's history,
    # experiment key -> per-seed figures) -> [(caption, matplotlib Figure)]
    figures: Callable[[Mapping[str, pd.DataFrame], Mapping[str, pd.DataFrame]],
                      list[tuple[str, Figure]]] | None = None

    def __post_init__(self) -> None:
        keys = {e.key for e in self.experiments}
        for claim in self.claims:
            unknown = sorted(set(claim.experiments) - keys)
            if unknown:
                raise ValueError(f"paper {self.key}, claim {claim.key}: no experiment "
                                 f"{', '.join(unknown)}")

    def read_by(self, claim: Claim) -> tuple[Experiment, ...]:
        """The experiments whose tables ``claim``'s judge reads (``Claim.experiments``)."""
        return tuple(e for e in self.experiments
                     if not claim.experiments or e.key in claim.experiments)

    def quick(self) -> Paper:
        """The paper as ``landnav reproduce --quick`` runs it: its claims that are no variant
        of another (a swept condition's other values are left to the full run) nor
        ``full_only``, the experiments those claims read, each with its ``quick_entries``."""
        claims = tuple(c for c in self.claims if not c.variant_of and not c.full_only)
        read = {e.key for c in claims if c.judge is not None for e in self.read_by(c)}
        return replace(self, claims=claims, experiments=tuple(
            replace(e, entries={k: e.entries[k] for k in e.quick_entries}) if e.quick_entries
            else e for e in self.experiments if e.key in read))
