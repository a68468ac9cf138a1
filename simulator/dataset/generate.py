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
build_truth, sensor_rng, generate_streams, build_manifest, stream_units, generate_dataset.
"""

from __future__ import annotations

import importlib
import os
import platform
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import simulator
from simulator import columns as col
from simulator.dataset.events import events_table, gnss_outage_intervals, zone_events
from simulator.dataset.io import DatasetWriter
from simulator.dataset.truth_sensors import truth_sensors_table
from simulator.drive import build_drive
from simulator.faults import FAULT_REGISTRY
from simulator.faults.apply import apply_faults
from simulator.outputs import atomic_output_dir
from simulator.progress import progress
from simulator.scenario import Scenario
from simulator.sensors import SENSOR_MODELS
from simulator.sensors.base import sample_times
from simulator.stochastic import stream_rng
from simulator.tables import Table, as_frames, column
from simulator.threads import one_blas_thread
from simulator.trajectory.kinematics import Kinematics
from simulator.vehicle.params import vehicle_parameters
from simulator.vehicle.suspension import axle_distances


def build_truth(scenario: dict) -> Kinematics:
    """The exact truth trajectory of a resolved scenario dictionary (a drive built for it)."""
    return build_drive(scenario).truth


# worker threads for the sensors (the dataset writer has its own two): the IMU's three draws
# and the other sensors keep up to four busy
_SENSOR_WORKERS = max(2, min(4, os.cpu_count() or 2))


def sensor_rng(seed: int, name: str) -> np.random.Generator:
    """The random stream of one sensor (``stochastic.stream_rng`` keyed by its name)."""
    return stream_rng(seed, name)


@dataclass
class Generated:
    truth: Kinematics
    streams: dict[str, Table]  # DataFrames unless generate_streams(frames=False)
    drawn: dict[str, dict] = field(default_factory=dict)
    timing: dict[str, dict] = field(default_factory=dict)  # stream -> how it is stamped
    truth_keys: dict[str, dict] = field(default_factory=dict)  # sensor -> {key: nominal}


@one_blas_thread
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
    for model in models.values():  # a sensor made by another (the base by the rover)
        if getattr(model, "host", None) in models:
            models[model.host].attach(model)
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
    fault_rows = apply_faults(streams, scenario, truth)
    rows = zone_events(truth.profile.zones) + fault_rows
    true_errors = {name: series for model in models.values()
                   for name, series in getattr(model, "true_errors", {}).items()}
    truth_sensors = truth_sensors_table(true_errors, truth.duration_s, fault_rows)
    if truth_sensors is not None:
        streams["truth_sensors"] = truth_sensors
    gnss_rate = None if gnss is None else gnss["rate"]
    for t_start, t_end in _outages(streams, truth.duration_s, gnss_rate):
        rows.append({"t_start": t_start, "t_end": t_end, "kind": "gnss_outage", "detail": ""})
    if gnss is not None and "raw" not in gnss["outputs"]:
        streams.pop("gnss_raw", None)
    streams["events"] = events_table(rows)
    timing = {stream: how for model in models.values() for stream, how in model.timing().items()
              if stream in streams}
    return Generated(truth, as_frames(streams) if frames else streams, drawn, timing,
                     {name: dict(model.truth_keys) for name, model in models.items()})


def _outages(streams: dict[str, Table], end_t: float, gnss_rate_hz: float | None
             ) -> list[tuple[float, float]]:
    """The stretches of receiver epochs without a single measurement (SPEC section 5): epochs
    from the fix stream, or the receiver's epoch grid when it outputs raw measurements only."""
    if "gnss_fix" in streams:
        epochs = column(streams["gnss_fix"], "t")
    elif "gnss_raw" in streams and gnss_rate_hz:
        epochs = sample_times(end_t, gnss_rate_hz)
    else:
        return []
    if "gnss_raw" in streams:
        has = np.isin(epochs, column(streams["gnss_raw"], "t"))
    else:
        has = column(streams["gnss_fix"], "fix") > 0
    return gnss_outage_intervals(epochs, has, end_t)


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


# what a real user of the dataset would know, and what only the scorer may read
KNOWLEDGE = {
    "user": ["datasheet", "timing", "gps_time_start", "utc_start", "streams", "duration",
             "software"],
    "truth": ["scenario", "overrides", "sensors", "truth_parameters", "origin", "seed",
              "truth*.parquet", "events.parquet"],
}


