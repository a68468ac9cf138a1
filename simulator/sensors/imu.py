"""Inertial measurement unit: samples the exact body rate and specific force as rates or as
increments integrated over each sample interval.

The ``ideal`` preset turns every error term off: its rate output is the truth sampled at the IMU
rate and its increment output is the exact integral over each interval (Gauss-Legendre on the
analytic kinematics), which is what the strapdown closure test integrates.

Public names
------------
IMU_FIELD, Imu.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from simulator import columns as col
from simulator.scenario.schema import (
    Context,
    ListOf,
    Number,
    Path,
    Record,
    Text,
    Vector,
)
from simulator.sensors.base import integrate_over_samples, sample_times
from simulator.trajectory.kinematics import Kinematics

PRESETS: dict[str, dict] = {"ideal": {}}


def _resolve(value: dict, path: Path, ctx: Context) -> dict:
    if value["preset"] not in PRESETS:
        ctx.error(path + ("preset",), f"unknown IMU preset {value['preset']!r}; known: "
                                      f"{', '.join(sorted(PRESETS))}")
    return value


IMU_FIELD = Record(
    {
        "preset": Text("ideal", doc="named parameter set; 'ideal' turns every error off"),
        "rate": Number("Hz", 100.0, gt=0, max=10000),
        "output": Text("rate", choices=["rate", "increment"]),
        "axes": ListOf(Text(choices=list(col.IMU_AXES)), list(col.IMU_AXES), min_len=1),
        "lever_arm": Vector(3, Number("m"), [0.0, 0.0, 0.0]),
        "mounting": Vector(3, Number(angle=True), [0.0, 0.0, 0.0]),
    },
    default=None,
    post=_resolve,
)


class Imu:
    """An IMU built from its resolved scenario block (``sensors.imu``)."""

    name = "imu"

    def __init__(self, config: dict):
        self.config = config
        self.rate_hz = float(config["rate"])
        self.drawn: dict = {"preset": config["preset"]}

    def generate(self, truth: Kinematics, rng: np.random.Generator) -> dict[str, pd.DataFrame]:
        dt = 1.0 / self.rate_hz
        if self.config["output"] == "increment":
            t = sample_times(truth.duration_s, self.rate_hz, first=1)
            k = integrate_over_samples(truth, t, dt)
        else:
            t = sample_times(truth.duration_s, self.rate_hz)
            k = truth.inertial(t)
        values = np.concatenate([k["w_body"], k["f_body"]], axis=1)
        table = {"t": t}
        for i, axis in enumerate(col.IMU_AXES):
            if axis in self.config["axes"]:
                table[axis] = values[:, i]
        return {"imu": pd.DataFrame(table)}
