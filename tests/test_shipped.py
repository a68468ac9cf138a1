"""Every shipped scenario validates and generates; the code base stays ruff-clean."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from simulator.cli import main
from simulator.dataset.io import open_dataset

REPO = Path(__file__).resolve().parents[1]
SCENARIOS = sorted((REPO / "scenarios").glob("*.yaml"))


@pytest.mark.parametrize("path", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_shipped_scenario_generates(path, tmp_path):
    assert main(["validate", str(path)]) == 0
    out = tmp_path / "ds"
    assert main(["generate", str(path), "-o", str(out)]) == 0
    ds = open_dataset(out)
    truth = ds.read("truth")
    assert truth.t.iloc[-1] == pytest.approx(ds.manifest["duration"], abs=0.02)


def test_ruff_clean():
    ruff = shutil.which("ruff")
    if ruff is None:
        pytest.skip("ruff is not installed (pip install -e '.[test]')")
    result = subprocess.run([ruff, "check", str(REPO)], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout


def test_help_teaches(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert "landnav generate" in out and "validate" in out
    result = subprocess.run([sys.executable, "-m", "simulator.cli", "generate", "--help"],
                            capture_output=True, text=True, cwd=REPO)
    assert "--force" in result.stdout and "--set" in result.stdout
