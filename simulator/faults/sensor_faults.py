"""Faults of the IMU, odometer and barometer, and of any stream's sampling.

Kinds: ``imu_bias_step``, ``imu_saturation_burst``, ``odometer_slip``,
``odometer_scale_change``, ``baro_jump``, ``sensor_dropout``, ``timestamp_jitter``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from simulator import columns as col
from simulator.faults.base import fault_kind, in_intervals
from simulator.schema import ListOf, Number, Text

if TYPE_CHECKING:
    import pandas as pd

_AXES = ListOf(Text(choices=list(col.IMU_AXES)), list(col.IMU_AXES), min_len=1,
               doc="the IMU channels it acts on")


def _imu_axes(imu: pd.DataFrame, axes: list[str], sensors: dict
              ) -> list[tuple[str, str, float]]:
    """(axis, group, scale) of the requested axes the unit has; scale converts a rate to the
    stream's unit (1 for rate output, the sample interval for increment output)."""
    config = sensors.get("imu") or {}
    scale = 1.0 / config["rate"] if config.get("output") == "increment" else 1.0
    return [(a, a.split("_")[0], scale) for a in axes if a in imu]


@fault_kind("imu_bias_step", {
    "axes": _AXES,
    "gyro": Number("rad/s", 0.0, doc="bias step of the gyros among axes"),
    "accel": Number("m/s^2", 0.0, doc="bias step of the accelerometers among axes"),
}, ("imu",), "a step in the IMU bias")
def _imu_bias_step(streams, intervals, params, context) -> None:
    imu = streams["imu"]
    mask = in_intervals(imu["t"].to_numpy(), intervals)
    for axis, group, scale in _imu_axes(imu, params["axes"], context.sensors):
        imu.loc[mask, axis] = imu.loc[mask, axis].to_numpy() + params[group] * scale


@fault_kind("imu_saturation_burst", {
    "axes": ListOf(Text(choices=list(col.IMU_AXES)), ["accel_x", "accel_y", "accel_z"],
                   doc="the IMU channels it acts on",
                   min_len=1),
    "gyro_amplitude": Number("rad/s", 0.0, min=0, doc="shock oscillation on the gyros"),
    "accel_amplitude": Number("m/s^2", 0.0, min=0, doc="shock oscillation on the accels"),
    "frequency": Number("Hz", 30.0, gt=0, doc="oscillation frequency of the shock"),
    "gyro_range": Number("rad/s", None, gt=0, doc="gyro saturation (default: unit's range)"),
    "accel_range": Number("m/s^2", 4 * 9.80665, gt=0, doc="accelerometer saturation"),
}, ("imu",), "a shock (pothole, door slam) that drives the IMU into saturation")
def _imu_saturation_burst(streams, intervals, params, context) -> None:
    imu = streams["imu"]
    t = imu["t"].to_numpy()
    mask = in_intervals(t, intervals)
    wave = np.sin(2 * np.pi * params["frequency"] * t[mask])
    for axis, group, scale in _imu_axes(imu, params["axes"], context.sensors):
        values = imu.loc[mask, axis].to_numpy() + params[f"{group}_amplitude"] * wave * scale
        limit = params[f"{group}_range"]
        if limit is not None:
            values = np.clip(values, -limit * scale, limit * scale)
        imu.loc[mask, axis] = values


@fault_kind("odometer_slip", {"slip": Number("", min=-1.0, doc=(
    "speed error ratio: +0.2 spins the wheel 20 % fast, -1 locks it"))}, ("odometer",),
    "wheel spin or lock: the measured speed is off by a ratio")
def _odometer_slip(streams, intervals, params, context) -> None:
    odo = streams["odometer"]
    mask = in_intervals(odo["t"].to_numpy(), intervals)
    odo.loc[mask, "speed"] = odo.loc[mask, "speed"].to_numpy() * (1.0 + params["slip"])
    if "ticks" in odo:
        odo.loc[mask, "ticks"] = np.round(odo.loc[mask, "ticks"].to_numpy()
                                          * (1.0 + params["slip"]))


@fault_kind("odometer_scale_change", {"scale_change": Number("", gt=-0.5, lt=0.5, doc=(
    "relative change of the scale factor, e.g. \"3 %\" after a tyre change"))},
    ("odometer",), "a tyre change: the odometer scale factor changes")
def _odometer_scale_change(streams, intervals, params, context) -> None:
    _odometer_slip.apply(streams, intervals, {"slip": params["scale_change"]}, context)


@fault_kind("baro_jump", {
    "delta_pa": Number("Pa", doc="pressure step (a window opened, a door closed)"),
    "recovery": Number("s", 5.0, min=0, doc="time over which the step decays at the end"),
}, ("baro",), "a pressure step and its recovery")
def _baro_jump(streams, intervals, params, context) -> None:
    baro = streams["baro"]
    t = baro["t"].to_numpy()
    for start, end in intervals:
        mask = (t >= start) & (t < end)
        recovery = min(params["recovery"], end - start)
        # full step until the recovery, then a smooth (cosine) return to zero at the end
        u = np.clip((t[mask] - (end - recovery)) / recovery, 0.0, 1.0) if recovery > 0 else 0.0
        delta = params["delta_pa"] * 0.5 * (1.0 + np.cos(np.pi * u))
        baro.loc[mask, "pressure"] = baro.loc[mask, "pressure"].to_numpy() + delta


_STREAM = Text(choices=["imu", "odometer", "gnss_fix", "gnss_raw", "baro", "mag"],
               doc="the stream it acts on")


@fault_kind("sensor_dropout", {"stream": _STREAM}, ("imu", "odometer", "gnss_fix", "gnss_raw",
                                                   "baro", "mag"),
          "a stream loses its samples")
def _sensor_dropout(streams, intervals, params, context) -> None:
    name = params["stream"]
    frame = streams[name]
    keep = ~in_intervals(frame["t"].to_numpy(), intervals)
    streams[name] = frame.loc[keep].reset_index(drop=True)


@fault_kind("timestamp_jitter", {
    "stream": _STREAM,
    "sigma": Number("s", gt=0, doc="standard deviation of the time-tag error"),
}, ("imu", "odometer", "gnss_fix", "gnss_raw", "baro", "mag"),
    "time tags off by a random error (kept in order)")
def _timestamp_jitter(streams, intervals, params, context) -> None:
    name = params["stream"]
    frame = streams[name]
    t = frame["t"].to_numpy()
    mask = in_intervals(t, intervals)
    epochs = np.unique(t[mask])
    if len(epochs) == 0:
        return
    # a per-epoch error (all rows of one epoch move together), bounded to under half the
    # sample spacing so the stream stays in time order
    spacing = np.min(np.diff(np.unique(t))) if len(np.unique(t)) > 1 else 1.0
    bound = 0.45 * spacing
    jitter = np.clip(context.rng.normal(0.0, params["sigma"], len(epochs)), -bound, bound)
    frame.loc[mask, "t"] = t[mask] + jitter[np.searchsorted(epochs, t[mask])]


SENSOR_FAULTS = (_imu_bias_step, _imu_saturation_burst, _odometer_slip, _odometer_scale_change,
                 _baro_jump, _sensor_dropout, _timestamp_jitter)
