"""Engineering units for people: every display unit of the table converts as the datasheet
constants of ``simulator.units`` say (written by hand, independent of pint), a value takes the
unit an engineer reads it in, and ``landnav presets`` prints datasheet units."""

from __future__ import annotations

import pytest

from simulator import units as u
from simulator.display_units import DISPLAY_UNITS, display, display_value

# (SI value, SI unit, expected text): each from the hand-written datasheet constants
CASES = [
    (1.0 * u.DEG_S, "rad/s", "1 deg/s"),  # a consumer gyro's turn-on bias
    (10.0 * u.DEG_H, "rad/s", "10 deg/h"),  # an automotive gyro's bias instability
    (0.02 * u.DEG_S_RT_HZ, "rad/s/sqrt(Hz)", "1.2 deg/sqrt(h)"),  # 0.02 deg/s/sqrt(Hz) = 1.2
    (0.1 * u.DEG_RT_H, "rad/s/sqrt(Hz)", "0.1 deg/sqrt(h)"),
    (70.0 * u.MILLI_G, "m/s^2", "70 mg"),
    (50.0 * u.MICRO_G, "m/s^2", "50 ug"),
    (2.0 * 9.80665, "m/s^2", "2 g"),
    (0.19 * u.MILLI_G_RT_HZ, "m/s^2/sqrt(Hz)", "190 ug/sqrt(Hz)"),
    (0.5 * u.PERCENT, "1", "0.5 %"),
    (150.0 * u.PPM, "1", "150 ppm"),
    (1.0 * u.MILLI, "rad", "1 mrad"),
    (4.0 * u.HPA, "Pa", "4 hPa"),
    (5.0 * u.MICRO_T, "T", "5 uT"),
    (3.0, "m", "3 m"),  # not in the table: SI
]


@pytest.mark.parametrize("value, si_unit, text", CASES)
def test_values_read_in_datasheet_units(value, si_unit, text):
    assert display(value, si_unit) == text


def test_every_display_unit_converts_to_its_si_unit():
    """Each display unit parses and has its SI unit's dimension (``to_si`` refuses otherwise)."""
    from simulator.units import to_si

    for si_unit, shown in DISPLAY_UNITS.items():
        for unit in shown:
            assert to_si(f"1 {unit}", si_unit) > 0, (si_unit, unit)
        assert display_value(1e9, si_unit)[1] == shown[0]


def test_a_list_shares_the_unit_of_its_largest():
    assert display([0.0, 0.0, 2.0 * u.DEG_H], "rad/s") == "[0, 0, 2] deg/h"


def test_presets_print_datasheet_units(capsys):
    from simulator.cli import main

    assert main(["presets"]) == 0
    lines = capsys.readouterr().out.splitlines()
    smi130 = next(line for line in lines if line.split()[:2] == ["imu", "bosch-smi130"])
    # Bosch SMI130 datasheet: 1 deg/s offset, 0.02 deg/s/sqrt(Hz) noise, 70 mg accel offset
    for text in ("bias: 1 deg/s", "noise_density: 1.2 deg/sqrt(h)", "bias: 70 mg",
                 "scale_factor: 0.5 %"):
        assert text in smi130, smi130
    assert "0.0174533" not in smi130
