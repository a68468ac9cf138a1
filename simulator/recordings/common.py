"""What every recording importer shares: the reference trajectory as ``truth.parquet``, the
sensors a recording's streams resemble as the manifest's datasheet, GNSS gaps as events, and the
dataset written atomically (SPEC section 9).

A ``Recording`` holds the streams already in landnav's columns and units with ``t`` in seconds
since the recording's start (every stream's own timestamps, irregular sampling and gaps kept),
the GPS and UTC time of that start, the reference trajectory and where it came from, the sensor
blocks of a scenario that describes the recording's sensors (presets and rates: they become the
datasheet, what a user of the recording knows), and ``lacks``: the columns a stream carries as
NaN because the recording does not have them, with the reason, so that an estimator that needs
them is refused by name (``simulator.replay``).

Public names
------------
Recording, reference_truth, write_recording, gnss_gap_events.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

import simulator
from simulator import columns as col
from simulator.dataset.generate import vehicle_datasheet
from simulator.dataset.io import DatasetWriter
from simulator.earth import dcm_to_euler, ecef_to_geodetic, ned_to_ecef_matrix
from simulator.outputs import atomic_output_dir
from simulator.timebase import gps_to_utc


@dataclass
class Recording:
    """A real recording in landnav's streams (see the module docstring)."""

    kind: str
    sources: list[str]
    gps_week: int
    gps_tow: float                      # GPS seconds of week of t = 0
    streams: dict[str, pd.DataFrame]    # imu, odometer, gnss_fix, gnss_raw, ... and truth
    reference: str                      # what the truth is: the recording's reference solution
    sensors: dict[str, Any]             # scenario sensor blocks (presets, rates) of the recording
    lacks: dict[str, str] = field(default_factory=dict)  # stream -> what it lacks, and why
    notes: list[str] = field(default_factory=list)       # conversions made, for the manifest
    vehicle: str = "rigid"              # vehicle preset of the datasheet (geometry unknown)

    @property
    def utc_start(self) -> str:
        utc = gps_to_utc(self.gps_week, self.gps_tow)
        return utc.isoformat(timespec="milliseconds") + "Z"


def reference_truth(t: np.ndarray, pos_ecef: np.ndarray, vel_ecef: np.ndarray,
                    c_b_e: np.ndarray | None) -> pd.DataFrame:
    """A reference trajectory in the columns of ``truth.parquet``.

    Parameters
    ----------
    t : (n,) s since the recording's start.
    pos_ecef, vel_ecef : (n, 3) ECEF position (m) and velocity (m/s).
    c_b_e : (n, 3, 3) body (FRD) to ECEF rotation, or None when the reference has no attitude
        (roll, pitch, yaw NaN).

    The body rate and specific force (``w*``, ``f*``) are NaN (a reference solution does not
    carry them); ``speed`` is the velocity's norm and ``distance`` its trapezoidal integral.
    """
    lat, lon, alt = ecef_to_geodetic(np.asarray(pos_ecef, dtype=float))
    c_ne = ned_to_ecef_matrix(lat, lon)                      # (n, 3, 3) NED -> ECEF
    v_ned = np.einsum("nji,nj->ni", c_ne, vel_ecef)          # C_e^n v^e
    if c_b_e is None:
        roll = pitch = yaw = np.full(len(t), np.nan)
    else:
        c_bn = np.einsum("nji,njk->nik", c_ne, c_b_e)        # C_e^n C_b^e
        roll, pitch, yaw = dcm_to_euler(c_bn)
    speed = np.linalg.norm(v_ned, axis=1)
    distance = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(t))])
    nan = np.full(len(t), np.nan)
    return pd.DataFrame({
        "t": t, "lat": np.degrees(lat), "lon": np.degrees(lon), "alt": alt,
        "vn": v_ned[:, 0], "ve": v_ned[:, 1], "vd": v_ned[:, 2],
        "roll": roll, "pitch": pitch, "yaw": yaw,
        "wx": nan, "wy": nan, "wz": nan, "fx": nan, "fy": nan, "fz": nan,
        "speed": speed, "distance": distance, "zone": np.full(len(t), "", dtype=object)})


