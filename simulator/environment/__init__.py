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
                                  doc="canyon: mean height of the buildings above the antenna "
                                      "(each drawn with building_height_spread); the end "
                                      "facades' height"),
        "street_width": Number("m", 20.0, gt=0, doc="canyon: width between the facades"),
        "nlos_attenuation": Number("", 15.0, min=0,
                                   doc="canyon: mean C/N0 loss of one reflection off a facade, "
                                       "dB (Berlin u-blox log: NLOS 15.7 dB below LOS)"),
        "nlos_attenuation_spread": Number("", 8.0, min=0,
                                          doc="canyon: 1-sigma of the reflection loss from one "
                                              "facade (building) to the next, dB"),
        "scattering_coefficient": Number("", 0.4, min=0, max=1,
                                         doc="canyon: S of the facades' diffuse scattering (the "
                                             "Lambertian effective-roughness model, Degli-Esposti "
                                             "et al. 2007: about 0.4 for building walls); 0: "
                                             "specular reflections and diffraction only"),
        "facade_length": Number("m", 20.0, gt=0,
                                doc="canyon: frontage of one building along the street (each has "
                                    "its own height and draws its own reflection loss; Berlin's "
                                    "perimeter-block plots are about 20 m wide)"),
        "building_height_spread": Number("m", 3.0, min=0,
                                         doc="canyon: 1-sigma of the buildings' heights about "
                                             "building_height, drawn per building (about one "
                                             "storey)"),
        "block_length": Number("m", 110.0, gt=0,
                               doc="canyon: length of a block between cross streets (European "
                                   "city centres 50-150 m; Barcelona's Eixample 113 m)"),
        "cross_street_width": Number("m", 20.0, min=0,
                                     doc="canyon: width of the cross streets between blocks, where "
                                         "the facades open on both sides (0: none)"),
        "building_gap": Number("m", 0.0, min=0,
                               doc="canyon: gap between neighbouring buildings of a block (0: the "
                                   "closed perimeter block)"),
    },
    default={},
)

# zones a scenario uses without declaring them: these names have no sky, the others open sky
COVERED_ZONE_NAMES = ("tunnel", "garage", "parking", "underground", "underpass")

ENVIRONMENT_FIELD = Record({"zones": MapOf(ZONE_FIELD, {}, doc="what each named zone does to "
                                                             "the sky")}, default={})
