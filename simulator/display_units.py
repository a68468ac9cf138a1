"""Sensor parameters as a navigation engineer reads them: an SI value shown in the datasheet unit
of its kind (deg/h, deg/sqrt(h), mg, ug/sqrt(Hz), ppm, %). SI stays in every file; this is only
for what a person reads (``landnav presets``, the report, ``landnav estimators NAME``).

``DISPLAY_UNITS`` is the one table: for each SI unit, the units it is shown in, largest first.
A value is shown in the first of them where its magnitude reaches ``SMALLEST_SHOWN`` (0.1), so a
consumer gyro's 0.0175 rad/s bias reads 1 deg/s and a tactical one's 4.8e-6 rad/s reads 1 deg/h;
a value of an SI unit the table does not hold is shown in SI. The conversion factors come from
``simulator.units.to_si`` (pint, with the datasheet habits it reads: ``sqrt(h)``, ``mg`` as
milli-standard-gravity).

Public names
------------
DISPLAY_UNITS, SMALLEST_SHOWN, display, display_value.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

from simulator.units import to_si

DISPLAY_UNITS: dict[str, tuple[str, ...]] = {
    "rad/s": ("deg/s", "deg/h"),  # gyro bias, instability, range, resolution
    "rad/s/sqrt(Hz)": ("deg/sqrt(h)",),  # gyro white noise: angle random walk
    "rad/s^2/sqrt(Hz)": ("deg/h/sqrt(h)",),  # gyro bias random walk
    "rad/s/s": ("deg/h/s",),  # gyro rate ramp
    "rad/s/K": ("deg/h/K",),  # gyro bias temperature coefficient
    "rad/s/(m/s^2)": ("deg/h/g",),  # gyro g-sensitivity
    "m/s^2": ("g", "mg", "ug"),  # accelerometer bias, instability, range, resolution
    "m/s^2/sqrt(Hz)": ("ug/sqrt(Hz)",),  # accelerometer white noise: velocity random walk
    "m/s^3/sqrt(Hz)": ("ug/sqrt(s)",),  # accelerometer bias random walk
    "m/s^2/s": ("ug/s",),  # accelerometer ramp
    "m/s^2/K": ("mg/K",),  # accelerometer bias temperature coefficient
    "rad": ("deg", "mrad"),  # misalignment, heading
    "1": ("%", "ppm"),  # a ratio: scale-factor errors, soft iron
    "1/K": ("ppm/K",),  # scale-factor temperature coefficient
    "1/sqrt(s)": ("%/sqrt(h)", "ppm/sqrt(h)"),  # odometer scale-factor drift
    "Pa": ("hPa", "Pa"),  # barometer bias, noise, range
    "Pa/s": ("Pa/h",),  # barometer drift
    "T": ("uT", "nT"),  # magnetometer hard iron, noise
}
SMALLEST_SHOWN = 0.1  # a value takes the first display unit in which it reaches this magnitude


@functools.cache
def _factor(unit: str, si_unit: str) -> float:
    """SI value of one ``unit``."""
    return to_si(f"1 {unit}", si_unit)


def display_value(value_si: float, si_unit: str) -> tuple[float, str]:
    """``value_si`` (in ``si_unit``) in its display unit: (value, unit)."""
    factor, unit = _unit_for(abs(value_si), si_unit)
    return value_si / factor, unit


def _unit_for(magnitude_si: float, si_unit: str) -> tuple[float, str]:
    """(SI value of one display unit, display unit) for a value of this magnitude."""
    units = DISPLAY_UNITS.get(si_unit)
    if not units or not math.isfinite(magnitude_si):
        return 1.0, si_unit
    for unit in units:
        if magnitude_si / _factor(unit, si_unit) >= SMALLEST_SHOWN or magnitude_si == 0:
            break
    return _factor(unit, si_unit), unit


def display(value_si: float | Sequence[float], si_unit: str, digits: int = 3) -> str:
    """``value_si`` (a number, or a list of them, e.g. per axis, all shown in the unit of the
    largest) as text in its display unit with ``digits`` significant digits:
    ``display(4.848e-05, "rad/s")`` -> ``"10 deg/h"``, ``display([0.0, 3.39e-07], "rad/s/s")``
    -> ``"[0, 0.07] deg/h/s"``."""
    values = [float(v) for v in value_si] if isinstance(value_si, Sequence) else [
        float(value_si)]
    factor, unit = _unit_for(max(abs(v) for v in values) if values else 0.0, si_unit)
    text = ", ".join(_number(v / factor, digits) for v in values)
    return (f"[{text}] {unit}" if isinstance(value_si, Sequence) else f"{text} {unit}").rstrip()


def _number(x: float, digits: int) -> str:
    """``digits`` significant digits, without an exponent from 1e-3 to 1e6 (1100, not 1.1e+03)."""
    if 10 ** (digits - 1) <= abs(x) < 1e6:
        return f"{x:.0f}"
    return f"{x:.{digits}g}"
