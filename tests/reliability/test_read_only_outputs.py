"""An output folder the process may not write into (EACCES): ``generate``, ``run``, ``score
--report`` and ``campaign`` each end with exit 2 and one message naming the path, no
traceback, nothing written and no temporary left.

The folder is made read-only (mode 0555). Root writes there anyway (its capability
CAP_DAC_OVERRIDE passes over the mode), so when the tests run as root the command runs under
``setpriv`` with that capability and CAP_DAC_READ_SEARCH taken out of its bounding set: it
keeps root's user id (it reads the interpreter and the checkout as before) but the kernel
checks the folder's mode as for any user. Dropping to the user ``nobody`` would not do on a
machine whose interpreter lies under root's home folder (not executable by others)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from simulator.cli import main
from tests.reliability.checks import tree
from tests.reliability.drives import shared_dataset, straight_drive  # noqa: F401 (fixture)

REPO = Path(__file__).resolve().parents[2]
SETPRIV = shutil.which("setpriv")
_NO_DAC = "-dac_override,-dac_read_search"
SLOW = pytest.mark.slow  # each case about 3 s of CPU (a landnav process); two run by default

pytestmark = pytest.mark.skipif(
    os.geteuid() == 0 and SETPRIV is None,
    reason="running as root, which writes into a read-only folder, and without setpriv "
           "(util-linux) to run the command without that capability")


def _landnav_without_write_access(args: list[str], cwd: Path) -> subprocess.CompletedProcess:
    """``landnav ARGS`` in ``cwd``, as a process that the folders' modes bind (see above); its
    temporary folder is ``cwd/tmp``."""
    prefix = ([SETPRIV, f"--bounding-set={_NO_DAC}", f"--inh-caps={_NO_DAC}", "--"]
              if os.geteuid() == 0 else [])
    env = {**os.environ, "PYTHONPATH": str(REPO), "TMPDIR": str(cwd / "tmp")}
    return subprocess.run([*prefix, sys.executable, "-m", "simulator.cli", *args], cwd=cwd,
                          env=env, capture_output=True, text=True, timeout=600)


CASES = {
    "generate": ["generate", "s.yaml", "-o", "locked/out"],
    "run": ["run", "s.yaml", "-o", "locked/out"],
    "score --report": ["score", "DATASET", "--solution", "sol.parquet", "--report",
                       "locked/out"],
    "campaign": ["campaign", "s.yaml", "--runs", "1", "-o", "locked/out"],
}


@pytest.mark.parametrize("case", [pytest.param(c, marks=SLOW) if c in ("run", "campaign")
                                  else c for c in CASES])
def test_a_read_only_output_folder_is_one_message(dataset, tmp_path, case):
    (tmp_path / "s.yaml").write_text(straight_drive(
        100, sensors="  imu: {preset: ideal, rate: 50}\n  odometer: {rate: 10}\n",
        tail="estimators: [dead_reckoning]\n"))
    if case == "score --report":
        assert main(["estimate", str(dataset), "-e", "dead_reckoning", "-o",
                     str(tmp_path / "sol.parquet")]) == 0
    (tmp_path / "tmp").mkdir()
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    args = [str(dataset) if a == "DATASET" else a for a in CASES[case]]
    before = {"cwd": tree(tmp_path), "dataset": tree(dataset)}
    try:
        done = _landnav_without_write_access(args, tmp_path)
    finally:
        locked.chmod(0o755)
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("error: locked/") and "cannot write here: Permission denied" \
        in lines[0], done.stderr
    assert list((tmp_path / "tmp").iterdir()) == []
    assert {"cwd": tree(tmp_path), "dataset": tree(dataset)} == before
