"""Sensor models: each turns the exact trajectory and its own random stream into stream tables.

``SENSOR_FIELDS`` holds each sensor's scenario schema (``sensors.<name>``) and ``SENSOR_MODELS``
its model class; the dataset generator builds every configured sensor from these two tables. A
model with a ``host`` (the GNSS base station) has its streams made by that sensor's model
(``attach``), which shares its sky with it.
"""

from __future__ import annotations

from simulator.schema import Context
from simulator.sensors.baro import BARO_FIELD, Barometer
from simulator.sensors.gnss import GNSS_FIELD, Gnss
from simulator.sensors.gnss_base import GNSS_BASE_FIELD, GnssBase
from simulator.sensors.imu import IMU_FIELD, Imu
from simulator.sensors.mag import MAG_FIELD, Magnetometer
from simulator.sensors.odometer import ODOMETER_FIELD, Odometer

SENSOR_FIELDS = {"imu": IMU_FIELD, "odometer": ODOMETER_FIELD, "gnss": GNSS_FIELD,
                 "gnss_base": GNSS_BASE_FIELD, "baro": BARO_FIELD, "mag": MAG_FIELD}
SENSOR_MODELS = {"imu": Imu, "odometer": Odometer, "gnss": Gnss, "gnss_base": GnssBase,
                 "baro": Barometer, "mag": Magnetometer}


def resolve_block(name: str, block: dict) -> dict:
    """A sensor block as a scenario's validation resolves it (preset applied, defaults filled,
    units converted), for code that builds a sensor by hand; the models take resolved blocks
    and do not check them again. Raises ValueError naming every problem."""
    ctx = Context(f"sensors.{name}")
    resolved = SENSOR_FIELDS[name].check(block, ("sensors", name), ctx)
    if ctx.problems:
        raise ValueError("; ".join(str(p) for p in ctx.problems))
    return resolved
