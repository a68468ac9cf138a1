"""Magnetometer: the Earth's main field from the World Magnetic Model (through ``pygeomag``) in
the body frame, with hard- and soft-iron distortion, white noise, and field disturbances inside
covered zones.

Model (the usual compass-calibration model, e.g. Gebre-Egziabher et al. 2006, eq. 4)::

    m = (I + S) C_n^b B^n(lat, lon, h, date) + b_hi + d(t) + n

* B^n: WMM main field (north, east, down) at the truth position and the drive's start date,
  evaluated every ``_FIELD_STEP_S`` seconds and interpolated (the field changes by a few nT per
  kilometre); the model is the WMM release whose five-year life span holds the date (WMM2010,
  WMM2015v2, WMM2020, WMM2025); before 2010 or from 2030 the nearest release is extrapolated
  with its secular variation, and the manifest names the release used (``field_model``);
* S: soft iron, a 3 x 3 matrix with elements N(0, ``soft_iron``^2); b_hi: hard iron, N(0,
  ``hard_iron``^2) per axis; both drawn once per run, body frame;
* d(t): inside zones whose sky is ``none`` (tunnels, garages: steel and cables), a first-order
  Gauss-Markov field of 1-sigma ``disturbance`` per axis and correlation time
  ``disturbance_time``; zero elsewhere;
* n: white noise, 1-sigma ``noise`` per axis (T).

Public names
------------
MAG_FIELD, MAG_PRESETS, WMM_RELEASES, Magnetometer, wmm_release, earth_field_ned.

References
----------
Chulliat et al., *The US/UK World Magnetic Model for 2020-2025*, NOAA NCEI, 2020, and
*for 2025-2030*, 2025 (the models and their test values); coefficients as shipped with
``pygeomag`` (a Python port of the WMM reference C code).
Gebre-Egziabher, Elkaim, Powell & Parkinson, "Calibration of strapdown magnetometers in
magnetic field domain", J. Aerosp. Eng. 19(2), 2006.
"""

from __future__ import annotations

import datetime as dt

import numpy as np

from simulator.earth import euler_to_dcm
from simulator.schema import Number
from simulator.sensors.base import sample_times, truth_at
from simulator.sensors.presets import PresetSensor, preset_sensor_field
from simulator.stochastic import gauss_markov
from simulator.tables import ColumnTable
from simulator.trajectory.kinematics import Kinematics
from simulator.units import MICRO_T

NT_TO_T = 1e-9
_FIELD_STEP_S = 30.0  # spacing of the WMM evaluations along the drive, s

MAG_PRESETS: dict[str, dict] = {
    "ideal": {},
    # a MEMS magnetometer in a car: representative values, not a data sheet
    "automotive": {"rate": 10.0, "noise": 0.3 * MICRO_T, "hard_iron": 5 * MICRO_T,
                   "soft_iron": 0.02, "disturbance": 10 * MICRO_T, "disturbance_time": 2.0},
}

_FIELDS = {
    "rate": Number("Hz", None, gt=0, max=1000, doc="sample rate"),
    "noise": Number("T", None, min=0, doc="white noise per axis, 1-sigma"),
    "hard_iron": Number("T", None, min=0, doc="hard-iron offset per axis, 1-sigma"),
    "soft_iron": Number("1", None, min=0, doc="soft-iron matrix elements, 1-sigma"),
    "disturbance": Number("T", None, min=0, doc="field disturbance in covered zones, 1-sigma"),
    "disturbance_time": Number("s", None, gt=0, doc="correlation time of the disturbance"),
}
_DEFAULTS = {"rate": 10.0, "disturbance_time": 2.0}


MAG_FIELD = preset_sensor_field("magnetometer", MAG_PRESETS, _FIELDS, _DEFAULTS,
                                "is the exact WMM field")


# WMM releases shipped with pygeomag: (first decimal year of the life span, coefficient file)
WMM_RELEASES = ((2010.0, "WMM_2010"), (2015.0, "WMM_2015v2"), (2020.0, "WMM_2020"),
                (2025.0, "WMM_2025"))
