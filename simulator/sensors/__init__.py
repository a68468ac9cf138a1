"""Sensor models: each turns the exact trajectory and its own random stream into stream tables.

``SENSOR_FIELDS`` holds each sensor's scenario schema (``sensors.<name>``) and ``SENSOR_MODELS``
its model class; the dataset generator builds every configured sensor from these two tables.
"""

from __future__ import annotations

from simulator.sensors.gnss import GNSS_FIELD, Gnss
from simulator.sensors.imu import IMU_FIELD, Imu

SENSOR_FIELDS = {"imu": IMU_FIELD, "gnss": GNSS_FIELD}
SENSOR_MODELS = {"imu": Imu, "gnss": Gnss}
