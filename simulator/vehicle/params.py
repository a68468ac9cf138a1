"""The scenario's ``vehicle`` block: ``rigid`` (the body is a point that follows the road exactly,
the behaviour before issue 13), a car preset's name, or a mapping of a ``preset`` and single-key
overrides.

Presets (``VEHICLE_PRESETS``) hold the parameters of three common cars. Masses, wheelbases,
tracks and centre-of-gravity heights are typical of their class (Gillespie, *Fundamentals of
Vehicle Dynamics*, SAE 1992, Table 5.1 and ch. 5: sprung-mass ride frequencies of 1-1.5 Hz,
damping ratios of 0.2-0.4, wheel-hop near 10 Hz); cornering stiffnesses are those of passenger-car
tyres (Rajamani, *Vehicle Dynamics and Control*, 2nd ed., Springer 2012, ch. 2-3: some 60-100
kN/rad per tyre). The corners' horizontal stiffnesses follow from the tyre's relaxation length
sigma, the ratio of its slip stiffness to its carcass stiffness (Pacejka, *Tire and Vehicle
Dynamics*, 3rd ed., 2012, ch. 7: sigma = C / c): sideways the cornering stiffness of one tyre
over sigma_y = 0.5 m, fore-aft a longitudinal slip stiffness of about 60 kN over sigma_x =
0.2 m (chosen values of a passenger-car tyre; the suspension's bushings, several times stiffer,
are left out of the series). The ``automotive`` preset is the default (``default_vehicle``).

Public names
------------
VEHICLE_FIELD, VEHICLE_PRESETS, ROUGHNESS_CLASSES, default_vehicle, vehicle_parameters.
"""

from __future__ import annotations

from typing import Any

from simulator.schema import (
    INVALID,
    Context,
    Either,
    Integer,
    Number,
    Path,
    Record,
    Text,
    Vector,
)
from simulator.vehicle.suspension import corner_ride_rates

# ISO 8608:2016 Table 1: the geometric mean of each class's displacement PSD Gd(n0) at the
# reference spatial frequency n0 = 0.1 cycle/m, m^3 (waviness w = 2)
ROUGHNESS_CLASSES = {"A": 16e-6, "B": 64e-6, "C": 256e-6, "D": 1024e-6, "E": 4096e-6}

VEHICLE_PRESETS: dict[str, dict[str, Any]] = {
    # a mid-size saloon: 1500 kg, 2.7 m wheelbase, 57 % of the weight on the front axle
    "automotive": dict(
        mass=1500.0, wheelbase=2.7, front_weight=0.57, track=1.55, cg_height=0.55,
        pitch_inertia=2400.0, roll_inertia=550.0, unsprung_mass=40.0,
        front_frequency=1.2, rear_frequency=1.35, damping=0.3,
        tyre_stiffness=2.2e5, roll_stiffness=5.0e4,
        tyre_longitudinal_stiffness=3.0e5, tyre_lateral_stiffness=1.5e5,
        front_cornering=1.4e5, rear_cornering=1.6e5,
        imu_position=[0.2, 0.0, -0.1], roughness="B", camber=0.02,
        engine_frequency=28.0, engine_accel=0.05),
    # a compact hatchback: lighter and shorter, a softer ride
    "compact": dict(
        mass=1150.0, wheelbase=2.5, front_weight=0.62, track=1.47, cg_height=0.52,
        pitch_inertia=1500.0, roll_inertia=380.0, unsprung_mass=33.0,
        front_frequency=1.3, rear_frequency=1.45, damping=0.3,
        tyre_stiffness=1.9e5, roll_stiffness=3.5e4,
        tyre_longitudinal_stiffness=2.6e5, tyre_lateral_stiffness=1.3e5,
        front_cornering=1.1e5, rear_cornering=1.25e5,
        imu_position=[0.2, 0.0, -0.1], roughness="B", camber=0.02,
        engine_frequency=30.0, engine_accel=0.06),
    # a sport-utility vehicle: heavier, a higher centre of gravity, stiffer springs
    "suv": dict(
        mass=2000.0, wheelbase=2.8, front_weight=0.55, track=1.63, cg_height=0.70,
        pitch_inertia=3800.0, roll_inertia=850.0, unsprung_mass=50.0,
        front_frequency=1.3, rear_frequency=1.45, damping=0.3,
        tyre_stiffness=2.6e5, roll_stiffness=7.0e4,
        tyre_longitudinal_stiffness=3.5e5, tyre_lateral_stiffness=1.8e5,
        front_cornering=1.7e5, rear_cornering=1.9e5,
        imu_position=[0.2, 0.0, -0.15], roughness="B", camber=0.02,
        engine_frequency=25.0, engine_accel=0.05),
}
DEFAULT_PRESET = "automotive"
RIGID = "rigid"

