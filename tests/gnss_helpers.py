"""Shared builders for the GNSS tests: short drives and receivers without the scenario loader."""

from __future__ import annotations

import datetime as dt

from simulator.schema import Context
from simulator.sensors.gnss import GNSS_FIELD, Gnss
from simulator.trajectory.kinematics import Kinematics, kinematics_from_profile
from simulator.trajectory.segments import LIMITS_FIELD, SEGMENT_FIELD, build_road_profile

START = {"lat": 37.0, "lon": 127.0, "alt": 40.0, "heading": 0.0}


def drive(segments: list[dict], zones: dict | None = None, start: dict | None = None,
          utc: dt.datetime = dt.datetime(2024, 5, 1, 3, 0), rate_hz: float = 100.0
          ) -> Kinematics:
    ctx = Context("test")
    limits = LIMITS_FIELD.check({}, ("limits",), ctx)
    segs = [SEGMENT_FIELD.check(s, ("segments", i), ctx) for i, s in enumerate(segments)]
    profile = build_road_profile(segs, limits, ctx)
    assert not ctx.problems, ctx.problems
    return kinematics_from_profile(profile, start or START, rate_hz, limits["roll_gradient"],
                                   utc, {"zones": zones or {}})


def receiver(**config) -> Gnss:
    ctx = Context("test")
    resolved = GNSS_FIELD.check(config, ("sensors", "gnss"), ctx)
    assert not ctx.problems, ctx.problems
    return Gnss(resolved)
