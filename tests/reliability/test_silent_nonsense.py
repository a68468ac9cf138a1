"""Inputs that used to give quiet nonsense: a drive across the antimeridian, a start before the
GPS epoch, a fault triggered beyond the end of the drive."""

from __future__ import annotations

import numpy as np
import pytest

from simulator.cli import main
from simulator.dataset.io import open_dataset

DRIVE = """\
name: t
start: {{utc: {utc}, lat: 10.0, lon: {lon}, heading: 90}}
trajectory:
  kind: segments
  segments:
    - accelerate: {{to_speed: 20, accel: 2}}
    - straight: {{length: 400}}
sensors:
  imu: {{preset: ideal, rate: 20}}
faults: {faults}
"""


def test_longitude_wraps_at_the_antimeridian(tmp_path):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(DRIVE.format(utc="2020-01-01T00:00:00Z", lon=179.998, faults="[]"))
    assert main(["generate", str(scenario), "-o", str(tmp_path / "ds")]) == 0
    lon = open_dataset(tmp_path / "ds").read("truth")["lon"].to_numpy()
    assert lon.min() >= -180.0 and lon.max() < 180.0
    assert lon[0] > 179.99 and lon[-1] < -179.99  # crossed eastwards, about 450 m
    step = np.diff(np.unwrap(np.radians(lon)))
    assert np.all(step >= 0)


@pytest.mark.parametrize("utc, words", [
    ("1900-01-01T00:00:00Z", "before 1980-01-06T00:00:00Z (the GPS epoch"),
    ("1979-12-31T23:59:59Z", "before 1980-01-06T00:00:00Z (the GPS epoch"),
])
def test_start_before_the_gps_epoch(tmp_path, capsys, utc, words):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(DRIVE.format(utc=utc, lon=10.0, faults="[]"))
    assert main(["validate", str(scenario)]) == 2
    assert words in capsys.readouterr().err


def test_fault_distance_beyond_the_drive(tmp_path, capsys):
    faults = "[{kind: sensor_dropout, stream: imu, distance: [5000, 5100]}]"
    scenario = tmp_path / "s.yaml"
    scenario.write_text(DRIVE.format(utc="2020-01-01T00:00:00Z", lon=10.0, faults=faults))
    assert main(["validate", str(scenario)]) == 2
    err = capsys.readouterr().err
    assert "faults.0.distance: starts at 5000 m, beyond the drive's end" in err
