"""Unit parsing for scenario values: datasheet strings to SI floats, with pint.

A scenario value may be a plain number (SI, or degrees for plain angles) or a string with its unit
as datasheets print it: ``"0.02 deg/s/sqrt(Hz)"``, ``"70 mg"``, ``"10 deg/h"``, ``"1.3 Pa"``,
``"2 %"``. Datasheet habits pint does not know are rewritten first: ``sqrt(X)`` and ``√X`` become
``(X)**0.5``, and where an acceleration is expected ``g``/``mg``/``ug`` mean standard gravity
(9.80665 m/s^2), not grams.

Named parameter sets written in code (sensor presets) use the factors below instead of strings,
so that a scenario naming a preset does not load pint (about a second): ``0.02 * DEG_S_RT_HZ``
reads like the datasheet's "0.02 deg/s/sqrt(Hz)".

Public names
------------
to_si, UnitError; DEG, DEG_S, DEG_H, DEG_RT_H, DEG_S_RT_HZ, DEG_S2_RT_HZ, MILLI_G, MICRO_G,
MILLI_G_RT_HZ, MILLI_G_S_RT_HZ, M_S_RT_H, PERCENT, PPM, PERCENT_RT_H, HPA, MICRO_T, MILLI.
"""

from __future__ import annotations

import functools
import re

from simulator.earth import G0_M_S2

# datasheet units as SI factors (value * factor = SI value)
DEG = 0.017453292519943295  # degree, rad
DEG_S = DEG  # deg/s, rad/s
DEG_H = DEG / 3600.0  # deg/h, rad/s
DEG_RT_H = DEG / 60.0  # deg/sqrt(h) (angle random walk), rad/s/sqrt(Hz)
DEG_S_RT_HZ = DEG  # deg/s/sqrt(Hz), rad/s/sqrt(Hz)
DEG_S2_RT_HZ = DEG  # deg/s^2/sqrt(Hz) (rate random walk), rad/s^2/sqrt(Hz)
MILLI_G = 1e-3 * G0_M_S2  # mg, m/s^2
MICRO_G = 1e-6 * G0_M_S2  # ug, m/s^2
MILLI_G_RT_HZ = MILLI_G  # mg/sqrt(Hz), m/s^2/sqrt(Hz)
MILLI_G_S_RT_HZ = MILLI_G  # mg/s/sqrt(Hz) (acceleration random walk), m/s^3/sqrt(Hz)
M_S_RT_H = 1.0 / 60.0  # m/s/sqrt(h) (velocity random walk), m/s^2/sqrt(Hz)
PERCENT = 1e-2  # %, dimensionless
PPM = 1e-6  # ppm, dimensionless
PERCENT_RT_H = PERCENT / 60.0  # %/sqrt(h), 1/sqrt(s)
HPA = 100.0  # hPa, Pa
MICRO_T = 1e-6  # uT, T
MILLI = 1e-3  # the prefix m (mrad, ms)
KM_H = 1.0 / 3.6  # km/h, m/s


class UnitError(ValueError):
    """A value whose unit cannot be read or has the wrong dimension."""


@functools.cache
def _registry():
    import pint  # imported on first use: a scenario of plain SI numbers never pays for it

    ureg = pint.UnitRegistry(autoconvert_offset_to_baseunit=True)
    ureg.define(f"gee = {G0_M_S2} * meter / second ** 2")
    ureg.define("ppb = 1e-9 = _ = parts_per_billion")
    return ureg


_SQRT = re.compile(r"(?:sqrt|√)\s*\(([^()]*)\)")
_SQRT_BARE = re.compile(r"√\s*([A-Za-z]+)")
_GRAVITY_G = re.compile(r"(?<![A-Za-z_])([mµu]?)g(?![A-Za-z_0-9])")


def _rewrite(text: str, gravity: bool) -> str:
    text = _SQRT.sub(r"(\1)**0.5", text)
    text = _SQRT_BARE.sub(r"(\1)**0.5", text)
    text = text.replace("%", " percent ").replace("°", " deg ")
    if gravity:
        text = _GRAVITY_G.sub(lambda m: f"{m.group(1).replace('µ', 'u')}gee", text)
    return text


@functools.cache
def _dimensionality(unit: str):
    return _registry().parse_expression(_rewrite(unit, False)).dimensionality


def to_si(value: str, si_unit: str) -> float:
    """Convert a string with a unit to a float in ``si_unit``.

    Parameters
    ----------
    value : str
        For example ``"0.02 deg/s/sqrt(Hz)"``.
    si_unit : str
        The unit the result is expressed in, which also fixes the expected dimension, e.g.
        ``"rad/s/sqrt(Hz)"``. Use ``""`` for dimensionless values (``"2 %"`` gives 0.02).

    Raises
    ------
    UnitError
        If the string cannot be parsed or its dimension differs from ``si_unit``'s.
    """
    ureg = _registry()
    target = _dimensionality(si_unit) if si_unit else ureg.dimensionless.dimensionality
    last_error = ""
    for gravity in (False, True):
        try:
            quantity = ureg.parse_expression(_rewrite(value.strip(), gravity))
        except Exception as exc:  # pint raises several unrelated exception types
            last_error = f"cannot read {value!r} as a quantity ({exc})"
            continue
        if not isinstance(quantity, ureg.Quantity):
            quantity = ureg.Quantity(float(quantity))
        if quantity.dimensionality == target:
            return float(quantity.to(_rewrite(si_unit, False) or "dimensionless").magnitude)
        last_error = (
            f"{value!r} has the dimension {quantity.dimensionality}, "
            f"expected a value in {si_unit or 'dimensionless units'} ({target})"
        )
    raise UnitError(last_error)
