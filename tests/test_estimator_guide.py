"""The plug-in guide (docs/estimator_plugins.md) as a newcomer follows it: its command block run
as written on the quickstart scenario, and its abridged listing the code of the example file."""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import pytest

from simulator.cli import main

REPO = Path(__file__).resolve().parents[1]
GUIDE = REPO / "docs" / "estimator_plugins.md"
EXAMPLE = REPO / "examples" / "my_estimator.py"


def _blocks(language: str) -> list[str]:
    return re.findall(rf"^```{language}\n(.*?)^```", GUIDE.read_text(), re.S | re.M)


def test_the_guides_example_runs_as_written_on_the_quickstart(tmp_path, monkeypatch):
    """Every command of the guide's quickstart block, in a fresh folder with the repository's
    scenarios: the example ends within 10 m horizontal RMS (about 3 m; without its gyro-bias
    state, 82 m)."""
    block = next(b for b in _blocks("bash") if "scenarios/quickstart.yaml" in b)
    (tmp_path / "scenarios").symlink_to(REPO / "scenarios")
    monkeypatch.chdir(tmp_path)
    commands = [shlex.split(line) for line in block.replace("\\\n", " ").splitlines()
                if line.strip()]
    assert [c[:2] for c in commands] == [["landnav", "generate"], ["landnav", "estimate"],
                                         ["landnav", "score"]]
    for command in commands:
        assert main(command[1:]) == 0, command
    scores = json.loads(Path(commands[-1][commands[-1].index("--json") + 1]).read_text())
    (mine,) = scores.values()
    assert mine["horizontal"]["rms"] < 10.0
    assert mine["sensor_errors"]["gyro_bias_z"]["rms"] < 0.1 * 0.0175  # a tenth of 1 deg/s


@pytest.mark.parametrize("block", [b for b in _blocks("python") if "class MyEstimator" in b])
def test_the_guides_listing_is_the_example_files_code(block):
    """Each line of the abridged listing (other than the ``...`` that mark the cuts) is a line
    of examples/my_estimator.py, in the same order."""
    lines = [line.rstrip() for line in EXAMPLE.read_text().splitlines()]
    at = 0
    for shown in block.splitlines():
        if shown.strip() in ("", "..."):
            continue
        assert shown.rstrip() in lines[at:], f"not in {EXAMPLE.name} (in order): {shown!r}"
        at = lines.index(shown.rstrip(), at) + 1
