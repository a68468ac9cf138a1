"""One RTK drive processed twice, for the rtk_ins_ekf tests and benchmark: the shipped
scenario ``rtk_open_road.yaml`` (or a shortened copy) generated at a seed, ``rtk_ins_ekf``
replayed on it inside landnav, the dataset exported as RINEX and processed by RTKLIB's
``rnx2rtkp`` kinematic (``tests.gnss.rtklib``), both solutions scored by ``landnav score``'s
own code (the ``rtk`` and ``consistency`` blocks)."""

from __future__ import annotations

import copy
import json
import time
from pathlib import Path

import numpy as np
import yaml

from tests.conftest import REPO
from tests.gnss.rtklib import kinematic_solution

SCENARIO = REPO / "scenarios" / "rtk_open_road.yaml"
# a few minutes of the same road: the stop, 1.5 km, one 450 m tunnel (30 s), 1 km, a turn
SHORT_SEGMENTS = [
    {"stop": {"duration": 30}},
    {"accelerate": {"to_speed": 15.0, "accel": 1.0}},
    {"straight": {"length": 1500}},
    {"straight": {"length": 450, "zone": "tunnel"}},
    {"straight": {"length": 1000}},
    {"turn": {"angle": 90, "radius": 50}},
    {"straight": {"length": 500}},
    {"accelerate": {"to_speed": 0.0, "accel": 1.0}},
    {"stop": {"duration": 10}},
]


# the dual-band rover's signals of each system (the base tracks the same)
SIGNALS = {"gps": ["1C", "2L"], "galileo": ["1C", "7Q"], "beidou": ["2I", "7I"]}
RINEX_LETTERS = {"gps": "G", "galileo": "E", "beidou": "C"}


def scenario(seed: int, short: bool, systems: tuple[str, ...] = ("gps",)) -> dict:
    """The shipped scenario at ``seed``, shortened to ``SHORT_SEGMENTS`` if ``short``, rover
    and base tracking ``systems`` (the dual-band signals of ``SIGNALS``)."""
    data = yaml.safe_load(SCENARIO.read_text())
    data = copy.deepcopy(data)
    data["seed"] = seed
    if short:
        data["trajectory"]["segments"] = SHORT_SEGMENTS
    if tuple(systems) != ("gps",):
        data["sensors"]["gnss"]["systems"] = list(systems)
        data["sensors"]["gnss_base"]["systems"] = list(systems)
        data["sensors"]["gnss_base"]["signals"] = {s: SIGNALS[s] for s in systems}
    data["estimators"] = ["rtk_ins_ekf"]
    return data


def process(work: Path, seed: int, short: bool, systems: tuple[str, ...] = ("gps",)) -> dict:
    """Generate, replay rtk_ins_ekf, export RINEX, run rnx2rtkp; the two solutions' scores
    (``rtk_ins_ekf`` and ``rtklib``: the ``rtk`` block, and ``consistency`` for ours) and the
    CPU seconds of each (``cpu_s``) with the drive's duration (``duration_s``)."""
    from simulator.dataset.export import export_rinex
    from simulator.dataset.io import open_dataset
    from simulator.pipeline import generate, load_scenario
    from simulator.replay import run_estimator
    from simulator.scoring.evaluate import score_solutions
    from simulator.scoring.readers import read_solution_file

    work.mkdir(parents=True, exist_ok=True)
    path = work / f"rtk_seed{seed}.yaml"
    path.write_text(yaml.safe_dump(scenario(seed, short, systems)))
    data = work / f"seed{seed}"
    generate(load_scenario(path), data, show_progress=False)
    dataset = open_dataset(data)
    start = time.process_time()
    frame, info = run_estimator(dataset, "rtk_ins_ekf", show_progress=False)
    ours_cpu = time.process_time() - start
    obs, nav = export_rinex(dataset, work / f"rinex{seed}")
    manifest = json.loads((data / "manifest.json").read_text())
    base = manifest["gnss_base"]
    pos = work / f"seed{seed}.pos"
    rtklib_cpu = kinematic_solution(obs, obs.with_name(obs.stem + "_base.obs"), nav,
                                    np.array([base["x"], base["y"], base["z"]]), pos,
                                    None if tuple(systems) == ("gps",)
                                    else "".join(RINEX_LETTERS[s] for s in systems))
    start_gps = manifest["gps_time_start"]
    rtklib, _, _ = read_solution_file(pos, (start_gps["week"], start_gps["tow"]))
    scored = score_solutions(dataset, {"rtk_ins_ekf": (frame, info), "rtklib": (rtklib, None)})
    ours = scored.results["rtk_ins_ekf"].scores
    theirs = scored.results["rtklib"].scores
    return {"seed": seed, "duration_s": float(manifest["duration"]),
            "rtk_ins_ekf": ours["rtk"], "rtklib": theirs["rtk"],
            "consistency": ours["consistency"],
            "cpu_s": {"rtk_ins_ekf": ours_cpu, "rnx2rtkp": rtklib_cpu}}


def median_refix(figures: dict) -> float:
    """Median re-fix time over a run's outages (s); an outage with no re-fix counts as
    infinite."""
    times = [np.inf if x is None else x for x in figures["refix_times"]]
    return float(np.median(times)) if times else float("nan")
