"""The drive: what a resolved scenario makes of the road before any sensor looks at it - its road
profile, its resolved start, the vehicle on that road (``simulator.vehicle``), the exact truth
kinematics, its UTC epoch and its environment. One
immutable object, built once while the scenario is validated (validation needs the profile to
check what the vehicle can drive and when faults fall) and handed to the generator.

The kinematics are computed on first use (``Drive.truth``): ``landnav validate`` never needs
them, and the dataset generator asks for them only after it has started the IMU's random draws
in worker threads, so the two overlap.

Public names
------------
Drive, build_profile, build_drive.
"""

from __future__ import annotations

import datetime as dt
import functools
from collections.abc import Mapping
from dataclasses import dataclass

from simulator.errors import InputError
from simulator.schema import Context
from simulator.threads import one_blas_thread
from simulator.timebase import parse_utc
from simulator.trajectory import PROFILE_BUILDERS
from simulator.trajectory.kinematics import Kinematics, kinematics_from_profile, truth_grid
from simulator.trajectory.segments import RoadProfile
from simulator.vehicle import vehicle_body


@dataclass(frozen=True)
class Drive:
    """A scenario's drive: road profile, resolved start, UTC epoch and environment, and the truth
    kinematics built from them on first use. Nothing changes it after it is built (the
    mappings are plain dictionaries so that a campaign can send the drive to its workers;
    nothing writes to them)."""

    profile: RoadProfile
    start: Mapping  # {utc, lat, lon (deg), alt (m), heading (deg)}, a source's own start applied
    utc_start: dt.datetime
    environment: Mapping  # the resolved ``environment`` block: zones, canyon, magnetic field
    rate_hz: float  # of the truth grid
    roll_gradient: float  # rad per m/s^2 of lateral acceleration (``limits.roll_gradient``)
    vehicle: str | Mapping  # the resolved ``vehicle`` block: "rigid", a preset or parameters

    @property
    def duration_s(self) -> float:
        return self.profile.duration_s

    @functools.cached_property
    def truth(self) -> Kinematics:
        """The exact truth trajectory (built once, on first use): the vehicle's body on the road,
        then the kinematics of both."""
        profile, body = vehicle_body(self.profile, self.vehicle,
                                     truth_grid(self.profile.duration_s, self.rate_hz))
        return kinematics_from_profile(profile, self.start, self.rate_hz, self.roll_gradient,
                                       self.utc_start, self.environment, body)


def build_profile(scenario: dict, ctx: Context | None = None) -> RoadProfile | None:
    """The road and speed profile of a (resolved) scenario, from its trajectory source. With
    ``ctx`` a manoeuvre the vehicle cannot drive is reported there (and None returned);
    without, it raises InputError."""
    try:
        return PROFILE_BUILDERS[scenario["trajectory"]["kind"]](scenario, ctx)
    except ValueError as exc:
        raise InputError(str(exc)) from None


@one_blas_thread
def build_drive(scenario: dict, profile: RoadProfile | None = None) -> Drive:
    """The drive of a resolved scenario (of its already built ``profile`` when given)."""
    profile = build_profile(scenario) if profile is None else profile
    return Drive(profile=profile,
                 start={**scenario["start"], **(profile.start or {})},
                 utc_start=parse_utc(scenario["start"]["utc"]),
                 environment=scenario["environment"],
                 rate_hz=scenario["trajectory"]["rate"],
                 roll_gradient=scenario["limits"]["roll_gradient"],
                 vehicle=scenario["vehicle"])
