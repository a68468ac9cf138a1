"""Small exact trajectories for the sensor tests (built by ``conftest.build_drive``)."""

from __future__ import annotations

import datetime as dt
from pathlib import Path

from conftest import build_drive

from simulator.trajectory.kinematics import Kinematics

SHARED = Path(__file__).resolve().parents[2] / "shared"

DRIVE = [
    {"stop": {"duration": 10}}, {"accelerate": {"to_speed": 12, "accel": 1.5}},
    {"straight": {"length": 300}}, {"turn": {"angle": 90, "radius": 40}},
    {"slope": {"grade": 0.06, "length": 200}}, {"accelerate": {"to_speed": 0, "accel": 2.0}},
    {"stop": {"duration": 5}},
]


def truth_from_segments(segments: list[dict], rate_hz: float = 100.0,
                        start: dict | None = None,
                        utc: dt.datetime = dt.datetime(2020, 1, 1),
                        environment: dict | None = None) -> Kinematics:
    """``conftest.build_drive`` with the sensor tests' start (37 N, 127 E, heading 30 deg) and
    epoch (2020-01-01)."""
    return build_drive(segments, rate_hz=rate_hz,
                       start=start or {"lat": 37.0, "lon": 127.0, "alt": 40.0, "heading": 30.0},
                       utc=utc.strftime("%Y-%m-%dT%H:%M:%SZ"), environment=environment)


def static_truth(duration_s: float) -> Kinematics:
    """A vehicle standing still for ``duration_s`` (base grid 1 Hz: only the IMU samples it)."""
    return truth_from_segments([{"stop": {"duration": duration_s}}], rate_hz=1.0)


def drive_truth() -> Kinematics:
    """A short drive with a stop, acceleration, straight, turn, slope and braking to a stop."""
    return truth_from_segments(DRIVE)
