"""The vehicle between the road and the truth (issue 13): a car body on its suspension, with side
slip, riding over a rough road; or, with ``vehicle: rigid``, a point following the road exactly.

``params`` holds the scenario block and the car presets, ``road`` the road under the wheels
(roughness, bumps, camber), ``suspension`` the full-car ride model, ``body`` the body's motion
as exactly differentiable curves that ``simulator.trajectory.kinematics`` turns into the truth.

Public names
------------
ROAD_STREAM, VEHICLE_FIELD, vehicle_body.
"""

from __future__ import annotations

import numpy as np

from simulator.stochastic import stream_rng
from simulator.trajectory.segments import RoadProfile
from simulator.vehicle.body import BodyMotion, build_body, level_road
from simulator.vehicle.params import VEHICLE_FIELD, vehicle_parameters

__all__ = ["ROAD_STREAM", "VEHICLE_FIELD", "vehicle_body"]

ROAD_STREAM = "road"  # name of the road's random stream (roughness, engine phase)


def vehicle_body(profile: RoadProfile, block: str | dict,
                 t_grid: np.ndarray) -> tuple[RoadProfile, BodyMotion | None]:
    """The road profile the body follows and the body's motion for a resolved ``vehicle``
    block: the profile unchanged and None with ``vehicle: rigid``; else the profile without its
    speed bumps in the grade (the wheels ride over them) and the body on its suspension.

    The road draws from its own random stream (``stochastic.stream_rng`` of ``road_seed``,
    keyed ``ROAD_STREAM``): the road is part of the drive, like the trajectory, so it does not
    change with the scenario's seed, which draws the sensors' errors."""
    params = vehicle_parameters(block)
    if params is None:
        return profile, None
    rng = stream_rng(params["road_seed"], ROAD_STREAM)
    level = level_road(profile)  # keeps ``bumps``, which the wheels ride over
    return level, build_body(level, params, t_grid, rng)
