"""Plug-in estimators that misbehave: each is reported as one message naming the estimator's
class, the call and the reason, exit 2, no traceback and no solution file."""

from __future__ import annotations

from pathlib import Path

import pytest

from simulator.cli import main
from tests.reliability.drives import generated_dataset, straight_drive

SCENARIO = straight_drive(60, sensors="  imu: {preset: ideal, rate: 50}\n")

CASES = {
    "RaiseInSetup": "failed in setup(): RuntimeError: deliberate setup failure",
    "RaiseInHandler": "failed in on_imu() at t = 1.0",
    "WriteToRow": "failed in on_imu() at t = 0.000000 s: ValueError: assignment destination is "
                  "read-only",
    "ReturnDict": "returned a dict; it must return None or 9 numbers",
    "ReturnShort": "returned 2 values; it must return None or 9 numbers",
    "ReturnStrings": "returned a list; it must return None or 9 numbers",
    "DuplicateColumns": "output_columns names yaw twice",
    "NoneDefaults": "defaults must be a mapping",
    "CallsExit": "called sys.exit(0); an estimator must return, not exit",
    "AllNan": "gave no solution row with a position",
    "OneMegahertz": "output_rate_hz must be a number in (0, 1000] Hz",
    "LeavesTheProcess": "ended its process (exit code 0)",
    "NeverReturns": "did not finish within the time limit of 3 s",
}


@pytest.fixture(scope="module")
def dataset(tmp_path_factory) -> Path:
    return generated_dataset(tmp_path_factory.mktemp("plugins"), SCENARIO)


@pytest.mark.parametrize("cls", list(CASES))
def test_misbehaving_plugin(dataset, tmp_path, capsys, cls):
    out = tmp_path / "sol.parquet"
    code = main(["estimate", str(dataset), "-e", f"hostile_plugins:{cls}", "-o", str(out),
                 "--time-limit", "3"])
    printed = capsys.readouterr()
    text = printed.err + printed.out
    assert code == 2, text
    assert "Traceback" not in text
    assert CASES[cls] in text, text
    assert "hostile_plugins" in text
    assert len([line for line in text.splitlines() if line.startswith("error:")]) == 1
    assert not out.exists() and list(tmp_path.iterdir()) == []
