"""Outputs that would destroy an input or a user's files: through a symbolic link into the
dataset, a folder that contains the input, ``--force`` on folders and files landnav did not
write, a running campaign's folder, links planted where landnav puts its lock and temporaries.
Each is refused (exit 2, one message, the inputs byte for byte as they were) or, for the
planted links, written without following them; a scenario's own code is never run by
``validate``."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from simulator.campaign.store import campaign_lock
from simulator.cli import main
from simulator.errors import InputError
from simulator.outputs import real_subfolder
from tests.reliability.checks import refused, tree
from tests.reliability.drives import (
    shared_dataset,  # noqa: F401 (fixtures)
    straight_drive,
)

SCENARIO = straight_drive(60, sensors="  imu: {preset: ideal, rate: 20}\n"
                                      "  gnss: {rate: 1, outputs: [fix]}\n")


@pytest.fixture
def link(dataset, tmp_path) -> Path:
    """``tmp_path/LINK`` -> the dataset."""
    path = tmp_path / "LINK"
    path.symlink_to(dataset, target_is_directory=True)
    return path


@pytest.mark.parametrize("command", [
    ["estimate", "{ds}", "-e", "gnss_only", "-o", "{link}/imu.parquet", "--force"],
    ["estimate", "{ds}", "-e", "gnss_only", "-o", "{link}/new.parquet"],
    ["score", "{ds}", "-e", "gnss_only", "--json", "{link}/manifest.json", "--force"],
    ["export", "{ds}", "--nmea", "{link}/manifest.json", "--force"],
    ["score", "{ds}", "-e", "gnss_only", "--report", "{link}/report", "--force"],
])
def test_output_through_a_link_into_the_dataset(dataset, link, capsys, command):
    args = [a.format(ds=dataset, link=link) for a in command]
    refused(args, capsys, [dataset.parent], "is inside the input")


def test_report_folder_that_contains_the_dataset(dataset, tmp_path, capsys):
    parent = tmp_path / "P"
    shutil.copytree(dataset, parent / "ds")
    refused(["score", str(parent / "ds"), "-e", "gnss_only", "--report", str(parent),
             "--force"], capsys, [parent], "contains the input")


def test_generate_into_the_folder_of_its_scenario(tmp_path, capsys):
    (tmp_path / "s.yaml").write_text(SCENARIO)
    refused(["generate", str(tmp_path / "s.yaml"), "-o", str(tmp_path), "--force"], capsys,
            [tmp_path], "contains the input")


def test_force_never_replaces_an_ordinary_folder(tmp_path, capsys):
    home = tmp_path / "home"
    home.mkdir()
    (home / "thesis.tex").write_text("years of work")
    (tmp_path / "s.yaml").write_text(SCENARIO)
    for command in ("run", "generate"):
        refused([command, str(tmp_path / "s.yaml"), "-o", str(home), "--force"], capsys,
                [tmp_path], "is not a landnav folder")


@pytest.mark.parametrize("option, name, kind", [
    ("-o", "mine.parquet", "parquet"), ("--json", "mine.json", "json"),
    ("--nmea", "mine.nmea", "nmea")])
def test_force_never_replaces_a_users_file(dataset, tmp_path, capsys, option, name, kind):
    mine = tmp_path / name
    mine.write_text('{"my": "settings"}\n')
    args = {"-o": ["estimate", str(dataset), "-e", "gnss_only", "-o", str(mine)],
            "--json": ["score", str(dataset), "-e", "gnss_only", "--json", str(mine)],
            "--nmea": ["export", str(dataset), "--nmea", str(mine)]}[option]
    refused([*args, "--force"], capsys, [tmp_path], f"is not a landnav {kind} file")


def test_force_replaces_landnav_own_outputs(dataset, tmp_path):
    solution, nmea = tmp_path / "sol.parquet", tmp_path / "out.nmea"
    for force in ([], ["--force"]):
        assert main(["estimate", str(dataset), "-e", "gnss_only", "-o", str(solution),
                     *force]) == 0
        assert main(["export", str(dataset), "--nmea", str(nmea), *force]) == 0
        assert main(["generate", str(dataset.parent / "s.yaml"), "-o", str(tmp_path / "ds"),
                     *force]) == 0


def test_writers_honour_a_running_campaign(tmp_path, capsys):
    (tmp_path / "s.yaml").write_text(SCENARIO)
    campaign = tmp_path / "mc"
    campaign.mkdir()
    (campaign / "campaign.json").write_text(json.dumps({"format": "landnav-campaign/1"}))
    with campaign_lock(campaign):
        for args in (["generate", str(tmp_path / "s.yaml"), "-o", str(campaign), "--force"],
                     ["run", str(tmp_path / "s.yaml"), "-o", str(campaign / "r"), "--force"]):
            refused(args, capsys, [tmp_path], "of a running landnav campaign")


def test_a_link_planted_at_the_lock_is_never_followed(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    (tmp_path / ".mc.lock").symlink_to(victim)
    with pytest.raises(InputError, match="is a symbolic link"), campaign_lock(tmp_path / "mc"):
        pass
    assert victim.read_text() == "precious"


def test_links_planted_at_the_old_temporary_names_are_not_followed(dataset, tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    out = tmp_path / "out"
    out.mkdir()
    for pid in range(os.getpid() - 2, os.getpid() + 3):  # the former names, .NAME.tmp-PID
        (out / f".sol.parquet.tmp-{pid}").symlink_to(victim)
    assert main(["estimate", str(dataset), "-e", "gnss_only", "-o", str(out / "sol.parquet")]
                ) == 0
    assert victim.read_text() == "precious"
    assert sorted(p.name for p in out.iterdir() if not p.is_symlink()) == ["sol.parquet"]


def test_plots_never_written_through_a_linked_folder(tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "keep.png").write_text("x")
    (tmp_path / "plots").symlink_to(elsewhere, target_is_directory=True)
    before = tree(elsewhere)
    plots = real_subfolder(tmp_path / "plots")
    assert plots.is_dir() and not plots.is_symlink()
    assert tree(elsewhere) == before


HELPER = """\
from pathlib import Path
Path("imported.txt").write_text("code ran")
from estimators.builtin.baselines import GnssOnly as Thing
"""


def test_validate_runs_no_code_the_scenario_names(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "helpers.py").write_text(HELPER)
    (tmp_path / "s.yaml").write_text(SCENARIO + "estimators: [helpers:Thing]\n")
    assert main(["validate", "s.yaml"]) == 0
    assert not (tmp_path / "imported.txt").exists()
    assert main(["validate", "s.yaml", "--import-plugins"]) == 0
    assert (tmp_path / "imported.txt").exists()
    capsys.readouterr()
