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

CAN wheel speed (``tooth_timing: true``), the way an ABS/ESC unit reports it: the ECU
time-stamps each tooth edge of the tone wheel and reports the mean speed between the first and
the last edge inside the last sample interval (the period-measurement method; the seed papers do
not describe how a CAN speed is formed, so this is the implementer's choice): speed(t_k) = (j -
i) / ``ticks_per_meter`` / (e_j - e_i), e_j the last edge at or before t_k and e_i the first
edge after t_k - 1/rate (at least the edge before e_j). Edge times come from inverting the
measured distance on a grid 4 times the sample rate (linear between grid points). The speed
reads exactly 0 when no edge came within 1 / (``ticks_per_meter`` ``min_speed``) seconds or the
speed is below ``min_speed`` (the low-speed cut-off of real wheel-speed sensors: a passive
sensor's signal vanishes near standstill). Then the speed is rounded to ``speed_resolution``
(the CAN signal's step, 0.01 km/h on the Toyota bus of the comma2k19 log). Without ``min_speed``
a stopped wheel keeps its last edge pair's speed forever, so the cut-off is required with tooth
timing (a choice: the papers are silent; real units use 1.5-3 km/h).

Scale factor: sf(t) = ``scale_factor`` + ``scale_drift`` W(t) + ``speed_scale`` |v(t)| +
``slip_per_accel`` a(t): the dynamic rolling radius of a radial tyre grows with speed
(centrifugal growth of the tread); the seed papers give no value, so the ``automotive`` preset's
0.2 % at 30 m/s is an assumed order of magnitude, written down here and in
docs/odometer-and-barometer.md. a is the acceleration along the path: a driven wheel turns
faster than the car rolls while accelerating and slower while braking, by the longitudinal slip
ratio, linear in the force for small slip (the linear range of the tyre's slip curve);
``slip_per_accel`` (s^2/m) lumps mass, load and slip stiffness and is 0 in every preset (no
sourced value yet); load and temperature are not modelled.

Direction: a real car's bus carries the unsigned wheel speed and, separately, the gear (the
direction). The ``direction`` column is that signal: +1 forward, -1 reversing, 0 standing still.
With ``signed: false`` the ``speed`` (and ``ticks``) are unsigned; with ``signed: true`` (the
default, the earlier behaviour) they carry the sign as below.

Reverse (``signed: true``): the sensor is a wheel-speed sensor whose direction comes from the
transmission (the gear selected), so ``speed`` is signed, negative while reversing, and the tick
counter is an up/down counter: ``ticks`` of an interval are negative while reversing, and summing
them gives the net displacement along the path, not the distance travelled.
At standstill no distance accrues, so the speed is exactly zero (+0.0, never -0.0).

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

from simulator.schema import Boolean, Context, Number, Path
from simulator.sensors.base import sample_times
from simulator.sensors.presets import PresetSensor, preset_sensor_field
from simulator.stochastic import random_walk
from simulator.tables import ColumnTable
from simulator.trajectory.kinematics import Kinematics
from simulator.units import KM_H, MILLI, PERCENT, PERCENT_RT_H

ODOMETER_PRESETS: dict[str, dict] = {
    "ideal": {},
    # an ABS wheel-speed sensor: 48-tooth tone wheel on a 0.65 m tyre (common passenger-car
    # values), 10 Hz as in the DR of Cho & Choi 2006, tyre radius known to 1 %
    "abs-wheel-speed": {"rate": 10.0, "scale_factor": 1.01, "scale_drift": 0.1 * PERCENT_RT_H,
                        "ticks_per_meter": 48 / (np.pi * 0.65), "latency": 20 * MILLI},
    # the vehicle speed on a CAN bus: the 48-tooth wheel timed by the ABS unit, 50 Hz, CAN step
    # 0.01 km/h and 89 Hz in the comma2k19 RAV4 log (refdata 3a); scale factor 0.991 measured in
    # that log against its ground truth (CAN speed / truth speed, least squares); cut-off 2 km/h;
    # tyre growth 0.2 % at 30 m/s (assumed, see the module docstring); unsigned plus direction
    "automotive": {"rate": 50.0, "scale_factor": 0.991, "scale_drift": 0.1 * PERCENT_RT_H,
                   "ticks_per_meter": 48 / (np.pi * 0.65), "latency": 20 * MILLI,
                   "tooth_timing": True, "min_speed": 2 * KM_H,
                   "speed_resolution": 0.01 * KM_H,
                   "speed_scale": 0.2 * PERCENT / 30.0, "signed": False},
}

_FIELDS = {
    "rate": Number("Hz", None, gt=0, max=1000, doc="sample rate"),
    "scale_factor": Number("", None, gt=0, doc="measured / true distance at t = 0"),
    "scale_drift": Number("1/sqrt(s)", None, min=0,
                          doc="random-walk density of the scale factor"),
    "ticks_per_meter": Number("1/m", None, min=0, doc="encoder ticks per metre; 0: no ticks"),
    "latency": Number("s", None, min=0, doc="delay of the reported speed"),
    "tooth_timing": Boolean(None, doc="speed from timing the tooth edges (CAN wheel speed) "
                                      "instead of counting ticks per interval"),
    "min_speed": Number("m/s", None, min=0, doc="low-speed cut-off: slower reads 0; required "
                                                "with tooth_timing"),
    "speed_resolution": Number("m/s", None, min=0, doc="quantisation step of the reported "
                                                       "speed, e.g. '0.01 km/h'; 0: none"),
    "speed_scale": Number("s/m", None, doc="scale-factor change per m/s of speed (tyre growth)"),
    "slip_per_accel": Number("s^2/m", None, doc="scale-factor change per m/s^2 of "
                                                "acceleration along the path (tyre slip)"),
    "signed": Boolean(None, doc="speed and ticks signed (negative reversing); false: unsigned "
                                "with the direction column"),
}
_DEFAULTS = {"rate": 10.0, "scale_factor": 1.0, "tooth_timing": False, "signed": True}


def _check_timing(out: dict, path: Path, ctx: Context) -> dict:
    if out["tooth_timing"] and not (out["ticks_per_meter"] > 0 and out["min_speed"] > 0):
        return ctx.error(path + ("tooth_timing",),
                         "tooth_timing needs ticks_per_meter > 0 and min_speed > 0")
    return out


ODOMETER_FIELD = preset_sensor_field("odometer", ODOMETER_PRESETS, _FIELDS, _DEFAULTS,
                                     "is the true speed", _check_timing)


class Odometer(PresetSensor):
    """An odometer built from its resolved scenario block (``sensors.odometer``)."""

    name = "odometer"
    truth_keys = {"scale_factor": 1.0}  # the true scale factor; a user assumes 1

    def timing(self) -> dict[str, dict]:
        """With tooth timing the speed is the mean between the edges of the last interval (about
        0.5/rate behind the stamp at driving speeds). With ticks the speed is the count over the
        interval (t - 1/rate, t] divided by its length: a mean, 0.5/rate behind its stamp, plus
        the latency."""
        c = self.config
        if c["tooth_timing"]:
            return {"odometer": {"stamp": "the last tooth edge before it; speed is the mean "
                                          "between the interval's first and last tooth edges",
                                 "delay_s": c["latency"] + 0.5 / self.rate_hz}}
        if c["ticks_per_meter"] > 0:
            return {"odometer": {"stamp": "the end of the tick-counting interval; speed is the "
                                          "mean over the interval",
                                 "delay_s": c["latency"] + 0.5 / self.rate_hz}}
        return {"odometer": {"stamp": "the sampling instant", "delay_s": c["latency"]}}

    def generate(self, truth: Kinematics, rng: np.random.Generator) -> dict[str, ColumnTable]:
        c = self.config
        dt = 1.0 / self.rate_hz
        t = sample_times(truth.duration_s, self.rate_hz)
        scale = c["scale_factor"] + random_walk(len(t), dt, c["scale_drift"], rng)[:, 0]
        self.drawn.update(scale_factor=float(scale[0]), scale_factor_end=float(scale[-1]))
        self.true_errors["odometer_scale_factor"] = (t, scale)
        t_true = np.clip(t - c["latency"], 0.0, truth.duration_s)
        direction = truth.profile.direction_at(t_true) * (
            truth.profile.distance_of_time(t_true, 1) > 0)
        table = {"t": t}
        if c["tooth_timing"]:
            speed = self._tooth_timed_speed(truth, t, t_true, scale, rng)
        elif c["ticks_per_meter"] > 0:
            speed, table["ticks"] = self._counted_speed(truth, t_true, scale, rng)
        else:
            _, speed, sf = self._wheel_scale(truth, t_true, scale)
            speed = sf * np.maximum(speed, 0.0)
            if c["min_speed"] > 0:
                speed = np.where(speed < c["min_speed"], 0.0, speed)
            speed = speed * (truth.profile.direction_at(t_true) if c["signed"] else 1.0)
        if c["speed_resolution"] > 0:
            speed = np.round(speed / c["speed_resolution"]) * c["speed_resolution"]
        table["speed"] = speed + 0.0
        table["direction"] = direction.astype(np.int8)
        return {"odometer": table}

    def _wheel_scale(self, truth: Kinematics, t_true: np.ndarray, scale: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The true distance s and speed v at ``t_true`` and the wheel's whole scale factor:
        ``scale`` + ``speed_scale`` |v| + ``slip_per_accel`` a (module docstring)."""
        c = self.config
        s, v, a = truth.profile.distance_of_time.evaluate(t_true, (0, 1, 2))
        return s, v, scale + c["speed_scale"] * np.abs(v) + c["slip_per_accel"] * a

    def _counted_speed(self, truth: Kinematics, t_true: np.ndarray, scale: np.ndarray,
                       rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """Ticks counted per interval and their mean speed (the up/down counter when signed)."""
        c = self.config
        distance, _, sf = self._wheel_scale(truth, t_true, scale)
        if c["signed"]:
            distance = truth.profile.net_distance(t_true)
        measured = np.cumsum(sf * np.diff(distance, prepend=distance[0]))
        phase = float(rng.uniform())
        counts = np.floor(measured * c["ticks_per_meter"] + phase).astype(np.int64)
        ticks = np.diff(counts, prepend=counts[0])
        self.drawn["tick_phase"] = phase
        return ticks * self.rate_hz / c["ticks_per_meter"], ticks

    def _tooth_timed_speed(self, truth: Kinematics, t: np.ndarray, t_true: np.ndarray,
                           scale: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """Mean speed between the tooth edges of the last interval (module docstring)."""
        c = self.config
        tpm, dt = c["ticks_per_meter"], 1.0 / self.rate_hz
        grid = np.linspace(0.0, t[-1], 4 * (len(t) - 1) + 1) if len(t) > 1 else t
        grid_true = np.clip(grid - c["latency"], 0.0, truth.duration_s)
        distance, _, sf = self._wheel_scale(truth, grid_true, np.interp(grid, t, scale))
        measured = np.cumsum(sf * np.diff(distance, prepend=distance[0]))
        phase = float(rng.uniform())
        self.drawn["tick_phase"] = phase
        levels = (np.arange(np.ceil(phase), np.floor(measured[-1] * tpm + phase) + 1)
                  - phase) / tpm
        k = np.clip(np.searchsorted(measured, levels, side="left"), 1, len(grid) - 1)
        edges = grid[k - 1] + (levels - measured[k - 1]) / (measured[k] - measured[k - 1]) * (
            grid[k] - grid[k - 1])
        last = np.searchsorted(edges, t, side="right") - 1
        first = np.minimum(np.searchsorted(edges, t - dt, side="right"), last - 1)
        ok = first >= 0
        first, last_ = np.maximum(first, 0), np.maximum(last, 0)
        span = np.where(ok, edges[last_] - edges[first], 1.0)
        speed = np.where(ok, (last_ - first) / tpm / np.where(span > 0, span, 1.0), 0.0)
        fresh = ok & (t - edges[last_] <= 1.0 / (tpm * c["min_speed"]))
        return np.where(fresh & (speed >= c["min_speed"]), speed, 0.0) * (
            truth.profile.direction_at(t_true) if c["signed"] else 1.0)
