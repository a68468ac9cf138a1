"""The environment the drive happens in: named zones (tunnel, garage, urban canyon) and what each
does to the sky, signals and fields.

The sky geometry of a canyon (line of sight, reflections) is in ``simulator.environment.sky``.
The standard atmosphere is in ``simulator.environment.atmosphere``; the geomagnetic main field
comes from the World Magnetic Model through ``pygeomag`` (``simulator.sensors.mag``).

Public names
------------
ENVIRONMENT_FIELD, ZONE_FIELD, COVERED_ZONE_NAMES.
"""

from __future__ import annotations

from simulator.schema import MapOf, Number, Record, Text

ZONE_FIELD = Record(
    {
        "sky": Text("open", choices=["open", "none", "canyon"],
                    doc="open sky, no sky (tunnel, garage: every satellite blocked), or an "
                        "urban canyon"),
        "building_height": Number("m", 30.0, min=0,
                                  doc="canyon: height of the facades above the antenna"),
        "street_width": Number("m", 20.0, gt=0, doc="canyon: width between the facades"),
        "nlos_attenuation": Number("", 15.0, min=0,
                                   doc="canyon: mean C/N0 loss of one reflection off a facade, "
                                       "dB (Berlin u-blox log: NLOS 15.7 dB below LOS)"),
        "nlos_attenuation_spread": Number("", 8.0, min=0,
                                          doc="canyon: 1-sigma of the reflection loss from one "
                                              "facade (building) to the next, dB"),
        "facade_length": Number("m", 20.0, gt=0,
                                doc="canyon: length of one building's facade along the street "
                                    "(each draws its own reflection loss)"),
    },
    default={},
)

# zones a scenario uses without declaring them: these names have no sky, the others open sky
COVERED_ZONE_NAMES = ("tunnel", "garage", "parking", "underground", "underpass")

ENVIRONMENT_FIELD = Record({"zones": MapOf(ZONE_FIELD, {}, doc="what each named zone does to "
                                                             "the sky")}, default={})
