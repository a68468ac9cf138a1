"""From a resolved scenario to a dataset: truth, sensors (each with its own random stream),
events and manifest, written atomically.

The streams are column tables (``simulator.tables``) wherever no pandas code touches them: the
truth, the IMU, odometer, barometer and magnetometer, and the events. The GNSS streams, and the
streams a fault acts on, are DataFrames; the writer takes either. ``generate_streams`` returns
every stream as a DataFrame unless asked for the tables as they are (``frames=False``, what
``generate_dataset`` does), so a scenario without GNSS and faults is generated without importing
pandas.

Public functions
----------------
build_truth, sensor_rng, generate_streams, build_manifest, generate_dataset.
"""

from __future__ import annotations

import importlib
import os
import platform
import zlib
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import simulator
from simulator.dataset.events import events_table, gnss_outage_intervals, zone_events
from simulator.dataset.io import DatasetWriter
from simulator.drive import build_drive
from simulator.faults import FAULT_REGISTRY
from simulator.faults.apply import apply_faults
from simulator.outputs import atomic_output_dir
from simulator.progress import progress
from simulator.scenario import Scenario
from simulator.sensors import SENSOR_MODELS
from simulator.tables import Table, as_frames, column
from simulator.trajectory.kinematics import Kinematics


def build_truth(scenario: dict) -> Kinematics:
    """The exact truth trajectory of a resolved scenario dictionary (a drive built for it)."""
    return build_drive(scenario).truth


# worker threads for the sensors (the dataset writer has its own two): the IMU's three draws
# and the other sensors keep up to four busy
_SENSOR_WORKERS = max(2, min(4, os.cpu_count() or 2))


def sensor_rng(seed: int, name: str) -> np.random.Generator:
    """The random stream of one sensor: a SeedSequence child keyed by the sensor's name, so adding
    a sensor does not change the others (SPEC section 2). The bit generator is numpy's SFC64
    (Doty-Humphrey's Small Fast Chaotic generator; expected period 2^255, and a 64-bit counter
    keeps distinct seeds apart for at least 2^64 draws, per numpy's documentation): the IMU of
    an hour draws some 15 million normals, 8 % quicker than with the default PCG64."""
    return np.random.Generator(np.random.SFC64(np.random.SeedSequence(seed, spawn_key=(
        zlib.crc32(name.encode()),))))


@dataclass
class Generated:
    truth: Kinematics
    streams: dict[str, Table]  # DataFrames unless generate_streams(frames=False)
    drawn: dict[str, dict] = field(default_factory=dict)


def generate_streams(scenario: Scenario | dict, show_progress: bool = True, frames: bool = True,
                     on_final: Callable[[str, Table], None] | None = None) -> Generated:
    """Truth table, every configured sensor's streams, and the events table.

    ``scenario`` is a validated ``Scenario``, whose drive its validation built, or a resolved
    scenario dictionary, for which a drive is built here.

    With ``frames`` (the default) every stream is a DataFrame; without, the tables stay as the
    sensors and faults left them (column tables or DataFrames), which is all the writer needs.
    ``on_final(name, table)`` receives each stream no fault will change (the truth always) as
    soon as it exists, so that it can be written while the other streams are made.

    A sensor with a ``prepare(duration_s, rng, pool)`` step (the IMU: its bias processes and
    noise need no trajectory) draws in worker threads while the truth is built; then it runs in
    this thread beside the other sensors in the workers. numpy releases the interpreter lock in
    its array work, so they overlap on several cores. The draws are the same as without the
    threads: each sensor owns its random stream.
    """
    if isinstance(scenario, Scenario):
        drive, scenario = scenario.drive, scenario.data
    else:
        drive = None
    drive = drive if drive is not None else build_drive(scenario)
    sensors = {k: v for k, v in scenario["sensors"].items() if v is not None}
    models = {name: SENSOR_MODELS[name](block) for name, block in sensors.items()}
    rngs = {name: sensor_rng(scenario["seed"], name) for name in models}
    drawn: dict[str, dict] = {}
    with ThreadPoolExecutor(max_workers=_SENSOR_WORKERS) as pool:
        for name, model in models.items():
            if hasattr(model, "prepare"):  # its parts go to the pool, ahead of the sensors
                model.prepare(drive.duration_s, rngs[name], pool)
        truth = drive.truth
        streams: dict[str, Table] = {"truth": truth.columns()}  # caches the grid evaluation
        # streams still to change: those a fault acts on, and raw GNSS kept only for the faults
        # and the outage table unless asked for
        gnss = sensors.get("gnss")
        unsettled = {name for fault in scenario["faults"]
                     for name in FAULT_REGISTRY[fault["kind"]].changed_streams}
        if gnss is not None and "raw" not in gnss["outputs"]:
            unsettled.add("gnss_raw")
        if on_final is not None:
            on_final("truth", streams["truth"])
        # the sensors only read the truth (its grid evaluation is cached above). Those with
        # draws in flight (``prepare``) run here, the others in the pool behind the draws: a
        # job waits only for jobs submitted before it, so no two threads wait on each other
        jobs = {name: pool.submit(model.generate, truth, rngs[name])
                for name, model in models.items() if not hasattr(model, "prepare")}
        for name in progress(models, "sensors", show_progress):
            made = (jobs[name].result() if name in jobs
                    else models[name].generate(truth, rngs[name]))
            streams.update(made)
            drawn[name] = models[name].drawn
            for stream, table in made.items():
                if on_final is not None and stream not in unsettled:
                    on_final(stream, table)
    rows = zone_events(truth.profile.zones) + apply_faults(streams, scenario, truth)
    for t_start, t_end in _outages(streams, truth.duration_s):
        rows.append({"t_start": t_start, "t_end": t_end, "kind": "gnss_outage", "detail": ""})
    if gnss is not None and "raw" not in gnss["outputs"]:
        streams.pop("gnss_raw", None)
    streams["events"] = events_table(rows)
    return Generated(truth, as_frames(streams) if frames else streams, drawn)


