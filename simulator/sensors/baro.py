"""Barometer: static pressure at the vehicle's altitude through the standard atmosphere, under a
drifting sea-level pressure (weather), with bias, white noise, quantisation and range.

Model::

    p(t) = p_std(h(t)) * p_sl(t) / 101325 Pa + b + n,   p_sl(t) = sea_level_pressure + drift t

* p_std: the ICAO / U.S. 1976 standard atmosphere (``simulator.environment.atmosphere``) at the
  truth altitude h (the ellipsoidal height is used as height above sea level: the geoid
  undulation is a constant offset, like the bias); a non-standard sea-level pressure scales the
  whole column (the altimeter-setting convention);
* ``drift``: sea-level pressure change per hour (Pa/h, given, e.g. "-1 hPa/h" for a passing
  front);
* b ~ N(0, ``bias``^2) drawn once per run; n white with 1-sigma ``noise`` (Pa);
* then clipping to ``range`` [min, max] and rounding to ``resolution``.

The ``altitude`` column is the pressure altitude of the measured pressure (standard atmosphere,
101325 Pa at sea level), so the ideal barometer's altitude is the truth altitude.

Public names
------------
BARO_FIELD, BARO_PRESETS, Barometer.

References
----------
ICAO Doc 7488/3, *Manual of the ICAO Standard Atmosphere*, 1993. Park et al., IEEE Access 7,
2019, Table 2 (Bosch BMP280: 300-1100 hPa, 1.3 Pa RMS noise, 20 Hz). Bosch Sensortec,
*BMP280 data sheet* BST-BMP280-DS001 (absolute accuracy +-1 hPa, resolution 0.16 Pa).
"""

from __future__ import annotations

import numpy as np

from simulator.environment.atmosphere import P0_PA, pressure_altitude_m, pressure_pa
from simulator.schema import Context, Number, Path, Vector
from simulator.sensors.base import sample_times
from simulator.sensors.presets import PresetSensor, preset_sensor_field
from simulator.tables import ColumnTable
from simulator.trajectory.kinematics import Kinematics
from simulator.units import HPA

BARO_PRESETS: dict[str, dict] = {
    "ideal": {},
    "bosch-bmp280": {"rate": 20.0, "noise": 1.3, "bias": 1 * HPA, "resolution": 0.16,
                     "range": [300 * HPA, 1100 * HPA]},
}

_FIELDS = {
    "rate": Number("Hz", None, gt=0, max=1000, doc="sample rate"),
    "noise": Number("Pa", None, min=0, doc="white noise, 1-sigma"),
    "bias": Number("Pa", None, min=0, doc="bias, 1-sigma, drawn once per run"),
    "drift": Number("Pa/s", None, doc="sea-level pressure change (weather), e.g. '-1 hPa/h'"),
    "sea_level_pressure": Number("Pa", None, gt=0, doc="sea-level pressure at t = 0"),
    "resolution": Number("Pa", None, min=0, doc="quantisation step"),
    "range": Vector(2, Number("Pa", gt=0), None, doc="lowest and highest pressure measured"),
}
_DEFAULTS = {"rate": 10.0, "sea_level_pressure": P0_PA, "range": None}


def _check_range(out: dict, path: Path, ctx: Context) -> dict:
    if out["range"] is not None and out["range"][0] >= out["range"][1]:
        return ctx.error(path + ("range",), "the lowest pressure must be below the highest")
    return out


BARO_FIELD = preset_sensor_field("barometer", BARO_PRESETS, _FIELDS, _DEFAULTS,
                                 "is the exact pressure", _check_range)


class Barometer(PresetSensor):
    """A barometer built from its resolved scenario block (``sensors.baro``)."""

    name = "baro"
    # the weather is truth: a user assumes the standard atmosphere, steady
    truth_keys = {"sea_level_pressure": P0_PA, "drift": 0.0}

    def generate(self, truth: Kinematics, rng: np.random.Generator) -> dict[str, ColumnTable]:
        c = self.config
        t = sample_times(truth.duration_s, self.rate_hz)
        altitude = truth.position(t)[:, 2]
        sea_level = c["sea_level_pressure"] + c["drift"] * t
        bias = c["bias"] * rng.standard_normal()
        pressure = (pressure_pa(altitude) * sea_level / P0_PA + bias
                    + c["noise"] * rng.standard_normal(len(t)))
        if c["range"] is not None:
            pressure = np.clip(pressure, *c["range"])
        if c["resolution"] > 0:
            pressure = np.round(pressure / c["resolution"]) * c["resolution"]
        self.drawn.update(bias=float(bias), sea_level_pressure_start=float(sea_level[0]),
                          sea_level_pressure_end=float(sea_level[-1]))
        return {"baro": {"t": t, "pressure": pressure,
                         "altitude": pressure_altitude_m(pressure)}}
