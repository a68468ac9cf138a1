"""GNSS receiver: raw pseudorange, pseudorange-rate/Doppler and C/N0 measurements of the
satellites in view (GPS, and with ``systems`` Galileo, BeiDou, GLONASS, QZSS, each on its
primary signal: docs/gnss-systems.md), and the receiver's own fixes computed from them, so that
a fix degrades exactly when and how the measurements do.

Scenario block ``sensors.gnss`` (``GNSS_FIELD``): ``rate``, ``outputs`` (``fix``, ``raw``),
``constellation`` (``gps-almanac``, the default: the real GPS constellation of the shipped
2020-01-01 almanac re-epoched to the drive, ``simulator.gnss.constellation``; ``nominal-gps``;
or a RINEX navigation file / YUMA almanac),
``expanded_slots`` (which expandable slots of ``nominal-gps`` are split into their fore/aft pairs:
any of ``B1``, ``D2``, ``F2``; all three give the 27-slot constellation), ``elevation_mask``
(deg), ``clock`` (receiver oscillator: ``tcxo``, ``ocxo``, ``ideal``), ``antenna_lever_arm``
(body FRD, m, from the IMU), the error levels and their time behaviour (``tracking_noise`` scale
of the C/N0-driven DLL/FLL jitter and the loops' bandwidths, ``carrier_smoothing`` Hatch filter,
``multipath`` zenith 1-sigma with ``multipath_distance`` and ``multipath_correlation_time``,
``cn0_fading``, ``iono_scale`` and ``iono_residual``, ``tropo_residual``, ``sis_error``,
``cn0_noise``; see ``simulator.gnss.errors``), the C/N0 parameters and ``smoothing`` (time
constant of the filtered fix output, 0 = raw single-epoch fixes). ``preset: ideal`` turns every
error off; ``automotive`` (default) is a mass-market single-frequency receiver with a TCXO;
``geodetic`` a static reference-station receiver.

Presets (the figures they follow):

- ``automotive``: DLL 0.5 Hz with 0.5-chip spacing and 100 s carrier smoothing (RTCA DO-229D,
  the 100 s Hatch filter; u-blox M8/F9 fixes change by centimetres per second while
  driving: 0.036 m/s per axis in a u-blox log at 17.6 m/s, issue 19); FLL 2 Hz: pseudorange-rate
  noise 0.024 / 0.04 / 0.08 m/s at 45 / 40 / 35 dB-Hz (Kaplan & Hegarty 2017 eq. 8.37), the
  level of the u-blox NEO-M8 datasheet's 0.05 m/s velocity accuracy (UBX-15031086) and of the
  0.097 m/s 1-sigma a u-blox M8 reports in comma2k19's log; multipath 0.3 m at zenith on the
  DO-229D J.2.4 elevation shape (0.75 m at 10 deg; Braasch 1996 for code multipath of
  mass-market antennas: metres near the horizon), decorrelating over 10 m travelled (the code
  multipath of a moving antenna keeps the envelope set by reflectors metres to tens of metres
  away; its phase rotates at v / lambda, far above the DLL bandwidth) and over 120 s standing
  still (a quarter of the Georgiadou & Kleusberg 1988 period for a reflector 2 m away at 45 deg);
  C/N0 fading 2 dB; TCXO.
- ``geodetic``: a monitor-station receiver's raw code (RINEX observations are not smoothed):
  narrow correlator 0.1 chip (Van Dierendonck, Fenton & Ford, "Theory and performance of narrow
  correlator spacing in a GPS receiver", Navigation 39(3), 1992), carrier-aided DLL 0.2 Hz, FLL
  0.5 Hz, multipath the DO-229D J.2.4 curve itself (0.13 m at zenith, 0.32 m at 10 deg: a
  choke-ring antenna), C/N0 fading 0.5 dB, OCXO.
- both: true ionosphere 1.5 x Klobuchar (Klobuchar 1987: the model removes about half of the
  rms delay; issue 19: ARL1's true ionosphere was 1.3-1.8 x the broadcast model) with a 20 %
  variation that is a smooth field over the pierce points (1000 km, 30 min;
  ``simulator.gnss.errors``); signal-in-space error 0.5 m (the GPS SPS signal-in-space URE of
  the 2010s: a global average SISRE of 0.7 m over 2013/2014, Montenbruck, Steigenberger &
  Hauschild, "Broadcast versus precise ephemerides: a multi-GNSS perspective", GPS Solutions
  19, 321-333, 2015, falling since as Block IIF/III satellites replaced older ones; kept at
  0.5 m, not fitted to the ARL1 hour, whose high satellites agree within 0.2 m:
  docs/gnss-errors.md); zenith troposphere residual 5 cm.

Signals (``systems``, ``signals``, ``carrier_phase``): each preset tracks the signals of its
receiver class (``simulator.gnss.signals.PRESET_SIGNALS``: ``geodetic`` GPS 1C 2W 5Q,
``dual-band`` a u-blox F9P-class 1C 2L, ``smartphone`` 1C 5Q, ``automotive`` and ``ideal`` 1C);
``dual-band`` and ``smartphone`` have the automotive error levels. Carrier phase, arcs, slips
and the base station (``sensors.gnss_base``): ``simulator.sensors.gnss_observables``,
docs/gnss-carrier.md.

Streams: ``gnss_raw`` (one row per tracked signal, unhealthy satellites included with their
``health`` code), ``gnss_fix`` (one row per epoch from the healthy signals: 3D fix from four
signals, 2D from three, else fix = 0 and NaN position), ``gnss_nav`` (the broadcast
elements used) and ``truth_gnss`` (the true error terms of every signal above the horizon).
Epoch times ``t`` are true GPS time since the scenario start; the receiver clock error is in
the measurements.

Public names
------------
GNSS_FIELD, PRESETS, ERROR_FIELDS, resolve_signals, Gnss.

References
----------
Oscillator h-parameters: Brown & Hwang 2012, Table 9.1. See ``simulator.gnss`` modules for the
signal, error and fix models.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable
from pathlib import Path as FilePath
from typing import TYPE_CHECKING

import numpy as np

from simulator import columns as col
from simulator.earth import (
    earth_rate_ned,
    ecef_to_geodetic,
    euler_to_dcm,
    geodetic_to_ecef,
    ned_to_ecef_matrix,
)
from simulator.environment import ZONE_FIELD
from simulator.environment.sky import canyon_reception, street_buildings
from simulator.errors import InputError, Problem, not_regular
from simulator.gnss.constants import LAMBDA_L1_M
from simulator.gnss.constellation import (
    EXPANDABLE_SLOTS,
    GPS_SKIES,
    QZSS_WITHOUT_FILE,
    missing_systems,
    sky_navigation,
)
from simulator.gnss.ephemeris import ephemeris_arrays, select_ephemeris
from simulator.gnss.errors import (
    OSCILLATORS,
)
from simulator.gnss.fix import receiver_fixes
from simulator.gnss.navfiles import read_navigation
from simulator.gnss.signals import SIGNALS, default_signals
from simulator.gnss.timesystems import SYSTEMS
from simulator.schema import (
    INVALID,
    Boolean,
    Context,
    ListOf,
    MapOf,
    Number,
    Path,
    Record,
    Text,
    Vector,
)
from simulator.sensors.base import sample_times
from simulator.sensors.gnss_observables import observe
from simulator.sensors.presets import PresetSensor, fill_from_preset, known_preset
from simulator.stochastic import child_rng
from simulator.timebase import utc_to_gps
from simulator.trajectory.kinematics import Kinematics

if TYPE_CHECKING:
    import pandas as pd

# the receivers' error levels and loops; sources in the module docstring, "Presets"
_LOOPS = {"dll_bandwidth": 0.5, "correlator_spacing": 0.5, "fll_bandwidth": 2.0,
          "pll_bandwidth": 15.0}
_ATMOSPHERE_AND_SKY = {"iono_scale": 1.5, "iono_residual": 0.2, "tropo_residual": 0.05,
                       "sis_error": 0.5, "iono_gradient": 0.5e-6,  # 0.5 mm/km
                       "tropo_gradient": 0.25e-6}  # 0.25 mm/km per axis
_MULTIPATH_MOTION = {"multipath_distance": 10.0, "multipath_correlation_time": 120.0}
_AUTOMOTIVE = {"clock": "tcxo", "tracking_noise": 1.0, **_LOOPS, "carrier_smoothing": 100.0,
               "multipath": 0.3, "multipath_delay": 3.0, **_MULTIPATH_MOTION, "cn0_fading": 2.0,
               "cn0_noise": 1.0, **_ATMOSPHERE_AND_SKY}
PRESETS: dict[str, dict] = {
    "automotive": _AUTOMOTIVE,
    "dual-band": _AUTOMOTIVE,
    "smartphone": _AUTOMOTIVE,
    "geodetic": {"clock": "ocxo", "tracking_noise": 1.0, "dll_bandwidth": 0.2,
                 "correlator_spacing": 0.1, "fll_bandwidth": 0.5, "pll_bandwidth": 10.0,
                 "carrier_smoothing": 0.0, "multipath": 0.13, "multipath_delay": 10.0,
                 **_MULTIPATH_MOTION, "cn0_fading": 0.5, "cn0_noise": 0.25,
                 **_ATMOSPHERE_AND_SKY},
    "ideal": {"clock": "ideal", "tracking_noise": 0.0, **_LOOPS, "carrier_smoothing": 0.0,
              "multipath": 0.0, "multipath_delay": 10.0, **_MULTIPATH_MOTION, "cn0_fading": 0.0,
              "cn0_noise": 0.0, "iono_scale": 1.0, "iono_residual": 0.0, "tropo_residual": 0.0,
              "sis_error": 0.0, "iono_gradient": 0.0, "tropo_gradient": 0.0},
}
# broadcast ionosphere used with the nominal constellation: the coefficients of the IGS
# broadcast file brdc1190.21n (2021-04-29), a moderate solar-activity day
DEFAULT_IONO_ALPHA = [0.9313e-08, 0.1490e-07, -0.5960e-07, -0.1192e-06]
DEFAULT_IONO_BETA = [0.8806e05, 0.4915e05, -0.1311e06, -0.3277e06]
# the constellations known by name (anything else names a file)
CONSTELLATIONS = GPS_SKIES
ALMANAC_MAX_AGE_S = 7 * 86400.0  # a YUMA almanac file is used up to a week from its TOA
# a zone the environment block does not describe, or describes in part: the schema's defaults
_ZONE_DEFAULTS = ZONE_FIELD.check({}, ("environment", "zones", "*"), Context("defaults"))


# the error levels a preset sets (a key the scenario gives overrides the preset's value)
ERROR_FIELDS = {
    "clock": Text(None, doc="receiver oscillator: tcxo, ocxo or ideal"),
    "tracking_noise": Number("", None, min=0,
                             doc="scale of the C/N0-driven DLL and FLL noise (0 = off)"),
    "dll_bandwidth": Number("Hz", None, gt=0,
                            doc="code tracking loop (DLL) noise bandwidth; its time constant "
                                "1 / (4 B) correlates the code noise"),
    "correlator_spacing": Number("", None, gt=0, max=1, doc="early-late spacing, chips"),
    "fll_bandwidth": Number("Hz", None, gt=0,
                            doc="carrier (frequency) loop noise bandwidth: the Doppler noise"),
    "carrier_smoothing": Number("s", None, min=0,
                                doc="time constant of the Hatch filter smoothing the code with "
                                    "the carrier (0 = raw code)"),
    "multipath": Number("m", None, min=0, doc="code multipath 1-sigma at zenith"),
    "multipath_distance": Number("m", None, gt=0,
                                 doc="distance travelled over which multipath and C/N0 fading "
                                     "decorrelate (1 / e)"),
    "multipath_correlation_time": Number("s", None, gt=0,
                                         doc="their correlation time standing still (the "
                                             "satellites' motion)"),
    "cn0_fading": Number("", None, min=0,
                         doc="C/N0 fading 1-sigma, dB, correlated like the multipath"),
    "cn0_noise": Number("", None, min=0, doc="C/N0 estimate noise 1-sigma, dB, white"),
    "iono_scale": Number("", None, min=0,
                         doc="mean true ionosphere / broadcast (Klobuchar) ionosphere"),
    "iono_residual": Number("", None, min=0,
                            doc="1-sigma of the relative variation of that ratio, a field "
                                "smooth over the pierce points (1000 km) and in time (30 min)"),
    "tropo_residual": Number("m", None, min=0, doc="zenith troposphere model error 1-sigma"),
    "sis_error": Number("m", None, min=0, doc="signal-in-space range error 1-sigma"),
    "pll_bandwidth": Number("Hz", None, gt=0,
                            doc="carrier phase-lock loop noise bandwidth (third order): the "
                                "phase jitter and the loop's dynamic stress"),
    "multipath_delay": Number("m", None, gt=0,
                              doc="extra path of the reflection giving the multipath: its "
                                  "relative amplitude is the code multipath / this, which sets "
                                  "the carrier multipath, and its phase turns with frequency"),
    "iono_gradient": Number("", None, min=0,
                            doc="rms horizontal gradient of the vertical L1 ionosphere from "
                                "travelling disturbances (150 km, 15 min), e.g. '0.5 mm/km': "
                                "what a base station at a distance does not share"),
    "tropo_gradient": Number("", None, min=0,
                             doc="1-sigma per horizontal axis of the zenith troposphere "
                                 "residual's gradient, e.g. '0.25 mm/km', held for the drive"),
}


def _resolve(value: dict, path: Path, ctx: Context) -> dict:
    if not known_preset(value["preset"], PRESETS, "GNSS", path, ctx):
        return INVALID
    value = fill_from_preset(value, PRESETS[value["preset"]], ERROR_FIELDS, path, ctx, {})
    if value is INVALID:
        return INVALID
    if value["clock"] not in OSCILLATORS:
        return ctx.error(path + ("clock",), f"unknown oscillator {value['clock']!r}; known: "
                                            f"{', '.join(sorted(OSCILLATORS))}")
    source = value["constellation"]
    expanded = value["expanded_slots"]
    if len(set(expanded)) < len(expanded):
        return ctx.error(path + ("expanded_slots",), "names a slot more than once")
    if expanded and source != "nominal-gps":
        return ctx.error(path + ("expanded_slots",), "only applies to constellation "
                                                     "'nominal-gps' (name it: the default is "
                                                     "'gps-almanac')")
    if len(set(value["systems"])) < len(value["systems"]):
        return ctx.error(path + ("systems",), "names a system more than once")
    if source in CONSTELLATIONS and "qzss" in value["systems"]:
        return ctx.error(path + ("systems",), QZSS_WITHOUT_FILE)
    if source not in CONSTELLATIONS:
        candidates = [FilePath(source)]
        if ctx.file and not FilePath(source).is_absolute():
            candidates.insert(0, FilePath(ctx.file).resolve().parent / source)
        found = [c for c in candidates if c.is_file()]
        other = next((kind for c in candidates
                      if (kind := not_regular(c)) not in (None, "missing")), None)
        if not found and other is not None:
            return ctx.error(path + ("constellation",), f"{source!r} is {other}, not a RINEX "
                                                        "navigation or YUMA almanac file")
        if not found:
            return ctx.error(path + ("constellation",),
                             f"{source!r} is neither 'gps-almanac', 'nominal-gps' nor an "
                             "existing RINEX navigation or YUMA almanac file")
        value["constellation"] = str(found[0].resolve())
        try:
            nav = read_navigation(found[0])
        except (ValueError, OSError) as exc:
            return ctx.error(path + ("constellation",), str(exc))
        problem = missing_systems(nav, value["systems"], str(found[0]))
        if problem:
            return ctx.error(path + ("systems",), problem)
    if value["cn0_horizon"] > value["cn0_zenith"]:
        return ctx.error(path + ("cn0_horizon",), "must not exceed cn0_zenith")
    return resolve_signals(value, path, ctx)


def resolve_signals(value: dict, path: Path, ctx: Context) -> dict:
    """``systems`` known and distinct (the rover's block has checked them against its sky),
    ``signals`` filled from the preset for each system and known, ``carrier_phase`` defaulted
    to whether raw measurements are output."""
    systems = value["systems"]
    unknown = [name for name in systems if name not in SYSTEMS]
    if unknown or not systems or len(set(systems)) < len(systems):
        return ctx.error(path + ("systems",), f"expected distinct names among "
                                              f"{', '.join(SYSTEMS)}, got {systems!r}")
    given = value["signals"] or {}
    extra = sorted(set(given) - set(systems))
    if extra:
        return ctx.error(path + ("signals",), f"names {', '.join(extra)}, not in systems")
    signals = default_signals(value["preset"], systems)
    for name, codes in given.items():
        letter = SYSTEMS[name]
        bad = [c for c in codes if (letter, c) not in SIGNALS]
        if bad or not codes or len(set(codes)) < len(codes):
            known = sorted(c for sys_, c in SIGNALS if sys_ == letter)
            return ctx.error(path + ("signals", name), f"expected distinct signal codes among "
                                                       f"{', '.join(known)}, got {codes!r}")
        signals[name] = list(codes)
    value["signals"] = signals
    if value["carrier_phase"] is None:
        value["carrier_phase"] = "raw" in value["outputs"]
    return value


GNSS_FIELD = Record(
    {
        "preset": Text("automotive", doc="error preset: 'automotive', 'geodetic' or 'ideal' "
                                         "(no errors)"),
        "rate": Number("Hz", 1.0, gt=0, max=100, doc="epoch rate"),
        "outputs": ListOf(Text(choices=["fix", "raw"]), ["fix", "raw"], min_len=1,
                          doc="streams written: gnss_fix and/or gnss_raw"),
        "constellation": Text("gps-almanac",
                              doc="'gps-almanac' (the real GPS of the NAVCEN almanac of "
                                  "2020-01-01, 31 satellites, re-epoched to the drive by whole "
                                  "ground-track repeats), 'nominal-gps' (the 24 SPS slots) or a "
                                  "RINEX navigation file or YUMA almanac"),
        "systems": ListOf(Text(choices=list(SYSTEMS)), ["gps"], min_len=1,
                          doc="satellite systems received: gps, galileo, beidou, glonass, "
                              "qzss (from the named sky's nominal constellations, or from the "
                              "navigation file, which must have them)"),
        "expanded_slots": ListOf(Text(choices=list(EXPANDABLE_SLOTS)), [],
                                 doc="expandable slots of 'nominal-gps' split into their fore/aft "
                                     "pairs (SPS PS 2008 Table 3.4-2); [B1, D2, F2] = 27 slots"),
        "elevation_mask": Number(angle=True, default=10.0, min=0, max=90,
                                 doc="satellites below it are not tracked"),
        "antenna_lever_arm": Vector(3, Number("m"), [0.0, 0.0, 0.0],
                                    doc="antenna position in the body frame (FRD) from the IMU"),
        "signals": MapOf(ListOf(Text()), None,
                         doc="per system, the RINEX 3 codes of the signals tracked, e.g. "
                             "{gps: [1C, 2W]}; default: the preset's "
                             "(simulator.gnss.signals.PRESET_SIGNALS)"),
        "carrier_phase": Boolean(None, doc="output carrier phase, LLI and lock time (default: "
                                           "when raw is an output)"),
        **ERROR_FIELDS,
        "cn0_zenith": Number("", 46.5, doc="C/N0 of a satellite at zenith, dB-Hz"),
        "cn0_horizon": Number("", 18.0, doc="C/N0 extrapolated to the horizon, dB-Hz"),
        "cn0_threshold": Number("", 17.0,
                                doc="tracking threshold, dB-Hz (the weakest signal the "
                                    "comma2k19 car's u-blox reports)"),
        "integration_time": Number("s", 0.02, gt=0, max=0.02,
                                   doc="coherent integration time of the correlators"),
        "smoothing": Number("s", 0.0, min=0, doc="fix smoothing time constant (0 = none)"),
        "dop_mask": Number("", 20.0, gt=0, doc="no fix when the HDOP is above this"),
    },
    default=None,
    post=_resolve,
)


class Gnss(PresetSensor):
    """A GPS L1 C/A receiver built from its resolved scenario block (``sensors.gnss``)."""

    name = "gnss"

    def __init__(self, config: dict):
        super().__init__(config)
        self.drawn["constellation"] = config["constellation"]

    def timing(self) -> dict[str, dict]:
        """Epochs are stamped with the true GPS time of the measurement (the receiver's clock
        error is in the measurements, not in ``t``); the fix of an epoch uses that epoch's
        measurements only."""
        stamp = "the true GPS time of the measurement epoch"
        return {"gnss_fix": {"stamp": stamp, "delay_s": 0.0,
                             "no_fix": "epochs without a fix are rows with fix = 0 and NaN "
                                       "position and velocity"},
                "gnss_raw": {"stamp": stamp, "delay_s": 0.0,
                             "no_fix": "one row per tracked satellite; an epoch with no "
                                       "satellite has no row"}}

    # -- inputs --------------------------------------------------------------------------------
    def navigation(self, truth: Kinematics) -> pd.DataFrame:
        """The navigation table used for the drive: the enabled systems of the named sky or of
        the named file (``simulator.gnss.constellation.sky_navigation``)."""
        week0, _ = utc_to_gps(truth.utc_start)
        nav = sky_navigation(self.config["constellation"], self.config["systems"],
                             truth.utc_start, truth.duration_s, self.config["expanded_slots"],
                             reference_week=week0)
        if self.config["constellation"] in CONSTELLATIONS:
            nav.attrs.update(iono_alpha=DEFAULT_IONO_ALPHA, iono_beta=DEFAULT_IONO_BETA)
        return nav

    def antenna(self, truth: Kinematics, t: np.ndarray) -> dict[str, np.ndarray]:
        """Antenna ECEF position and velocity, geodetic position, and heading at times t."""
        k = truth.inertial(t)
        lever = np.asarray(self.config["antenna_lever_arm"], dtype=float)
        c_bn = euler_to_dcm(k["roll"], k["pitch"], k["yaw"])
        c_ne = ned_to_ecef_matrix(k["lat"], k["lon"])
        pos = geodetic_to_ecef(k["lat"], k["lon"], k["alt"])
        pos = pos + np.einsum("nij,njk,k->ni", c_ne, c_bn, lever)
        # body rate w.r.t. the Earth, w_eb^b = w_ib^b - C_n^b w_ie^n, turns the lever arm
        w_eb = k["w_body"] - np.einsum("nji,nj->ni", c_bn, earth_rate_ned(k["lat"]))
        v_ned = k["v_ned"] + np.einsum("nij,nj->ni", c_bn, np.cross(w_eb, lever))
        vel = np.einsum("nij,nj->ni", c_ne, v_ned)
        lat, lon, alt = ecef_to_geodetic(pos)
        return {"pos": pos, "vel": vel, "v_ned": v_ned, "lat": lat, "lon": lon, "alt": alt,
                "yaw": k["yaw"], "distance": k["distance"]}

    def sky(self, truth: Kinematics, t: np.ndarray, az: np.ndarray, el: np.ndarray,
            yaw: np.ndarray, distance: np.ndarray, rng: np.random.Generator,
            antenna_gain_db: Callable[[np.ndarray], np.ndarray] | None = None,
            rows: np.ndarray | None = None, n_sky: int | None = None
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Line of sight, NLOS, NLOS extra path (m) and C/N0 loss (dB) per satellite and epoch
        from the environment zones (``sky``: open, none, canyon).

        A canyon (``simulator.environment.sky.canyon_reception``) is one street from where its
        zone begins to where it ends along the drive (consecutive segments of the zone make one
        street), closed at both ends by facades across it. Its buildings are laid out block by
        block with drawn heights (``street_buildings``: blocks of ``block_length``, cross streets
        of ``cross_street_width``, buildings of ``facade_length`` ``building_gap`` apart, heights
        from N(``building_height``, ``building_height_spread``)); the along-street coordinate
        is the antenna's distance driven. Each facade's reflection loss is drawn from
        N(``nlos_attenuation``, ``nlos_attenuation_spread``), floored at 0 dB, once per
        satellite and building (each end facade counts as one), and applied where that building
        is the reflection point. Diffuse scattering off the facade across the street
        (``scattering_coefficient``) arrives from that facade, where the antenna's gain
        (``antenna_gain_db`` against elevation) differs from its gain toward the satellite.
        Each canyon zone draws from its own stream (``rng``'s child named after the zone).
        ``az`` and ``el`` may be those of some satellites only, ``rows`` of the ``n_sky`` of the
        sky: the draws are those of every satellite, of which these keep their own."""
        los = np.ones(el.shape, dtype=bool)
        nlos = np.zeros(el.shape, dtype=bool)
        extra = np.zeros(el.shape)
        loss = np.zeros(el.shape)
        zones = (truth.environment or {}).get("zones", {}) or {}
        names = truth.zone_at(t)
        for name in sorted(set(names) - {""}):  # one pass per zone
            zone = {**_ZONE_DEFAULTS, **(zones.get(name) or {})}
            here = names == name
            if zone["sky"] == "none":
                los[:, here] = False
            elif zone["sky"] == "canyon":
                ahead, behind, streets = _street_ends(truth, name, t[here], distance[here])
                zone_rng = child_rng(rng, name)  # each canyon zone's own stream
                buildings = street_buildings(
                    zone_rng, streets, zone["block_length"], zone["cross_street_width"],
                    zone["facade_length"], zone["building_gap"], zone["building_height"],
                    zone["building_height_spread"])
                draws = zone_rng.standard_normal((el.shape[0] if n_sky is None else n_sky,
                                                  buildings.count))
                facade_loss = np.maximum(zone["nlos_attenuation"] + zone["nlos_attenuation_spread"]
                                         * (draws if rows is None else draws[rows]), 0.0)
                # traced only for the satellites above the horizon (about 40 % of them)
                shape = el[:, here].shape
                up = el[:, here] > 0
                satellite = np.broadcast_to(np.arange(shape[0])[:, None], shape)[up]
                z_los, z_nlos = np.zeros(shape, dtype=bool), np.zeros(shape, dtype=bool)
                z_extra, z_loss = np.zeros(shape), np.zeros(shape)
                z_los[up], z_nlos[up], z_extra[up], z_loss[up] = canyon_reception(
                    az[:, here][up], el[:, here][up], np.broadcast_to(yaw[here], shape)[up],
                    zone["building_height"], zone["street_width"],
                    np.broadcast_to(ahead, shape)[up], np.broadcast_to(behind, shape)[up],
                    facade_loss, LAMBDA_L1_M, np.broadcast_to(distance[here], shape)[up],
                    buildings, satellite, zone["scattering_coefficient"], antenna_gain_db)
                los[:, here], nlos[:, here], extra[:, here] = z_los, z_nlos, z_extra
                loss[:, here] = z_loss
        return los, nlos, extra, loss

    def _check_coverage(self, idx: np.ndarray, t: np.ndarray, truth: Kinematics,
                        max_age_s: float | None) -> None:
        """A navigation file that does not cover the drive is an input error, not a silent
        outage: at least four satellites need an ephemeris at every epoch."""
        short = (idx >= 0).sum(axis=0) < 4
        if short.any():
            raise InputError([Problem(
                self.config["constellation"], None, "sensors.gnss.constellation",
                "fewer than four satellites have an ephemeris within "
                + (f"{max_age_s / 3600:g} h" if max_age_s else "its validity (half the "
                   "broadcast fit interval: GPS and Galileo 2 h, BeiDou and QZSS 1 h, GLONASS "
                   "30 min; older records are not used)")
                + f" of the drive from t = {t[short][0]:g} s (the drive starts "
                f"{truth.utc_start:%Y-%m-%d %H:%M:%S} UTC); use a navigation file of that "
                "day or 'nominal-gps'")])

    # -- generation ----------------------------------------------------------------------------
    def attach(self, companion: PresetSensor) -> None:
        """Make ``companion`` (the base station, ``sensors.gnss_base``) with this receiver: it
        sees the same satellites, broadcast errors and atmosphere."""
        self.base = companion

    def broadcast(self, truth: Kinematics, t: np.ndarray) -> dict:
        """The broadcast records each satellite uses at each epoch and what comes with them."""
        week0, tow0 = utc_to_gps(truth.utc_start)
        nav = self.navigation(truth)
        eph = ephemeris_arrays(nav, week0)
        # an almanac describes the orbits for days (coarsely); an ephemeris only within its fit
        # interval. Unhealthy satellites are tracked and flagged; the fixes leave them out.
        almanac = nav.attrs.get("kind") == "almanac"
        max_age = ALMANAC_MAX_AGE_S if almanac else None  # None: each system's own
        sats = nav[["system", "sv"]].drop_duplicates().sort_values(["system", "sv"])
        systems, svs = sats["system"].to_numpy(dtype=str), sats["sv"].to_numpy(dtype=int)
        idx = select_ephemeris(eph, svs[:, None], tow0 + t[None, :], max_age_s=max_age,
                               healthy_only=False, system=systems[:, None])
        self._check_coverage(idx, t, truth, max_age)
        alpha = list(nav.attrs.get("iono_alpha", DEFAULT_IONO_ALPHA))
        beta = list(nav.attrs.get("iono_beta", DEFAULT_IONO_BETA))
        self.drawn["broadcast_iono"] = {"alpha": alpha, "beta": beta}
        corrections = nav.attrs.get("time_corrections") or {}
        if corrections:  # the file's system time offsets, for its RINEX export
            self.drawn["time_corrections"] = {k: list(v) for k, v in corrections.items()}
        new_year = dt.datetime(truth.utc_start.year, 1, 1)
        day_of_year = (truth.utc_start - new_year).total_seconds() / 86400.0 + 1.0 + t / 86400.0
        # each satellite's system and GLONASS frequency channel (the signals' frequencies)
        channel = nav.groupby(["system", "sv"])["glo_channel"].first().loc[
            list(zip(systems, svs, strict=True))].to_numpy()
        return {"nav": nav, "eph": eph, "idx": idx, "svs": svs, "systems": systems,
                "channel": np.nan_to_num(channel.astype(float)), "t_gps": tow0 + t,
                "alpha": alpha, "beta": beta, "day_of_year": day_of_year}

    def generate(self, truth: Kinematics, rng: np.random.Generator) -> dict[str, pd.DataFrame]:
        cfg = self.config
        t = sample_times(truth.duration_s, self.rate_hz)
        dt_s = 1.0 / self.rate_hz
        sky = self.broadcast(truth, t)
        ant = self.antenna(truth, t)

        def reception(az: np.ndarray, el: np.ndarray, antenna_gain_db: Callable,
                      rows: np.ndarray) -> tuple[np.ndarray, ...]:
            return self.sky(truth, t, az, el, ant["yaw"], ant["distance"],
                            child_rng(rng, "environment"), antenna_gain_db, rows,
                            len(sky["svs"]))

        rover = observe(cfg, t, dt_s, sky, ant, rng, reception)
        self.drawn.update(rover.drawn)
        self.true_errors.update(clock_bias=(t, rover.clock_m), clock_drift=(t, rover.drift_m_s))
        used = np.unique(sky["idx"][sky["idx"] >= 0])
        out = {"gnss_nav": sky["nav"].iloc[used].reset_index(drop=True)[list(col.GNSS_NAV)],
               "truth_gnss": rover.truth}
        # the raw stream always comes out here: faults act on the measurements and the fixes
        # are recomputed from them; the generator drops it if the scenario did not ask for it
        out["gnss_raw"] = rover.raw
        if "fix" in cfg["outputs"]:
            out["gnss_fix"] = receiver_fixes(t, rover.raw, cfg["smoothing"], cfg["dop_mask"], cfg)
        base = getattr(self, "base", None)
        if base is not None:
            out.update(base.observe_with(self, truth, t, dt_s, sky, rover.shared))
        return out


def _street_ends(truth: Kinematics, zone: str, t: np.ndarray, distance: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distance to the end facade ahead and behind (along the drive) at epochs t inside
    ``zone``, and each street's start and end in the distance driven (rows): consecutive
    stretches of the zone (one segment's end is the next one's start) make one street."""
    streets: list[list[float]] = []
    for start, end, name in truth.profile.zones:  # one pass per zoned segment
        if name != zone:
            continue
        if streets and abs(start - streets[-1][1]) < 1e-9:
            streets[-1][1] = end
        else:
            streets.append([start, end])
    bounds = np.asarray(streets, dtype=float).reshape(-1, 2)
    street = np.clip(np.searchsorted(bounds[:, 0], t, side="right") - 1, 0, len(bounds) - 1)
    at = truth.inertial(bounds.ravel())["distance"].reshape(-1, 2)
    return (np.maximum(at[street, 1] - distance, 0.0), np.maximum(distance - at[street, 0], 0.0),
            at)