_WMM_LIFE_SPAN_YEARS = 5.0


def wmm_release(decimal_year: float) -> str:
    """The WMM release for a date: the one whose life span holds it, else the nearest."""
    chosen = WMM_RELEASES[0][1]
    for first_year, name in WMM_RELEASES:
        if decimal_year >= first_year:
            chosen = name
    return chosen


def decimal_year(date: dt.datetime) -> float:
    """Date as a decimal year (the time argument of the WMM), to the second."""
    start = dt.datetime(date.year, 1, 1, tzinfo=date.tzinfo)
    length = dt.datetime(date.year + 1, 1, 1, tzinfo=date.tzinfo) - start
    return date.year + (date - start) / length


def earth_field_ned(lat_deg: np.ndarray, lon_deg: np.ndarray, alt_m: np.ndarray,
                    date: dt.datetime) -> tuple[np.ndarray, str]:
    """WMM main field (north, east, down), tesla, shape (n, 3), at geodetic positions (height
    above the WGS-84 ellipsoid), and the name of the WMM release used. One model evaluation per
    position: call it on a coarse set of points and interpolate."""
    from pygeomag import GeoMag  # pure Python, a few milliseconds; only this sensor needs it

    year = decimal_year(date)
    release = wmm_release(year)
    model = GeoMag(coefficients_file=f"wmm/{release}.COF")
    outside = not (WMM_RELEASES[0][0] <= year < WMM_RELEASES[-1][0] + _WMM_LIFE_SPAN_YEARS)
    field = np.empty((np.size(lat_deg), 3))
    for i, (lat, lon, alt) in enumerate(zip(np.ravel(lat_deg), np.ravel(lon_deg),
                                            np.ravel(alt_m), strict=True)):
        result = model.calculate(glat=float(lat), glon=float(lon), alt=float(alt) / 1000.0,
                                 time=year, allow_date_outside_lifespan=outside)
        field[i] = result.x, result.y, result.z
    return field * NT_TO_T, release


class Magnetometer(PresetSensor):
    """A magnetometer built from its resolved scenario block (``sensors.mag``)."""

    name = "mag"

    def generate(self, truth: Kinematics, rng: np.random.Generator) -> dict[str, ColumnTable]:
        c = self.config
        t = sample_times(truth.duration_s, self.rate_hz)
        k = truth_at(truth, t, ("roll", "pitch", "yaw"))
        coarse = np.unique(np.append(np.arange(0.0, t[-1], _FIELD_STEP_S), t[-1]))
        pos = truth.position(coarse)
        field, release = earth_field_ned(np.degrees(pos[:, 0]), np.degrees(pos[:, 1]),
                                         pos[:, 2], truth.utc_start)
        b_ned = np.stack([np.interp(t, coarse, field[:, j]) for j in range(3)], axis=-1)
        c_bn = euler_to_dcm(k["roll"], k["pitch"], k["yaw"])
        b_body = np.einsum("nji,nj->ni", c_bn, b_ned)
        soft = c["soft_iron"] * rng.standard_normal((3, 3))
        hard = c["hard_iron"] * rng.standard_normal(3)
        m = b_body @ (np.eye(3) + soft).T + hard
        covered = [name for name, zone in truth.environment.get("zones", {}).items()
                   if zone.get("sky") == "none"]
        disturbed = np.isin(truth.zone_at(t), covered) if covered else np.zeros(len(t), bool)
        if c["disturbance"] > 0 and disturbed.any():
            d = gauss_markov(len(t), 1.0 / self.rate_hz, np.full(3, c["disturbance"]),
                             c["disturbance_time"], rng)
            m = m + d * disturbed[:, None]
        m = m + c["noise"] * rng.standard_normal((len(t), 3))
        self.drawn.update(field_model=release, hard_iron=hard.tolist(), soft_iron=soft.tolist())
        return {"mag": {"t": t, "mag_x": m[:, 0], "mag_y": m[:, 1], "mag_z": m[:, 2]}}
