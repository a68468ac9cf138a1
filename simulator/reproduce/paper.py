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
Figures, Experiment, Verdict, Claim, Paper, STATUSES, SCENARIO_DIR, scenario_path.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import pandas as pd

from simulator.dataset.io import Dataset
from simulator.errors import InputError, Problem

__all__ = ["SCENARIO_DIR", "STATUSES", "Claim", "Experiment", "Figures", "Paper", "Verdict",
           "scenario_path"]

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


@dataclass(frozen=True)
class Verdict:
    """The one word on a claim, landnav's figure(s) in words, and why."""

    status: Literal["shown", "partly", "not shown"]
    measured: str  # "median 17.8 % (IQR 12-25), 7/10 seeds"
    reason: str    # why this word; for partly / not shown the analysis in a sentence or two


@dataclass(frozen=True)
class Claim:
    """A claim of the paper (or the issue's criterion for it) and how to judge it."""

    key: str
    text: str          # the claim as the paper makes it / the criterion
    paper_figure: str  # the number(s) the paper prints, with table / figure / section
    conditions: str    # what differs (simulated vs real data, metric, drive, sensor)
    judge: Callable[[Mapping[str, pd.DataFrame]], Verdict]
    # judge: experiment key -> DataFrame (index seed, columns figure names) -> Verdict


@dataclass(frozen=True)
class Paper:
    """One seed paper: its experiments and its claims."""

    key: str  # "cho2006", "park2019", "tan2008", "chan", "karamat2015"
    title: str
    citation: str
    experiments: tuple[Experiment, ...]
    claims: tuple[Claim, ...]
