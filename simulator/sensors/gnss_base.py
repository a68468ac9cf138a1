"""The base station (``sensors.gnss_base``): a static reference receiver for relative
positioning (RTK), made by the rover's receiver model so that it sees the same satellites, the
same broadcast records and their errors, and the same ionosphere and troposphere, each at its
own place (``simulator.sensors.gnss_observables``: the fields at its own pierce points, the
troposphere's gradient, the orbit error along its own lines of sight); its clock, multipath,
C/N0 fading and tracking noise are its own (the rover's child stream ``second_receiver``).

Scenario block: ``position`` ({lat, lon, alt}) or ``offset`` ({east, north, up} in m from the
drive's start), ``preset`` (default ``geodetic``), ``rate`` (the rover's rate divided by a whole
number), ``systems``, ``signals``, ``elevation_mask`` and the error overrides of
``sensors.gnss``. The base is in open sky (no zone acts on it).

Streams: ``gnss_base_raw`` (the columns of ``gnss_raw``) and ``truth_gnss_base``; the manifest's
``gnss_base`` holds its position.

Public names
------------
GNSS_BASE_FIELD, GnssBase.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from simulator.earth import ecef_to_geodetic, geodetic_to_ecef, ned_to_ecef
from simulator.schema import INVALID, Context, Number, Path, Record, Text
from simulator.sensors.gnss import ERROR_FIELDS, GNSS_FIELD, PRESETS, resolve_signals
from simulator.sensors.gnss_observables import observe
from simulator.sensors.presets import PresetSensor, fill_from_preset, known_preset

if TYPE_CHECKING:
    import pandas as pd

    from simulator.trajectory.kinematics import Kinematics

# the keys of the rover's block that a base station takes too
_SHARED_KEYS = ("systems", "signals", "carrier_phase", "elevation_mask", "cn0_zenith",
                "cn0_horizon", "cn0_threshold", "integration_time")


def _resolve(value: dict, path: Path, ctx: Context) -> dict:
    if (value["position"] is None) == (value["offset"] is None):
        return ctx.error(path, "give exactly one of position and offset")
    if not known_preset(value["preset"], PRESETS, "GNSS", path, ctx):
        return INVALID
    value = fill_from_preset(value, PRESETS[value["preset"]], ERROR_FIELDS, path, ctx, {})
    if value is INVALID:
        return INVALID
    value["outputs"] = ["raw"]
    return resolve_signals(value, path, ctx)


GNSS_BASE_FIELD = Record(
    {
        "preset": Text("geodetic", doc="error preset of the reference receiver (as "
                                       "sensors.gnss)"),
        "rate": Number("Hz", 1.0, gt=0, max=100,
                       doc="epoch rate; the rover's rate must be a whole multiple of it"),
        "position": Record({"lat": Number(angle=True, min=-90, max=90, doc="latitude, deg"),
                            "lon": Number(angle=True, min=-180, max=180,
                                          doc="longitude, deg"),
                            "alt": Number("m", doc="ellipsoidal height")}, default=None,
                           doc="the antenna's geodetic position"),
        "offset": Record({"east": Number("m", 0.0, doc="east of the drive's start"),
                          "north": Number("m", 0.0, doc="north of the drive's start"),
                          "up": Number("m", 0.0, doc="above the drive's start")},
                         default=None, doc="the antenna's position from the drive's start, m"),
        **{key: GNSS_FIELD.fields[key] for key in _SHARED_KEYS},
        **ERROR_FIELDS,
    },
    default=None,
    post=_resolve,
)


class GnssBase(PresetSensor):
    """The base station; its stream is made by the rover (``Gnss.attach``)."""

    name = "gnss_base"
    host = "gnss"  # the sensor that makes this one's streams

    def generate(self, truth: Kinematics, rng: np.random.Generator) -> dict:
        """Nothing: the rover's receiver makes the base's streams (``observe_with``)."""
        return {}

    def timing(self) -> dict[str, dict]:
        return {"gnss_base_raw": {"stamp": "the true GPS time of the measurement epoch",
                                  "delay_s": 0.0}}

    def position_ecef(self, truth: Kinematics) -> np.ndarray:
        """The antenna's ECEF position, m."""
        cfg = self.config
        if cfg["position"] is not None:
            p = cfg["position"]
            return np.ravel(geodetic_to_ecef(np.radians(p["lat"]), np.radians(p["lon"]),
                                             p["alt"]))
        start = truth.inertial(np.zeros(1))
        o = cfg["offset"]
        ned = np.array([[o["north"], o["east"], -o["up"]]])
        return ned_to_ecef(ned, float(start["lat"][0]), float(start["lon"][0]),
                           float(start["alt"][0]))[0]

    def observe_with(self, rover: PresetSensor, truth: Kinematics, t: np.ndarray, dt_s: float,
                     sky: dict, shared: object) -> dict[str, pd.DataFrame]:
        """The base's streams at the rover's epochs ``t``, kept at the base's own rate."""
        pos = self.position_ecef(truth)
        lat, lon, alt = (float(v) for v in np.ravel(ecef_to_geodetic(pos[None, :])))
        n = len(t)
        ant = {"pos": np.tile(pos, (n, 1)), "vel": np.zeros((n, 3)),
               "v_ned": np.zeros((n, 3)), "lat": np.full(n, lat), "lon": np.full(n, lon),
               "alt": np.full(n, alt), "yaw": np.zeros(n), "distance": np.zeros(n)}

        def open_sky(az: np.ndarray, el: np.ndarray, gain: object, rows: np.ndarray
                     ) -> tuple[np.ndarray, ...]:
            return (np.ones(el.shape, bool), np.zeros(el.shape, bool), np.zeros(el.shape),
                    np.zeros(el.shape))

        base = observe(self.config, t, dt_s, sky, ant, shared.second_rng,
                       open_sky, shared)
        self.drawn.update(base.drawn)
        self.drawn["position"] = {"lat": np.degrees(lat), "lon": np.degrees(lon), "alt": alt,
                                  "x": float(pos[0]), "y": float(pos[1]), "z": float(pos[2])}
        if int(round(rover.rate_hz / self.rate_hz)) == 1:  # every epoch kept: no copy
            return {"gnss_base_raw": base.raw, "truth_gnss_base": base.truth}
        kept_t = t[np.round(t * self.rate_hz, 9) % 1 == 0]
        return {"gnss_base_raw": base.raw[base.raw["t"].isin(kept_t)].reset_index(drop=True),
                "truth_gnss_base": base.truth[base.truth["t"].isin(kept_t)]
                .reset_index(drop=True)}
