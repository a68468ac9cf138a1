"""Magnetometer: the Earth's main field from the IGRF (through ``ppigrf``) in the body frame, with
hard- and soft-iron distortion, white noise, and field disturbances inside covered zones.

Model (the usual compass-calibration model, e.g. Gebre-Egziabher et al. 2006, eq. 4)::

    m = (I + S) C_n^b B^n(lat, lon, h, date) + b_hi + d(t) + n

* B^n: IGRF main field (north, east, down) at the truth position and the drive's start date,
  evaluated every ``_FIELD_STEP_S`` seconds and interpolated (the field changes by a few nT per
  kilometre);
* S: soft iron, a 3 x 3 matrix with elements N(0, ``soft_iron``^2); b_hi: hard iron, N(0,
  ``hard_iron``^2) per axis; both drawn once per run, body frame;
* d(t): inside zones whose sky is ``none`` (tunnels, garages: steel and cables), a first-order
  Gauss-Markov field of 1-sigma ``disturbance`` per axis and correlation time
  ``disturbance_time``; zero elsewhere;
* n: white noise, 1-sigma ``noise`` per axis (T).

Public names
------------
MAG_FIELD, MAG_PRESETS, Magnetometer, earth_field_ned.

References
----------
Alken et al., "International Geomagnetic Reference Field: the thirteenth generation", Earth
Planets Space 73, 49 (2021); IGRF-14 coefficients as shipped with ``ppigrf``.
Gebre-Egziabher, Elkaim, Powell & Parkinson, "Calibration of strapdown magnetometers in
magnetic field domain", J. Aerosp. Eng. 19(2), 2006.
"""

from __future__ import annotations

import datetime as dt

import numpy as np

from simulator.earth import euler_to_dcm
from simulator.scenario.schema import Number
from simulator.sensors.base import sample_times
from simulator.sensors.noise import gauss_markov
from simulator.sensors.presets import PresetSensor, preset_sensor_field
from simulator.tables import ColumnTable
from simulator.trajectory.kinematics import Kinematics
from simulator.units import MICRO_T

NT_TO_T = 1e-9
_FIELD_STEP_S = 10.0  # spacing of the IGRF evaluations along the drive, s

MAG_PRESETS: dict[str, dict] = {
    "ideal": {},
    # a MEMS magnetometer in a car: representative values, not a data sheet
    "automotive": {"rate": 10.0, "noise": 0.3 * MICRO_T, "hard_iron": 5 * MICRO_T,
                   "soft_iron": 0.02, "disturbance": 10 * MICRO_T, "disturbance_time": 2.0},
}

_FIELDS = {
    "rate": Number("Hz", None, gt=0, max=1000),
    "noise": Number("T", None, min=0, doc="white noise per axis, 1-sigma"),
    "hard_iron": Number("T", None, min=0, doc="hard-iron offset per axis, 1-sigma"),
    "soft_iron": Number("", None, min=0, doc="soft-iron matrix elements, 1-sigma"),
    "disturbance": Number("T", None, min=0, doc="field disturbance in covered zones, 1-sigma"),
    "disturbance_time": Number("s", None, gt=0, doc="correlation time of the disturbance"),
}
_DEFAULTS = {"rate": 10.0, "disturbance_time": 2.0}


MAG_FIELD = preset_sensor_field("magnetometer", MAG_PRESETS, _FIELDS, _DEFAULTS,
                                "is the exact IGRF field")


def earth_field_ned(lat_deg: np.ndarray, lon_deg: np.ndarray, alt_m: np.ndarray,
                    date: dt.datetime) -> np.ndarray:
    """IGRF main field (north, east, down), tesla, shape (n, 3), at geodetic positions."""
    # imported here: ppigrf (and the pandas it loads) cost a quarter of a second, and only
    # this sensor needs them
    import ppigrf

    east, north, up = ppigrf.igrf(np.asarray(lon_deg, float), np.asarray(lat_deg, float),
                                  np.asarray(alt_m, float) / 1000.0, date)
    return np.stack([np.ravel(north), np.ravel(east), -np.ravel(up)], axis=-1) * NT_TO_T


class Magnetometer(PresetSensor):
    """A magnetometer built from its resolved scenario block (``sensors.mag``)."""

    name = "mag"

    def generate(self, truth: Kinematics, rng: np.random.Generator) -> dict[str, ColumnTable]:
        c = self.config
        t = sample_times(truth.duration_s, self.rate_hz)
        k = truth.inertial(t)
        coarse = np.unique(np.append(np.arange(0.0, t[-1], _FIELD_STEP_S), t[-1]))
        pos = truth.position(coarse)
        field = earth_field_ned(np.degrees(pos[:, 0]), np.degrees(pos[:, 1]), pos[:, 2],
                                truth.utc_start)
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
        self.drawn.update(hard_iron=hard.tolist(), soft_iron=soft.tolist())
        return {"mag": {"t": t, "mag_x": m[:, 0], "mag_y": m[:, 1], "mag_z": m[:, 2]}}
