"""Tan et al. 2008 reproduced: ``ins_lkf`` on its 70 s outage (``scenarios/tan2008_outage.yaml``)
in five configurations replaying the same dataset of each seed, every claim judged as the paper
states it (docs/reproduction_tan2008.md).

Configurations (labels): ``full`` (the paper's design: closed loop with GPS, open loop in the
outage aided by the NHC, the height constraint and the magnetometer heading), ``constraints``
(without the magnetometer), ``free`` (no aiding in the outage: the free inertial solution),
``closed`` (``full`` kept in closed loop through the outage) and ``no_standstill`` (``full``
without the zero-velocity and zero-rate updates of the 60 s standstill).

Figures per seed: ``LABEL.end_horizontal_m`` and ``LABEL.max_horizontal_m``, the scorer's
horizontal error at the end of the outage and its largest inside it (SPEC section 8
``outages``); ``outage.distance_m``, the distance driven in it; ``LABEL.standstill_heading_deg``,
the absolute heading error at the end of the standstill.

Public names
------------
PAPER, OUTAGE, SHORT.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from simulator.dataset.io import Dataset
from simulator.reproduce import measures as m
from simulator.reproduce.paper import Claim, Experiment, Figures, Paper, Verdict
from simulator.reproduce.tan2008_figures import figures, history

# the last straight (segment 16) shortened: the drive ends about 20 s after the outage
SHORT = ("trajectory.segments.16.straight.length=200",)
STANDSTILL_S = 60.0  # the scenario's and the filter's initial standstill
FULL = {"tuning": "paper"}  # the paper's design: ins_lkf's defaults with the paper's noise


def _measure(dataset: Dataset, solutions: Mapping[str, pd.DataFrame]) -> Figures:
    out = {}
    for label, solution in solutions.items():
        (outage,) = m.outage_scores(dataset, solution)
        out[f"{label}.end_horizontal_m"] = outage["end_horizontal"]
        out[f"{label}.max_horizontal_m"] = outage["max_horizontal"]
        out["outage.distance_m"] = outage["distance"]
        e = m.errors(dataset, solution)
        out[f"{label}.standstill_heading_deg"] = abs(m.at_time(
            e["t"].to_numpy(), np.degrees(e["err_yaw"].to_numpy()), STANDSTILL_S))
    return out


OUTAGE = Experiment(
    key="outage", scenario="tan2008_outage.yaml",
    entries={"full": {"name": "ins_lkf", "config": FULL},
             "constraints": {"name": "ins_lkf", "config": {**FULL, "mag_heading": False}},
             "free": {"name": "ins_lkf",
                      "config": {**FULL, "nhc": False, "height_constraint": False,
                                 "mag_heading": False}},
             "closed": {"name": "ins_lkf", "config": {**FULL, "open_loop_outages": False}},
             "no_standstill": {"name": "ins_lkf", "config": {**FULL, "standstill": 0.0}}},
    measure=_measure, quick_overrides=SHORT, history=history, full_runs=20)


def paired(a: str, b: str, figure: str, what: str, analysis: str = ""):
    """A judge: configuration ``a``'s ``figure`` (m) smaller than ``b``'s, paired per seed."""
    def judge(tables: Mapping[str, pd.DataFrame]) -> Verdict:
        per = {f"{a} {figure}": m.column(tables, f"{a}.{figure}", "outage"),
               f"{b} {figure}": m.column(tables, f"{b}.{figure}", "outage")}
        return m.paired_judgement(per, *per, better="lower", kind="difference", unit="m",
                                  what=what, analysis=analysis)
    return judge


def _small_error(tables: Mapping[str, pd.DataFrame]) -> Verdict:
    """landnav's figure for the paper's 'small error' (no word: the paper prints no number)."""
    per = {"full end_horizontal_m": m.column(tables, "full.end_horizontal_m", "outage"),
           "full max_horizontal_m": m.column(tables, "full.max_horizontal_m", "outage"),
           "outage distance_m": m.column(tables, "outage.distance_m", "outage")}
    largest = per["full max_horizontal_m"]
    share = 100 * largest / per["outage distance_m"]
    measured = (f"largest horizontal error in the outage {m.spread_text(largest, 'm')}"
                f"; at its end {m.spread_text(per['full end_horizontal_m'], 'm')}; largest "
                f"error as a share of the {m.spread_text(per['outage distance_m'], 'm')} "
                f"driven: {m.spread_text(share, '%')}")
    return Verdict("not shown", measured, "listed with landnav's figure: the paper prints no "
                   "number for 'small'", None, {k: m.listed(v) for k, v in per.items()})


def _standstill(tables: Mapping[str, pd.DataFrame]) -> Verdict:
    per = {"with standstill updates, deg": m.column(tables, "full.standstill_heading_deg",
                                                     "outage"),
           "without, deg": m.column(tables, "no_standstill.standstill_heading_deg", "outage")}
    return m.paired_judgement(per, *per, better="lower", kind="difference", unit="deg",
                              what="the heading drifts less with the filter's standstill "
                                   "updates")


DRIVE = ("a simulated 12-minute city loop of straights and right-angle turns at 8-12 m/s "
         "(the paper's Hanoi route of Fig. 8 is not given in numbers); the outage covers a "
         "straight, a 90 deg turn and a straight")
SENSORS = ("the BP3010 preset (data-sheet noise of the ADXRS300 gyros and ADXL210E "
           "accelerometers, biases assumed calibrated) drawn per seed; the automotive "
           "magnetometer preset (the paper names none); landnav's GPS receiver")
METRIC = ("errors against the truth (the paper compares with GPS, which is absent in the "
          "outage); the drive is cut 20 s after the outage in --quick")
CONDITIONS = (DRIVE, SENSORS, METRIC)

PAPER = Paper(
    key="tan2008",
    title="Land-vehicle MEMS INS/GPS positioning during GPS signal blockage periods",
    citation="Tan, Ha, Long, Duc, Thuy, VNU Journal of Science, Mathematics-Physics 23, "
             "2007/2008 (seeds/003)",
    experiments=(OUTAGE,),
    figures=figures,
    claims=(
        Claim("constraints_reduce_outage_error",
              "The velocity (non-holonomic) and height constraints reduce the error in a GPS "
              "outage (error at the outage's end smaller with them)",
              "Sections 3 and 6: 'The vehicle motion constraints ... are utilized to reduce "
              "the INS error degradation during the periods of GPS unavailability' (no number)",
              (*CONDITIONS, "horizontal error at the end of the 70 s outage"),
              paired("constraints", "free", "end_horizontal_m", "constraints smaller")),
        Claim("magnetometer_reduces_outage_error",
              "The magnetometer heading measurements reduce the error in a GPS outage (error "
              "at the outage's end smaller with them than with the constraints alone)",
              "Sections 4 and 6: '... and magnetometer measurements are utilized to reduce "
              "the INS error degradation' (no number)",
              (*CONDITIONS, "horizontal error at the end of the 70 s outage"),
              paired("full", "constraints", "end_horizontal_m", "magnetometer smaller",
                     "The calibrated magnetometer observes the heading, which the outage's "
                     "along-track error hardly depends on over 70 s; its own error (the "
                     "automotive preset's) is of the order of the heading error it corrects.")),
        Claim("small_error_70_s",
              "In the 70 s outage (400-470 s) the INS/GPS trajectory follows the GPS one with "
              "small error",
              "Fig. 9 (trajectory only, no number): 'follows the GPS one (dot curve) with "
              "small error for quite a long trip'", CONDITIONS, _small_error,
              untestable="the paper prints no number for 'small error' (Fig. 9 is a "
                         "trajectory plot): landnav's figure is listed, no word is given"),
        Claim("closed_loop_better",
              "The closed-loop (feedback) configuration performs better than the open-loop one "
              "in the existence of nonlinear effects",
              "Section 2, Figs. 1-2 (no number)",
              (*CONDITIONS, "closed against open loop inside the outage only (with GPS both "
                            "run closed, the paper's design); largest horizontal error in the "
                            "outage"),
              paired("closed", "full", "max_horizontal_m", "closed loop smaller")),
        Claim("standstill_heading_drift",
              "Standing still, the filter stops the INS heading from drifting (the heading "
              "drift without the KF is far larger than with it)",
              "Figs. 6-7 (heading standing still without and with the KF; no number)",
              (*CONDITIONS, "without the KF: the same filter without its zero-velocity and "
                            "zero-rate updates (GPS position does not observe the heading at "
                            "rest); absolute heading error at the end of the 60 s standstill"),
              _standstill),
    ))