def gnss_gap_events(fix_t: np.ndarray, end_t: float, nominal_interval_s: float
                    ) -> pd.DataFrame:
    """Every stretch of more than three nominal fix intervals without a GNSS fix, as
    ``gnss_outage`` rows of ``events.parquet`` (SPEC section 5), so a recording's natural
    outages are scored like simulated ones."""
    edges = np.concatenate([[0.0], np.asarray(fix_t, dtype=float), [end_t]])
    gap = np.diff(edges)
    long = np.flatnonzero(gap > 3.0 * nominal_interval_s)
    return pd.DataFrame({"t_start": edges[long], "t_end": edges[long + 1],
                         "kind": ["gnss_outage"] * len(long),
                         "detail": ["no fix in the recording"] * len(long)})


def _resolved_sensors(sensors: dict[str, Any], duration_s: float) -> dict[str, Any]:
    """The recording's sensor blocks with every default filled, through the scenario schema
    (the same resolution as a scenario's) on a standstill as long as the recording (a slow
    stream, a station's 30 s RINEX, is checked against the recording's span)."""
    from simulator.scenario import validate_data

    data = {"name": "recording", "start": {"utc": "2020-01-01T00:00:00Z", "lat": 0.0,
                                           "lon": 0.0, "alt": 0.0},
            "trajectory": {"kind": "segments",
                           "segments": [{"stop": {"duration": max(10.0, duration_s)}}]},
            "sensors": sensors}
    return validate_data(data, "<recording sensors>")["sensors"]


def write_recording(recording: Recording, out_dir: str | Path, force: bool = False,
                    sources: Iterable[str | Path] = ()) -> Path:
    """Write a recording as a dataset (atomically; an existing ``out_dir`` only with
    ``force``). The manifest says ``"reference": true``, where the reference came from, what
    each stream lacks and the conversions made."""
    streams = {k: v for k, v in recording.streams.items() if v is not None}
    truth = streams["truth"]
    first = truth.iloc[0]
    sensors = _resolved_sensors(recording.sensors,
                                float(truth["t"].iloc[-1]) - float(truth["t"].iloc[0]))
    datasheet = {k: v for k, v in sensors.items() if v is not None}
    datasheet["vehicle"] = vehicle_datasheet(recording.vehicle)
    end_t = float(max(float(f["t"].iloc[-1]) for f in streams.values() if "t" in f))
    if "gnss_fix" in streams:
        rate = float(sensors["gnss"]["rate"]) if sensors.get("gnss") else 1.0
        streams["events"] = gnss_gap_events(streams["gnss_fix"]["t"].to_numpy(), end_t,
                                            1.0 / rate)
    manifest = {
        "reference": True,
        "reference_source": recording.reference,
        "recording": {"kind": recording.kind, "sources": recording.sources,
                      "notes": recording.notes, "imported": dt.date.today().isoformat()},
        "lacks": recording.lacks,
        "datasheet": datasheet,
        "knowledge": {"user": ["datasheet", "gps_time_start", "utc_start", "streams",
                               "duration", "recording", "lacks"],
                      "truth": ["reference_source", "origin", "truth.parquet",
                                "events.parquet"]},
        "software": {"landnav": simulator.__version__},
        "gps_time_start": {"week": int(recording.gps_week), "tow": float(recording.gps_tow)},
        "utc_start": recording.utc_start,
        "origin": {"lat": float(first["lat"]), "lon": float(first["lon"]),
                   "alt": float(first["alt"])},
        "duration": end_t,
        "seed": None,
        "sensors": {},
    }
    units = {}
    described = {}
    if "imu" in streams:
        described["imu"] = {"imu_output": "rate"}
    out_dir = Path(out_dir)
    with (atomic_output_dir(out_dir, force, sources) as tmp,  # a recording is never written over
          DatasetWriter(tmp, units) as writer):
        writer.finish(manifest, {k: _table(k, v) for k, v in streams.items()}, described)
    return out_dir


# the units of the multi-system columns of SPEC section 5 a recording may carry
SIGNAL_UNITS = {"system": "", "signal": "", "frequency": "Hz", "carrier_phase": "cycles",
                "lli": "1", "lock_time": "s", "group_delay": "m"}


def _table(name: str, frame: pd.DataFrame) -> pd.DataFrame:
    """A stream's columns in the SPEC's order first (extra columns after them), with the units
    of its extra columns."""
    spec = list(col.STREAMS[name][1]) if name in col.STREAMS else []
    ordered = [c for c in spec if c in frame] + [c for c in frame if c not in spec]
    table = frame[ordered].reset_index(drop=True)
    units = {c: u for c, u in SIGNAL_UNITS.items() if c in table and c not in spec}
    table.attrs = {"units": {**units, **frame.attrs.get("units", {})}}
    return table
