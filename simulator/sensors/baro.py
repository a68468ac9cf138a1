"""Barometer: static pressure at the vehicle's altitude through the standard atmosphere, under a
drifting sea-level pressure (weather), with bias, white noise, quantisation and range.

Model::

    p(t) = p_std(h(t)) * p_sl(t) / 101325 Pa + b + k_T dT(t) + n,
    p_sl(t) = sea_level_pressure + (drift + r) t

* p_std: the ICAO / U.S. 1976 standard atmosphere (``simulator.environment.atmosphere``) at the
  truth's height above mean sea level H, the orthometric height H = h - N, N the EGM96 geoid
  undulation at the truth's position (``simulator.geoid``; the atmosphere is layered on
  equipotential surfaces, so pressure follows the geoid: at ARL1, N = -26.9 m, about 3 hPa).
  This is the air's, not the sensor's: ``preset: ideal`` (no sensor error) reads the pressure
  of the true orthometric height too. ``geoid: false`` takes the ellipsoidal height h instead
  (an atmosphere layered on the ellipsoid, for comparisons). A non-standard sea-level pressure
  scales the whole column (the altimeter-setting convention);
* ``drift``: sea-level pressure change per hour (Pa/h, given, e.g. "-1 hPa/h" for a passing
  front);
* r ~ N(0, ``weather_drift``^2), the weather's rate drawn once per run (``drawn["drift_rate"]``
  holds drift + r). The ``bosch-bmp280`` preset draws it with 0.4 hPa/h, the rms change over
  one hour of the real ARL1 met file of 2015-07-19 (refdata 1a, Vaisala PTU300 every 15 min:
  0.41 hPa rms, at most 1.0 hPa in an hour, 3.8 hPa range over the day). A constant rate over
  a run is the choice: drives last minutes to an hour, shorter than weather systems change;
* k_T ~ N(0, ``temperature_coefficient``^2) drawn once per run, dT(t) the ``temperature``
  block's profile (``simulator.sensors.base.temperature_change_k``, the IMU's convention). The
  preset's 1.5 Pa/K is the BMP280's "temperature coefficient of offset" (data sheet Table 2,
  +-1.5 Pa/K, 25-40 degC at 900 hPa), taken as the 1-sigma; with the default temperature
  block (no change) it adds nothing until a profile is given;
* b ~ N(0, ``bias``^2) drawn once per run; n white with 1-sigma ``noise`` (Pa);
* then clipping to ``range`` [min, max] and rounding to ``resolution``.

The ``altitude`` column is the pressure altitude of the measured pressure (standard atmosphere,
101325 Pa at sea level): an error-free barometer reads the orthometric height, which differs
from the truth's ellipsoidal altitude by N (estimators calibrate the barometer's offset against
GNSS heights, which absorbs it).

Public names
------------
BARO_FIELD, BARO_PRESETS, Barometer.

References
----------
ICAO Doc 7488/3, *Manual of the ICAO Standard Atmosphere*, 1993. EGM96: Lemoine et al.,
NASA/TP-1998-206861. Park et al., IEEE Access 7, 2019, Table 2 (Bosch BMP280: 300-1100 hPa,
1.3 Pa RMS noise, 20 Hz). Bosch Sensortec, *BMP280 data sheet* BST-BMP280-DS001 (absolute
accuracy +-1 hPa, resolution 0.16 Pa).
"""

from __future__ import annotations

import numpy as np

from simulator.environment.atmosphere import P0_PA, pressure_altitude_m, pressure_pa
from simulator.geoid import orthometric_height_m
from simulator.schema import Boolean, Context, Number, Path, Vector
from simulator.sensors.base import TEMPERATURE_FIELD, sample_times, temperature_change_k
from simulator.sensors.presets import PresetSensor, preset_sensor_field
from simulator.tables import ColumnTable
from simulator.trajectory.kinematics import Kinematics
from simulator.units import HPA

BARO_PRESETS: dict[str, dict] = {
    "ideal": {},
    "bosch-bmp280": {"rate": 20.0, "noise": 1.3, "bias": 1 * HPA, "resolution": 0.16,
                     "range": [300 * HPA, 1100 * HPA], "weather_drift": "0.4 hPa/h",
                     "temperature_coefficient": "1.5 Pa/K", "geoid": True},
}

_FIELDS = {
    "rate": Number("Hz", None, gt=0, max=1000, doc="sample rate"),
    "noise": Number("Pa", None, min=0, doc="white noise, 1-sigma"),
    "bias": Number("Pa", None, min=0, doc="bias, 1-sigma, drawn once per run"),
    "drift": Number("Pa/s", None, doc="sea-level pressure change (weather), e.g. '-1 hPa/h'"),
    "weather_drift": Number("Pa/s", None, min=0, doc="1-sigma of the sea-level pressure rate "
                                                      "drawn once per run, e.g. '0.4 hPa/h'"),
    "temperature_coefficient": Number("Pa/K", None, min=0,
                                      doc="1-sigma pressure offset per kelvin, drawn once per run"),
    "temperature": TEMPERATURE_FIELD,
    "geoid": Boolean(None, doc="pressure of the height above the EGM96 geoid (mean sea level, "
                               "the default); false: of the ellipsoidal height"),
    "sea_level_pressure": Number("Pa", None, gt=0, doc="sea-level pressure at t = 0"),
    "resolution": Number("Pa", None, min=0, doc="quantisation step"),
    "range": Vector(2, Number("Pa", gt=0), None, doc="lowest and highest pressure measured"),
}
_DEFAULTS = {"rate": 10.0, "sea_level_pressure": P0_PA, "range": None, "geoid": True}


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
        lat, lon, altitude = truth.position(t).T
        if c["geoid"]:
            altitude = orthometric_height_m(np.degrees(lat), np.degrees(lon), altitude)
        bias = c["bias"] * rng.standard_normal()
        noise = c["noise"] * rng.standard_normal(len(t))
        rate = c["drift"] + c["weather_drift"] * rng.standard_normal()
        k_temp = c["temperature_coefficient"] * rng.standard_normal()
        sea_level = c["sea_level_pressure"] + rate * t
        pressure = (pressure_pa(altitude) * sea_level / P0_PA + bias + noise
                    + k_temp * temperature_change_k(c["temperature"], t))
        if c["range"] is not None:
            pressure = np.clip(pressure, *c["range"])
        if c["resolution"] > 0:
            pressure = np.round(pressure / c["resolution"]) * c["resolution"]
        self.drawn.update(bias=float(bias), drift_rate=float(rate),
                          temperature_coefficient=float(k_temp),
                          sea_level_pressure_start=float(sea_level[0]),
                          sea_level_pressure_end=float(sea_level[-1]))
        return {"baro": {"t": t, "pressure": pressure,
                         "altitude": pressure_altitude_m(pressure)}}
