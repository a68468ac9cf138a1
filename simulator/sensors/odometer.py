"""Odometer / wheel-speed sensor: the travelled distance scaled by a slowly drifting scale factor,
counted in encoder ticks, reported late by a fixed latency.

Model (the multiplicative odometer error of Park et al. 2019, eq. 22: u_odo = s (1 + ds) v):

* measured distance D(t_k) = sum_j sf(t_j) (x(t_j) - x(t_j-1)), with x the true signed distance
  along the body x axis (``RoadProfile.net_distance``: it decreases while reversing) at
  t - ``latency`` and sf(t) = ``scale_factor`` + ``scale_drift`` W(t) a random walk (W a unit
  Wiener process, so the 1-sigma change after T seconds is scale_drift sqrt(T));
* with ``ticks_per_meter`` > 0: ticks(t_k) = floor(D(t_k) ticks_per_meter + u), u ~ U[0, 1) the
  unknown phase of the encoder at t = 0; the ``ticks`` column counts the ticks of each interval
  and ``speed`` = ticks / (ticks_per_meter dt), the mean speed over the interval;
* without ticks: ``speed`` = sf(t) d v(t - latency), the instantaneous signed speed.

Reverse: the sensor is a wheel-speed sensor whose direction comes from the transmission (the
gear selected), so ``speed`` is signed, negative while reversing, and the tick counter is an
up/down counter: ``ticks`` of an interval are negative while reversing, and summing them gives
the net displacement along the path, not the distance travelled. At standstill no distance
accrues, so the speed is exactly zero (+0.0, never -0.0).

Public names
------------
ODOMETER_FIELD, ODOMETER_PRESETS, Odometer.

References
----------
Park et al., "MEMS 3D DR/GPS Integrated System for Land Vehicle Application Robust to GPS
Outages", IEEE Access 7, 2019, eq. 22 (odometer scale factor).
"""

from __future__ import annotations

import numpy as np

from simulator.schema import Number
from simulator.sensors.base import sample_times
from simulator.sensors.presets import PresetSensor, preset_sensor_field
from simulator.stochastic import random_walk
from simulator.tables import ColumnTable
from simulator.trajectory.kinematics import Kinematics
from simulator.units import MILLI, PERCENT_RT_H

ODOMETER_PRESETS: dict[str, dict] = {
    "ideal": {},
    # an ABS wheel-speed sensor: 48-tooth tone wheel on a 0.65 m tyre (common passenger-car
    # values), 10 Hz as in the DR of Cho & Choi 2006, tyre radius known to 1 %
    "abs-wheel-speed": {"rate": 10.0, "scale_factor": 1.01, "scale_drift": 0.1 * PERCENT_RT_H,
                        "ticks_per_meter": 48 / (np.pi * 0.65), "latency": 20 * MILLI},
}

_FIELDS = {
    "rate": Number("Hz", None, gt=0, max=1000, doc="sample rate"),
    "scale_factor": Number("", None, gt=0, doc="measured / true distance at t = 0"),
    "scale_drift": Number("1/sqrt(s)", None, min=0,
                          doc="random-walk density of the scale factor"),
    "ticks_per_meter": Number("1/m", None, min=0, doc="encoder ticks per metre; 0: no ticks"),
    "latency": Number("s", None, min=0, doc="delay of the reported speed"),
}
_DEFAULTS = {"rate": 10.0, "scale_factor": 1.0}


ODOMETER_FIELD = preset_sensor_field("odometer", ODOMETER_PRESETS, _FIELDS, _DEFAULTS,
                                     "is the true speed")


class Odometer(PresetSensor):
    """An odometer built from its resolved scenario block (``sensors.odometer``)."""

    name = "odometer"
    truth_keys = {"scale_factor": 1.0}  # the true scale factor; a user assumes 1

    def timing(self) -> dict[str, dict]:
        """With ticks the speed is the count over the interval (t - 1/rate, t] divided by its
        length: a mean, 0.5/rate behind its stamp, plus the latency."""
        c = self.config
        if c["ticks_per_meter"] > 0:
            return {"odometer": {"stamp": "the end of the tick-counting interval; speed is the "
                                          "mean over the interval",
                                 "delay_s": c["latency"] + 0.5 / self.rate_hz}}
        return {"odometer": {"stamp": "the sampling instant", "delay_s": c["latency"]}}

    def generate(self, truth: Kinematics, rng: np.random.Generator) -> dict[str, ColumnTable]:
        c = self.config
        dt = 1.0 / self.rate_hz
        t = sample_times(truth.duration_s, self.rate_hz)
        t_true = np.clip(t - c["latency"], 0.0, truth.duration_s)
        distance = truth.profile.net_distance(t_true)
        scale = c["scale_factor"] + random_walk(len(t), dt, c["scale_drift"], rng)[:, 0]
        measured = np.cumsum(scale * np.diff(distance, prepend=distance[0]))
        self.drawn.update(scale_factor=float(scale[0]), scale_factor_end=float(scale[-1]))
        self.true_errors["odometer_scale_factor"] = (t, scale)
        table = {"t": t}
        if c["ticks_per_meter"] > 0:
            phase = float(rng.uniform())
            counts = np.floor(measured * c["ticks_per_meter"] + phase).astype(np.int64)
            ticks = np.diff(counts, prepend=counts[0])
            table["speed"] = ticks / (c["ticks_per_meter"] * dt)
            table["ticks"] = ticks
            self.drawn["tick_phase"] = phase
        else:
            speed = np.maximum(truth.profile.distance_of_time(t_true, 1), 0.0)
            table["speed"] = scale * truth.profile.direction_at(t_true) * speed + 0.0
        return {"odometer": table}
