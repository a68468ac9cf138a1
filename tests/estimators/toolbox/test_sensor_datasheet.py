"""The datasheet's IMU figures as a filter takes them: the white-noise floor is the tactical
grade's densities as the simulator's ``tactical`` preset states them (an independent source),
so it acts on ideal and navigation-grade sheets and on no MEMS sheet."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.toolbox.sensor_datasheet import ACCEL_NOISE_FLOOR, GYRO_NOISE_FLOOR
from simulator.sensors.imu_presets import IMU_PRESETS


def test_the_noise_floor_is_the_tactical_grade():
    tactical = IMU_PRESETS["tactical"]
    assert GYRO_NOISE_FLOOR == pytest.approx(tactical["gyro"]["noise_density"], rel=1e-12)
    assert ACCEL_NOISE_FLOOR == pytest.approx(tactical["accel"]["noise_density"], rel=1e-12)


@pytest.mark.parametrize("name", ["consumer", "automotive", "bosch-smi130", "bosch-bmi160"])
def test_no_mems_sheet_is_under_the_floor(name):
    sheet = IMU_PRESETS[name]
    assert np.min(sheet["gyro"]["noise_density"]) > GYRO_NOISE_FLOOR
    assert np.min(sheet["accel"]["noise_density"]) > ACCEL_NOISE_FLOOR
