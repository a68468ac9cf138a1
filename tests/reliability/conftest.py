"""The small dataset the hostile cases share (IMU, GNSS fix and raw; 100 m), and a fresh copy
of it for a case that corrupts it."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import pytest

from tests.reliability.drives import generated_dataset, straight_drive

SHARED = straight_drive(100, sensors="  imu: {preset: ideal, rate: 50}\n  odometer: {rate: 10}\n"
                                     "  gnss: {rate: 1, outputs: [fix, raw]}\n")


@pytest.fixture(scope="session")
def dataset(tmp_path_factory) -> Path:
    return generated_dataset(tmp_path_factory.mktemp("shared"), SHARED)


@pytest.fixture
def copy_dataset(dataset, tmp_path) -> Callable[[], Path]:
    def copy() -> Path:
        target = tmp_path / "copy" / "ds"
        shutil.copytree(dataset, target)
        return target
    return copy
