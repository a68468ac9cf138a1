"""Trajectory sources: each turns its ``trajectory`` block into a ``RoadProfile`` (road geometry
along the distance travelled and the distance in time), from which ``kinematics`` computes the
exact truth.

``TRAJECTORY_KINDS`` maps each ``trajectory.kind`` to its schema record and ``PROFILE_BUILDERS``
to the function ``(scenario, ctx) -> RoadProfile | None`` that builds it (reporting manoeuvres the
vehicle cannot drive into ``ctx`` when one is given).
"""

from __future__ import annotations

from collections.abc import Callable

from simulator.schema import Context, ListOf, Number, Record
from simulator.trajectory.recorded import RECORDED_FIELD, build_recorded_profile
from simulator.trajectory.segments import (
    DRIVE_SEGMENT_FIELD,
    RoadProfile,
    build_road_profile,
    expand_repeats,
)
from simulator.trajectory.sumo import SUMO_FIELD, build_sumo_profile

_RATE = Number("Hz", None, gt=0, max=10000,
               doc="base rate of the truth table (default: the IMU rate, or 100 Hz)")

TRAJECTORY_KINDS: dict[str, Record] = {
    "segments": Record({"segments": ListOf(DRIVE_SEGMENT_FIELD, min_len=1), "rate": _RATE},
                       post=expand_repeats),
    "sumo": SUMO_FIELD,
    "recorded": RECORDED_FIELD,
}


def _segments_profile(scenario: dict, ctx: Context | None) -> RoadProfile | None:
    return build_road_profile(scenario["trajectory"]["segments"], scenario["limits"], ctx)


PROFILE_BUILDERS: dict[str, Callable[[dict, Context | None], RoadProfile | None]] = {
    "segments": _segments_profile,
    "sumo": build_sumo_profile,
    "recorded": build_recorded_profile,
}
