"""The IMU error budget a user reads from the dataset's datasheet (the manifest's ``datasheet``,
``Estimator.datasheet``; docs/dataset-format.md), in the numbers a filter's P0 and Q are made
of: one figure per sensor triad (the largest of its three axes, so that no axis is claimed
better than its datasheet line).

* ``noise_density``: white noise, rad/s/sqrt(Hz) or m/s^2/sqrt(Hz) (angle / velocity random
  walk);
* ``bias``: the turn-on bias, 1-sigma (a filter's bias prior);
* ``bias_instability``: the Allan-deviation floor's B (IEEE Std 952);
* ``random_walk``: the rate random walk, rad/s/sqrt(s) or m/s^2/sqrt(s);
* ``scale_factor``, ``misalignment``: 1-sigma, dimensionless and rad.

``bias_walk`` turns the last three into the one random-walk density a filter with
random-constant-plus-walk biases can carry: the datasheet's rate random walk plus the bias
instability reached over ``BIAS_INSTABILITY_TIME_S`` (a flicker floor seen by a random walk:
B^2 / T; Groves 2013, section 4.4.3 describes the bias instability as the flicker part of the
bias drift).

A filter's white noise is the datasheet's noise density, at least ``GYRO_NOISE_FLOOR`` and
``ACCEL_NOISE_FLOOR``, the ``tactical`` preset's densities (0.1
deg/sqrt(h), 51 ug/sqrt(Hz)). A filter's strapdown is itself a sensor of finite accuracy: its
discrete-time mechanisation of 100 Hz samples (the trapezoidal integration of interval-mean
rates, the coning and sculling left over on a car body that vibrates and pitches on its
springs) makes attitude errors of about 0.1 mrad with an error-free IMU (an ``ideal`` IMU on
``urban_canyon``: roll 0.12 mrad RMS with GNSS aiding), which a datasheet of zeros gives the
filter no noise for: its tilt sigma then fell to 5 urad, 20 times below the error. The floor
sits under every MEMS IMU's densities, so it acts on ideal and navigation-grade sheets only.

Public names
------------
TriadErrors, ImuDatasheet, BIAS_INSTABILITY_TIME_S, GYRO_NOISE_FLOOR, ACCEL_NOISE_FLOOR.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

BIAS_INSTABILITY_TIME_S = 100.0  # s: the time over which a random walk reaches B
GYRO_NOISE_FLOOR = 0.1 * np.pi / 180.0 / 60.0  # rad/s/sqrt(Hz): 0.1 deg/sqrt(h) (tactical)
ACCEL_NOISE_FLOOR = 0.03 / 60.0  # m/s^2/sqrt(Hz): 0.03 m/s/sqrt(h), 51 ug/sqrt(Hz) (tactical)


def _largest(block: Mapping[str, Any], key: str) -> float:
    value = block.get(key)
    if value is None:
        return 0.0
    return float(np.max(np.abs(np.asarray(value, dtype=float))))


@dataclass(frozen=True)
class TriadErrors:
    """One sensor triad's datasheet figures (module docstring)."""

    noise_density: float
    bias: float
    bias_instability: float
    random_walk: float
    scale_factor: float
    misalignment: float

    @classmethod
    def from_block(cls, block: Mapping[str, Any]) -> TriadErrors:
        """From a datasheet's ``imu.gyro`` or ``imu.accel`` mapping (missing keys read 0)."""
        return cls(*(_largest(block, k) for k in ("noise_density", "bias", "bias_instability",
                                                  "random_walk", "scale_factor",
                                                  "misalignment")))

    @property
    def bias_walk(self) -> float:
        """Random-walk density of the bias (unit/sqrt(s)): sqrt(K^2 + B^2 / T), T =
        ``BIAS_INSTABILITY_TIME_S`` (module docstring)."""
        return float(np.hypot(self.random_walk,
                              self.bias_instability / np.sqrt(BIAS_INSTABILITY_TIME_S)))


@dataclass(frozen=True)
class ImuDatasheet:
    """The gyro and accelerometer triads of a datasheet, or None for a dataset without one."""

    gyro: TriadErrors
    accel: TriadErrors

    @classmethod
    def from_datasheet(cls, datasheet: Mapping[str, Any]) -> ImuDatasheet | None:
        """Read the manifest's ``datasheet["imu"]``; None when it has no gyro and accel block
        (a recording imported without a datasheet)."""
        imu = datasheet.get("imu") or {}
        if not imu.get("gyro") or not imu.get("accel"):
            return None
        return cls(TriadErrors.from_block(imu["gyro"]), TriadErrors.from_block(imu["accel"]))
