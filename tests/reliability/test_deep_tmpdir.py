"""A local campaign in a deep temporary folder: the forkserver's Unix socket would lie in
TMPDIR, whose path a socket's may not exceed (107 bytes on Linux), so the workers are
spawned instead, and the campaign works (before, it stopped with "AF_UNIX path too long")."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from tests.reliability.drives import straight_drive

REPO = Path(__file__).resolve().parents[2]
SCENARIO = straight_drive(60, sensors="  imu: {preset: ideal, rate: 50}\n  odometer: {rate: 10}\n",
                          tail="estimators: [dead_reckoning]\n")


def test_a_campaign_in_a_deep_temporary_folder(tmp_path):
    deep = tmp_path / ("t" * 60) / ("m" * 60)
    deep.mkdir(parents=True)
    assert len(str(deep)) + len("/pymp-12345678/listener-12345678") > 107
    (tmp_path / "s.yaml").write_text(SCENARIO)
    env = {**os.environ, "PYTHONPATH": str(REPO), "TMPDIR": str(deep)}
    done = subprocess.run([sys.executable, "-m", "simulator.cli", "campaign", "s.yaml", "--runs",
                           "2", "--workers", "2", "-o", "mc"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "2 result(s) ok, 0 failed" in done.stdout, done.stdout
    assert list(deep.iterdir()) == []  # the workers' temporaries removed