def _outages(streams: dict[str, Table], end_t: float) -> list[tuple[float, float]]:
    if "gnss_fix" in streams:
        fix = streams["gnss_fix"]
        epochs = column(fix, "t")
        if "gnss_raw" in streams:
            has = np.isin(epochs, column(streams["gnss_raw"], "t"))
        else:
            has = column(fix, "fix") > 0
        return gnss_outage_intervals(epochs, has, end_t)
    return []


def _versions(data: dict) -> dict[str, str]:
    """Python, landnav and the packages that made this dataset: numpy (every draw) and pyarrow
    (the files) always, pygeomag with a magnetometer, pandas with GNSS or faults. From the
    modules' ``__version__`` (importlib.metadata costs 13 ms to import)."""
    used = ["numpy", "pyarrow"]
    if data["sensors"].get("mag") is not None:
        used.append("pygeomag")
    if data["sensors"].get("gnss") is not None or data["faults"]:
        used.append("pandas")
    return {"python": platform.python_version(), "landnav": simulator.__version__,
            **{name: importlib.import_module(name).__version__ for name in used}}


def build_manifest(scenario: Scenario, generated: Generated) -> dict:
    """The manifest (SPEC section 5) without its ``streams`` block."""
    data = scenario.data
    truth = generated.truth
    return {
        "scenario": data,
        "seed": data["seed"],
        "overrides": scenario.overrides,
        "software": _versions(data),
        "gps_time_start": {"week": truth.gps_week, "tow": truth.gps_tow},
        "utc_start": data["start"]["utc"],
        "origin": {"lat": truth.origin.lat_deg, "lon": truth.origin.lon_deg,
                   "alt": truth.origin.alt_m},
        "duration": truth.duration_s,
        "sensors": generated.drawn,
    }


def generate_dataset(scenario: Scenario, out_dir: Path, force: bool = False,
                     show_progress: bool = True) -> Path:
    """Generate a scenario's dataset into ``out_dir`` (atomically; refuses to overwrite without
    ``force``). Returns ``out_dir``. Each stream no fault changes is written while the others are
    made."""
    out_dir = Path(out_dir)
    with atomic_output_dir(out_dir, force) as tmp, DatasetWriter(tmp) as writer:
        generated = generate_streams(scenario, show_progress, frames=False,
                                     on_final=writer.write)
        imu = scenario.data["sensors"].get("imu")
        described = {"imu": {"imu_output": imu["output"]}} if imu is not None else {}
        writer.finish(build_manifest(scenario, generated), generated.streams, described)
    return out_dir
