"""Shared builders for the GNSS tests: short drives (``conftest.build_drive``) and receivers."""

from __future__ import annotations

import datetime as dt

from conftest import build_drive

from simulator.schema import Context
from simulator.sensors.gnss import GNSS_FIELD, Gnss
from simulator.trajectory.kinematics import Kinematics

START = {"lat": 37.0, "lon": 127.0, "alt": 40.0, "heading": 0.0}


def drive(segments: list[dict], zones: dict | None = None, start: dict | None = None,
          utc: dt.datetime = dt.datetime(2024, 5, 1, 3, 0), rate_hz: float = 100.0
          ) -> Kinematics:
    """``conftest.build_drive`` with the GNSS tests' start (37 N, 127 E, heading 0) and zones."""
    return build_drive(segments, rate_hz=rate_hz, start=start or START,
                       utc=utc.strftime("%Y-%m-%dT%H:%M:%SZ"), environment={"zones": zones or {}})


def receiver(**config) -> Gnss:
    ctx = Context("test")
    resolved = GNSS_FIELD.check(config, ("sensors", "gnss"), ctx)
    assert not ctx.problems, ctx.problems
    return Gnss(resolved)
