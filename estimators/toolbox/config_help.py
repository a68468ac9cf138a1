"""The ``config_help`` lines the built-in INS filters share: key -> (SI unit, meaning), one
meaning for each key (``landnav estimators NAME`` shows them).

Public names
------------
SHARED_HELP, shared_help.
"""

from __future__ import annotations

__all__ = ["SHARED_HELP", "shared_help"]

SHARED_HELP: dict[str, tuple[str, str]] = {
    "nhc": ("", "non-holonomic constraint: zero lateral and vertical body velocity"),
    "nhc_point": ("", "where the constraint holds: rear_axle (the datasheet's) or imu"),
    "initial_position_std": ("m", "initial position uncertainty per axis, 1-sigma"),
    "initial_velocity_std": ("m/s", "initial velocity uncertainty per axis, 1-sigma"),
    "initial_attitude_std": ("deg", "initial roll, pitch, yaw uncertainty, 1-sigma"),
}


def shared_help(*keys: str) -> dict[str, tuple[str, str]]:
    """The shared lines of ``keys``, to unpack into an estimator's ``config_help``."""
    return {key: SHARED_HELP[key] for key in keys}