_FIELDS = {
    "preset": Text(DEFAULT_PRESET, choices=sorted(VEHICLE_PRESETS),
                   doc="car whose parameters fill the keys not given"),
    "mass": Number("kg", None, gt=0, doc="total mass"),
    "wheelbase": Number("m", None, gt=0, max=10.0, doc="front to rear axle"),
    "front_weight": Number("", None, gt=0, lt=1,
                           doc="share of the weight on the front axle (sets the centre of "
                               "gravity between the axles)"),
    "track": Number("m", None, gt=0, max=3.0, doc="distance between the left and right wheels"),
    "cg_height": Number("m", None, gt=0, max=3.0,
                        doc="centre of gravity above the pitch and roll axes (load transfer)"),
    "pitch_inertia": Number("kg*m^2", None, gt=0, doc="sprung-mass pitch moment of inertia"),
    "roll_inertia": Number("kg*m^2", None, gt=0, doc="sprung-mass roll moment of inertia"),
    "unsprung_mass": Number("kg", None, gt=0, doc="mass of one wheel, tyre, brake and hub"),
    "front_frequency": Number("Hz", None, gt=0, max=5.0,
                              doc="ride frequency of the sprung mass on the front springs"),
    "rear_frequency": Number("Hz", None, gt=0, max=5.0,
                             doc="ride frequency of the sprung mass on the rear springs"),
    "damping": Number("", None, gt=0, max=2.0, doc="damping ratio of the ride modes"),
    "tyre_stiffness": Number("N/m", None, gt=0, doc="vertical stiffness of one tyre"),
    "roll_stiffness": Number("N*m/rad", None, min=0,
                             doc="anti-roll bars, front and rear together"),
    "tyre_longitudinal_stiffness": Number("N/m", None, gt=0,
                                          doc="fore-aft stiffness of one corner (tyre carcass "
                                              "in series with the suspension's compliance)"),
    "tyre_lateral_stiffness": Number("N/m", None, gt=0,
                                     doc="sideways stiffness of one corner (tyre carcass in "
                                         "series with the suspension's compliance)"),
    "front_cornering": Number("N/rad", None, gt=0,
                              doc="cornering stiffness of the front axle (both tyres)"),
    "rear_cornering": Number("N/rad", None, gt=0,
                             doc="cornering stiffness of the rear axle (both tyres)"),
    "imu_position": Vector(3, Number("m"), None,
                           doc="the truth's reference point (where the IMU sits; the IMU's "
                               "lever_arm counts from it) from the centre of gravity, FRD"),
    "roughness": Text(None, choices=[*ROUGHNESS_CLASSES, "none"],
                      doc="ISO 8608 road class A-E of the random road profile, or none"),
    "camber": Number("", None, min=-0.1, max=0.1,
                     doc="road cross-slope (rise/run), + falling to the right"),
    "engine_frequency": Number("Hz", None, gt=0, doc="engine vibration frequency"),
    "engine_accel": Number("m/s^2", None, min=0, doc="engine vibration of the body, vertical rms"),
    "road_seed": Integer(0, min=0, max=2**63 - 1,
                         doc="seed of the road's roughness and the engine's phase: part of the "
                             "drive, so a campaign's runs over seeds share one road"),
}


def _resolve(value: dict, path: Path, ctx: Context) -> dict:
    """Fill the keys not given from the preset (checked by their field, so a preset is held to
    the same limits as a scenario), then check that the car can be built: the wheels lighter
    than the car, and each tyre stiffer than the ride rate it carries (the spring in series
    with it, ``suspension.FullCar``, would otherwise be negative)."""
    preset = VEHICLE_PRESETS[value["preset"]]
    out = dict(value)
    for key, field in _FIELDS.items():
        if out[key] is None:  # the preset's value, or the field's own default (road_seed)
            out[key] = field.check(preset.get(key, field.default), path + (key,), ctx)
    if any(v is INVALID for v in out.values()):
        return INVALID
    if out["mass"] <= 4 * out["unsprung_mass"]:
        return ctx.error(path + ("unsprung_mass",), f"four wheels of {out['unsprung_mass']:g} "
                                                    f"kg weigh more than the car's mass "
                                                    f"{out['mass']:g} kg")
    ride = corner_ride_rates(out)[1].max()
    if out["tyre_stiffness"] <= ride:
        return ctx.error(path + ("tyre_stiffness",),
                         f"{out['tyre_stiffness']:g} N/m is not stiffer than the ride rate of "
                         f"a corner ({ride:.0f} N/m, from the mass and the ride frequency); "
                         "raise it or lower the frequencies")
    return out


VEHICLE_FIELD = Either(
    Text(choices=[RIGID, *sorted(VEHICLE_PRESETS)]),
    Record(_FIELDS, post=_resolve),
    default=None,
    doc="'rigid' (a point following the road), a car preset, or {preset, overrides}; "
        "default: the automotive preset, rigid for a recorded drive (``default_vehicle``)",
)


def default_vehicle(trajectory_kind: str) -> str:
    """The ``vehicle`` of a scenario that names none: the automotive car, except on a recorded
    drive, whose log already holds the real body's motion (its roll, its side slip), which a
    model would add to a second time."""
    return RIGID if trajectory_kind == "recorded" else DEFAULT_PRESET


def vehicle_parameters(block: str | dict) -> dict | None:
    """The resolved ``vehicle`` block as a full parameter mapping; None for ``rigid``."""
    if block == RIGID:
        return None
    if isinstance(block, str):
        return _resolve({key: None for key in _FIELDS} | {"preset": block}, ("vehicle",),
                        Context("(preset)"))
    return block
