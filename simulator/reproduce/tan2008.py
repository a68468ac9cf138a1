"""Tan et al. 2008 reproduced: ``ins_lkf`` on its 70 s outage (``scenarios/tan2008_outage.yaml``)
in three configurations replaying the same dataset of each seed, with issue 14's criteria
(docs/reproduction_tan2008.md).

Figures per seed: ``LABEL.end_horizontal_m``, the scorer's horizontal error at the end of the
outage (SPEC section 8 ``outages.end_horizontal``) of ``full`` (NHC, height constraint and
magnetometer heading), ``constraints`` (NHC and height only) and ``free`` (no aiding in the
outage: the free inertial solution).

Public names
------------
PAPER, OUTAGE, SHORT.
"""

from __future__ import annotations

from collections.abc import Mapping

import pandas as pd

from simulator.dataset.io import Dataset
from simulator.reproduce import measures as m
from simulator.reproduce.paper import Claim, Experiment, Figures, Paper, Verdict

# the last straight (segment 16) shortened: the drive ends about 20 s after the outage
SHORT = ("trajectory.segments.16.straight.length=200",)
CUT_AT_LEAST = 0.30  # NHC + height cut the outage-end error by at least this fraction
MAG_AT_MOST = 1.10  # the magnetometer makes it worse by at most this ratio


def _outage_end(dataset: Dataset, solutions: Mapping[str, pd.DataFrame]) -> Figures:
    out = {}
    for label, solution in solutions.items():
        (outage,) = m.outage_scores(dataset, solution)
        out[f"{label}.end_horizontal_m"] = outage["end_horizontal"]
    return out


OUTAGE = Experiment(
    key="outage", scenario="tan2008_outage.yaml",
    entries={"full": {"name": "ins_lkf"},
             "constraints": {"name": "ins_lkf", "config": {"mag_heading": False}},
             "free": {"name": "ins_lkf",
                      "config": {"nhc": False, "height_constraint": False,
                                 "mag_heading": False}}},
    measure=_outage_end, quick_overrides=SHORT)


def _end(tables: Mapping[str, pd.DataFrame], label: str) -> pd.Series:
    return tables["outage"][f"{label}.end_horizontal_m"]


def _judge_constraints(tables: Mapping[str, pd.DataFrame]) -> Verdict:
    free, constrained = _end(tables, "free"), _end(tables, "constraints")
    cut = 1.0 - constrained / free  # NaN where a seed has no end error: counted, not dropped
    wins, n = m.paired_wins(constrained.to_numpy(), free.to_numpy())
    measured = (f"cut {m.spread_text(100 * cut, '%')}; end error free "
                f"{m.spread_text(free, 'm')}, with NHC + height "
                f"{m.spread_text(constrained, 'm')}; "
                f"{m.win_rate_text(wins, n, 'constrained', m.missing_count(constrained, free))}")
    return m.median_verdict(cut, CUT_AT_LEAST, "above", 0.0, measured,
                            "cut of the outage-end error")


def _judge_magnetometer(tables: Mapping[str, pd.DataFrame]) -> Verdict:
    full, constrained = _end(tables, "full"), _end(tables, "constraints")
    ratio = full / constrained
    wins, n = m.paired_wins(full.to_numpy(), constrained.to_numpy())
    missing = m.missing_count(full, constrained)
    measured = (f"ratio with / without magnetometer {m.spread_text(ratio)}; "
                f"{m.win_rate_text(wins, n, 'with magnetometer', missing)}")
    return m.median_verdict(ratio, MAG_AT_MOST, "below", MAG_AT_MOST, measured,
                            "ratio with / without the magnetometer")


CONDITIONS = ("simulated 12-minute drive with the BP3010 unit's errors drawn per seed instead "
              "of the paper's Hanoi drive; the paper prints no error figure, so issue 14's "
              "criteria are tested; the drive is cut 20 s after the outage in --quick",)
PAPER = Paper(
    key="tan2008",
    title="Land-vehicle MEMS INS/GPS positioning during GPS signal blockage periods",
    citation="Tan, Ha, Long, Duc, Thuy, VNU Journal of Science, Mathematics-Physics 23, "
             "2007/2008 (seeds/003)",
    experiments=(OUTAGE,),
    claims=(
        Claim("constraints_cut_outage_error",
              "On a 70 s outage the NHC and height constraints cut the horizontal error at the "
              "end of the outage by >= 30 % (median over seeds, paired) against the same filter "
              "without them",
              "Fig. 9 (outage 400-470 s, trajectory only): 'follows the GPS one with small "
              "error'; no number printed", CONDITIONS, _judge_constraints),
        Claim("magnetometer_no_worse",
              "Calibrated magnetometer heading aiding does not make the outage-end error worse "
              "by more than 10 % (median ratio <= 1.10)",
              "section 3: the magnetometer heading aids the filter in outages; no number "
              "printed", CONDITIONS, _judge_magnetometer),
    ))
