"""The drive (``simulator.drive``) is built once: validation builds the road profile, and
generation and the whole ``landnav run`` reuse it."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from simulator import trajectory
from simulator.cli import main
from simulator.scenario import load_scenario

QUICKSTART = Path(__file__).resolve().parents[1] / "scenarios" / "quickstart.yaml"


@pytest.fixture
def builds(monkeypatch) -> list[str]:
    """Every road-profile build, by trajectory kind."""
    made: list[str] = []
    for kind, builder in trajectory.PROFILE_BUILDERS.items():
        def counted(scenario, ctx, kind=kind, builder=builder):
            made.append(kind)
            return builder(scenario, ctx)
        monkeypatch.setitem(trajectory.PROFILE_BUILDERS, kind, counted)
    return made


@pytest.fixture
def scenario_file(tmp_path) -> Path:
    data = yaml.safe_load(QUICKSTART.read_text())
    data["trajectory"]["segments"] = data["trajectory"]["segments"][:5]
    data["estimators"] = ["dead_reckoning"]
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize("command", ["generate", "run"])
def test_one_profile_build_per_command(builds, scenario_file, tmp_path, command):
    assert main([command, str(scenario_file), "-o", str(tmp_path / "out")]) == 0
    assert builds == ["segments"]


def test_the_drive_is_the_validated_one(builds, scenario_file):
    scenario = load_scenario(scenario_file)
    drive = scenario.drive
    assert builds == ["segments"]
    truth = drive.truth
    assert truth is drive.truth  # built once
    assert truth.duration_s == drive.duration_s == drive.profile.duration_s
    assert truth.utc_start.isoformat() == "2024-05-01T03:00:00"
    # GPS week 2312 began on Sunday 2024-04-28; GPS time is UTC + 18 s since 2017
    assert (truth.gps_week, round(truth.gps_tow)) == (2312, 3 * 86400 + 3 * 3600 + 18)
    assert truth.environment is scenario.data["environment"]
    with pytest.raises(AttributeError):
        drive.profile = None  # frozen