def _datasheet(data: dict, truth_keys: dict[str, dict]) -> tuple[dict, dict]:
    """Each sensor's block as a user would know it (the true-value keys replaced by their
    nominal values), and the true values replaced; and the car's installation geometry
    (``vehicle_datasheet``) under ``vehicle``."""
    datasheet, true_values = {}, {}
    for name, block in data["sensors"].items():
        if block is None:
            continue
        keys = truth_keys.get(name, {})
        datasheet[name] = {k: keys.get(k, v) for k, v in block.items()}
        if keys:
            true_values[name] = {k: block[k] for k in keys if k in block}
    datasheet["vehicle"] = vehicle_datasheet(data["vehicle"])
    return datasheet, true_values


def vehicle_datasheet(block: str | dict) -> dict:
    """What a user measures on the car before a drive: its ``preset`` (``rigid``: the truth's
    point follows the road, with nothing else), ``wheelbase`` (m), the truth's reference point
    ``imu_position`` from the centre of gravity and ``rear_axle``, the point above the rear
    axle's centre at the centre of gravity's height, from the IMU (both body FRD, m): there
    the rear wheels roll without steering, so the non-holonomic constraint holds there (the
    bicycle model's rear axle; ``estimators.toolbox.constraints``). The GNSS antenna's lever
    arm from the IMU is the ``gnss`` block's ``antenna_lever_arm``, the IMU's mounting the
    ``imu`` block's ``mounting``."""
    params = vehicle_parameters(block)
    if params is None:
        return {"preset": "rigid"}
    _, l_r = axle_distances(params)
    imu = [float(x) for x in params["imu_position"]]
    return {"preset": params["preset"], "wheelbase": float(params["wheelbase"]),
            "imu_position": imu, "rear_axle": [-l_r - imu[0], -imu[1], -imu[2]]}


def build_manifest(scenario: Scenario, generated: Generated) -> dict:
    """The manifest (SPEC section 5) without its ``streams`` block.

    Besides the SPEC keys: ``datasheet`` (each sensor's parameters as a user knows them: the
    datasheet and nominal values, with the scenario keys that set a true value, such as the
    odometer's ``scale_factor``, replaced by the nominal value a user assumes), the values so
    replaced in ``truth_parameters``; a base station's block carries its ``surveyed_position``
    {lat, lon, alt, x, y, z}, the antenna position a user of a base knows), ``timing`` (how
    each stream is stamped and its effective delay) and ``knowledge`` (which keys a real user
    would know, and which are truth that only scoring may read: the resolved ``scenario``, the
    drawn ``sensors``, ...).
    """
    data = scenario.data
    truth = generated.truth
    datasheet, true_values = _datasheet(data, generated.truth_keys)
    base = generated.drawn.get("gnss_base", {}).get("position")
    if base is not None and "gnss_base" in datasheet:
        # a base station's antenna is surveyed: its position is what a user of it knows
        datasheet["gnss_base"]["surveyed_position"] = dict(base)
    return {
        "knowledge": KNOWLEDGE,
        "datasheet": datasheet,
        "truth_parameters": true_values,
        "timing": generated.timing,
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
        **({"gnss_base": base} if base is not None else {}),
    }


def stream_units(scenario: dict) -> dict[str, dict[str, str]]:
    """Column units that differ from ``columns.STREAMS`` for this scenario: an IMU with
    ``output: increment`` writes angle (rad) and velocity (m/s) increments over each sample
    interval, so its file's ``unit`` metadata says so."""
    imu = scenario["sensors"].get("imu")
    if imu is not None and imu.get("output") == "increment":
        return {"imu": dict(col.IMU_INCREMENT_UNITS)}
    return {}


def generate_dataset(scenario: Scenario, out_dir: Path, force: bool = False,
                     show_progress: bool = True, honour_lock: bool = True) -> Path:
    """Generate a scenario's dataset into ``out_dir`` (atomically; refuses to overwrite without
    ``force``). Returns ``out_dir``. Each stream no fault changes is written while the others are
    made. The scenario's files are inputs: never written over; ``honour_lock=False`` only for a
    campaign's own runs, writing into the folder it holds."""
    out_dir = Path(out_dir)
    with (atomic_output_dir(out_dir, force, scenario.input_files, honour_lock) as tmp,
          DatasetWriter(tmp, stream_units(scenario.data)) as writer):
        generated = generate_streams(scenario, show_progress, frames=False,
                                     on_final=writer.write)
        imu = scenario.data["sensors"].get("imu")
        described = {"imu": {"imu_output": imu["output"]}} if imu is not None else {}
        writer.finish(build_manifest(scenario, generated), generated.streams, described)
    return out_dir
