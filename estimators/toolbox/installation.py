"""The installation geometry a user measures on the car, read from the dataset's datasheet (the
manifest's ``datasheet``, handed to every estimator as ``Estimator.datasheet``; docs/dataset-
format.md): where the non-holonomic constraint holds, where the GNSS antenna is, and how the IMU
is mounted.

* ``rear_axle``: the point above the rear axle's centre from the IMU (body FRD, m), from the
  datasheet's ``vehicle`` block; None on a ``rigid`` body (the truth's point follows the road
  and the constraint holds at the IMU itself) or when the datasheet has no vehicle.
* ``antenna``: the GNSS ``antenna_lever_arm`` from the IMU (body FRD, m); None when zero.
* ``mounting``: the direction cosine matrix C_s^v that turns the IMU's sensor-frame outputs into
  the vehicle frame, x_v = C_s^v x_s (the datasheet's ``imu.mounting``, roll, pitch, yaw in
  degrees, x_s = C_v^s x_v as ``simulator.sensors.imu`` applies it); None when zero. A filter
  that rotates its IMU samples with it navigates the vehicle frame, in which the constraints
  are written. (The car's body pitches and rolls on its suspension: that is the vehicle
  frame's own attitude, which the strapdown tracks, not a mounting.)
* ``wheelbase``: m; None when unknown.
* ``odometer``: the point whose travelled distance the odometer counts, from the IMU (body FRD,
  m): the truth's road-following centre of gravity, -``imu_position`` of the datasheet's
  ``vehicle`` block (the simulated odometer counts the distance along the road profile,
  ``simulator.sensors.odometer``, which is that point's path, docs/vehicle.md; in a turn of
  radius R it runs faster than the rear axle by 1 / sqrt(1 - (l_r / R)^2), 1 % in an 11 m
  helix); None without a vehicle block.

Public names
------------
Installation.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from simulator.earth import euler_to_dcm


def _vector(value: Any) -> np.ndarray | None:
    if value is None:
        return None
    v = np.asarray(value, dtype=float)
    return v if v.any() else None


@dataclass(frozen=True)
class Installation:
    """The geometry of the module docstring."""

    rear_axle: np.ndarray | None = None
    antenna: np.ndarray | None = None
    mounting: np.ndarray | None = None
    wheelbase: float | None = None
    odometer: np.ndarray | None = None

    @classmethod
    def from_datasheet(cls, datasheet: Mapping[str, Any]) -> Installation:
        """Read from a manifest's ``datasheet`` (an empty mapping gives every field None)."""
        vehicle = datasheet.get("vehicle") or {}
        gnss = datasheet.get("gnss") or {}
        mount = _vector((datasheet.get("imu") or {}).get("mounting"))
        rear = vehicle.get("rear_axle")
        cog = vehicle.get("imu_position")
        return cls(rear_axle=None if rear is None else np.asarray(rear, dtype=float),
                   odometer=None if cog is None else -np.asarray(cog, dtype=float),
                   antenna=_vector(gnss.get("antenna_lever_arm")),
                   mounting=None if mount is None else euler_to_dcm(*np.radians(mount)),
                   wheelbase=vehicle.get("wheelbase"))
