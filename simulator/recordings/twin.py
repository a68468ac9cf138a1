"""A dataset's twin: a scenario that drives the simulator along the dataset's reference (or
truth) trajectory, at its date and place, with the sensor presets and rates of its datasheet
(SPEC section 3, ``landnav twin``).

The trajectory is a ``recorded`` one (``simulator.trajectory.recorded``) read from a Parquet
log written beside the scenario (``NAME.drive.parquet``: t, lat, lon, alt and, where the
reference has it, roll), so the twin is self-contained; ``start.utc`` is the dataset's
``utc_start``, so the default sky is the one of that day. Each sensor the dataset has gets the
preset of its datasheet at the datasheet's rate (a recording's datasheet names the nearest
landnav presets, ``simulator.recordings.common``), and the GNSS receiver its outputs.

Public names
------------
twin_scenario, write_twin.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from simulator.dataset.io import Dataset
from simulator.errors import InputError, Problem
from simulator.outputs import atomic_output_file, os_problem

SENSOR_STREAMS = {"imu": "imu", "odometer": "odometer", "gnss": "gnss_fix", "baro": "baro",
                  "mag": "mag"}
KEPT_KEYS = {"imu": ("preset", "rate", "output"), "odometer": ("preset", "rate"),
             "gnss": ("preset", "rate", "outputs", "elevation_mask"),
             "baro": ("preset", "rate"), "mag": ("preset", "rate")}


def twin_scenario(dataset: Dataset, log_file: str) -> dict[str, Any]:
    """The twin scenario of ``dataset`` as a mapping, its trajectory read from ``log_file``
    (a path relative to the scenario)."""
    sheet = dataset.manifest.get("datasheet")
    if not isinstance(sheet, dict) or not sheet:
        raise InputError([Problem(str(dataset.path / "manifest.json"), None, "datasheet",
                                  "missing: a twin takes its sensors from the datasheet")])
    sensors: dict[str, Any] = {}
    for sensor, stream in SENSOR_STREAMS.items():
        block = sheet.get(sensor)
        if not isinstance(block, dict) or not dataset.has(stream):
            continue
        kept = {k: block[k] for k in KEPT_KEYS[sensor] if block.get(k) is not None}
        if sensor == "gnss":
            outputs = [o for o, s in (("fix", "gnss_fix"), ("raw", "gnss_raw"))
                       if dataset.has(s)]
            kept["outputs"] = outputs
        sensors[sensor] = kept
    if sensor_missing := [s for s in ("imu", "gnss") if s in sensors and "preset" not in
                          sensors[s]]:
        raise InputError([Problem(str(dataset.path / "manifest.json"), None,
                                  f"datasheet.{s}.preset", "missing") for s in sensor_missing])
    origin = dataset.field("origin")
    name = f"twin-of-{Path(dataset.path).resolve().name}"
    return {
        "name": name,
        "seed": 1,
        "start": {"utc": str(dataset.field("utc_start")), "lat": float(origin["lat"]),
                  "lon": float(origin["lon"]), "alt": float(origin["alt"])},
        "trajectory": {"kind": "recorded", "file": log_file},
        "sensors": sensors,
        "estimators": [],
    }


def write_twin(dataset: Dataset, scenario_path: str | Path, force: bool = False) -> Path:
    """Write the twin scenario and its drive log (``STEM.drive.parquet`` beside it), both
    atomically; the scenario is validated before either is moved into place."""
    from simulator.scenario import load_scenario

    out = Path(scenario_path)
    log = out.with_name(f"{out.stem}.drive.parquet")
    truth = dataset.read("truth")
    columns = ["t", "lat", "lon", "alt"] + (["roll"] if np.isfinite(truth["roll"]).any()
                                            else [])
    drive = truth[columns].dropna(subset=["lat", "lon", "alt"])
    drive = drive.assign(t=drive["t"] - drive["t"].iloc[0])
    data = twin_scenario(dataset, log.name)
    text = (f"# The twin of {dataset.path}: the simulator driven along its reference\n"
            f"# trajectory ({log.name}) with the sensors of its datasheet.\n"
            + yaml.safe_dump(data, sort_keys=False))
    try:
        with tempfile.TemporaryDirectory() as check:  # validated before anything is written
            drive.to_parquet(Path(check) / log.name, index=False)
            (Path(check) / out.name).write_text(text, encoding="utf-8")
            load_scenario(Path(check) / out.name)
    except OSError as exc:  # the temporary folder is full or read-only
        raise os_problem(tempfile.gettempdir(), exc) from None
    with (atomic_output_file(log, force, [dataset.path], "twin-drive") as log_tmp,
          atomic_output_file(out, force, [dataset.path], "twin-scenario") as out_tmp):
        drive.to_parquet(log_tmp, index=False)
        Path(out_tmp).write_text(text, encoding="utf-8")
    return out
