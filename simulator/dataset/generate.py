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

import platform
import zlib
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path

import numpy as np

from simulator.dataset.events import events_table, gnss_outage_intervals, zone_events
from simulator.dataset.io import atomic_output_dir, write_dataset
from simulator.errors import InputError
from simulator.faults.apply import apply_faults
from simulator.progress import progress
from simulator.scenario import Scenario
from simulator.sensors import SENSOR_MODELS
from simulator.tables import Table, as_frames, column
from simulator.timebase import parse_utc, utc_to_gps
from simulator.trajectory import PROFILE_BUILDERS
from simulator.trajectory.kinematics import Kinematics, kinematics_from_profile


def build_truth(scenario: dict) -> Kinematics:
    """The exact truth trajectory of a resolved scenario."""
    traj = scenario["trajectory"]
    try:
        profile = PROFILE_BUILDERS[traj["kind"]](scenario, None)
    except ValueError as exc:
        raise InputError(str(exc)) from None
    start = {**scenario["start"], **(profile.start or {})}
    truth = kinematics_from_profile(profile, start, traj["rate"],
                                    scenario["limits"]["roll_gradient"])
    truth.utc_start = parse_utc(scenario["start"]["utc"])
    truth.gps_week, truth.gps_tow = utc_to_gps(truth.utc_start)
    truth.environment = scenario["environment"]
    return truth


def sensor_rng(seed: int, name: str) -> np.random.Generator:
    """The random stream of one sensor: a SeedSequence child keyed by the sensor's name, so adding
    a sensor does not change the others (SPEC section 2)."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(zlib.crc32(
        name.encode()),)))


@dataclass
class Generated:
    truth: Kinematics
    streams: dict[str, Table]  # DataFrames unless generate_streams(frames=False)
    drawn: dict[str, dict] = field(default_factory=dict)


def generate_streams(scenario: dict, show_progress: bool = True,
                     frames: bool = True) -> Generated:
    """Truth table, every configured sensor's streams, and the events table.

    With ``frames`` (the default) every stream is a DataFrame; without, the tables stay as the
    sensors and faults left them (column tables or DataFrames), which is all the writer needs.
    """
    truth = build_truth(scenario)
    streams: dict[str, Table] = {"truth": truth.columns()}
    drawn: dict[str, dict] = {}
    sensors = {k: v for k, v in scenario["sensors"].items() if v is not None}
    for name in progress(sensors, "sensors", show_progress):
        model = SENSOR_MODELS[name](sensors[name])
        streams.update(model.generate(truth, sensor_rng(scenario["seed"], name)))
        drawn[name] = model.drawn
    rows = zone_events(truth.profile.zones) + apply_faults(streams, scenario, truth)
    for t_start, t_end in _outages(streams, truth.duration_s):
        rows.append({"t_start": t_start, "t_end": t_end, "kind": "gnss_outage", "detail": ""})
    gnss = sensors.get("gnss")
    if gnss is not None and "raw" not in gnss["outputs"]:
        streams.pop("gnss_raw", None)  # kept until here for the faults and the outage table
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


def _versions() -> dict[str, str]:
    out = {"python": platform.python_version()}
    for pkg in ("landnav", "numpy", "scipy", "pandas", "pyarrow"):
        try:
            out[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            out[pkg] = "not installed"
    return out


def build_manifest(scenario: Scenario, generated: Generated) -> dict:
    """The manifest (SPEC section 5) without its ``streams`` block."""
    data = scenario.data
    truth = generated.truth
    return {
        "scenario": data,
        "seed": data["seed"],
        "overrides": scenario.overrides,
        "software": _versions(),
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
    ``force``). Returns ``out_dir``."""
    out_dir = Path(out_dir)
    with atomic_output_dir(out_dir, force) as tmp:
        generated = generate_streams(scenario.data, show_progress, frames=False)
        write_dataset(tmp, build_manifest(scenario, generated), generated.streams)
    return out_dir
