"""The datasheet unit factors that presets are written with, against pint through ``to_si``."""

from __future__ import annotations

import pytest

from simulator import units

CASES = [
    ("DEG", "1 deg", "rad"), ("DEG_S", "1 deg/s", "rad/s"), ("DEG_H", "1 deg/h", "rad/s"),
    ("DEG_RT_H", "1 deg/sqrt(h)", "rad/s/sqrt(Hz)"),
    ("DEG_S_RT_HZ", "1 deg/s/sqrt(Hz)", "rad/s/sqrt(Hz)"),
    ("DEG_S2_RT_HZ", "1 deg/s^2/sqrt(Hz)", "rad/s^2/sqrt(Hz)"),
    ("MILLI_G", "1 mg", "m/s^2"), ("MICRO_G", "1 ug", "m/s^2"),
    ("MILLI_G_RT_HZ", "1 mg/sqrt(Hz)", "m/s^2/sqrt(Hz)"),
    ("MILLI_G_S_RT_HZ", "1 mg/s/sqrt(Hz)", "m/s^3/sqrt(Hz)"),
    ("M_S_RT_H", "1 m/s/sqrt(h)", "m/s^2/sqrt(Hz)"), ("PERCENT", "1 %", ""),
    ("PPM", "1 ppm", ""), ("PERCENT_RT_H", "1 %/sqrt(h)", "1/sqrt(s)"), ("HPA", "1 hPa", "Pa"),
    ("MICRO_T", "1 uT", "T"), ("MILLI", "1 mrad", "rad"),
]


@pytest.mark.parametrize("name, text, si_unit", CASES)
def test_factor_matches_pint(name, text, si_unit):
    assert getattr(units, name) == pytest.approx(units.to_si(text, si_unit), rel=1e-12)
