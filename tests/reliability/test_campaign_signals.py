"""SIGTERM and SIGINT to a campaign whose worker is stuck in an estimator: the campaign ends
promptly with 143 / 130 and a message, its worker processes are stopped, nothing but finished
runs is left (no lock file, no temporary), and a rerun completes with nothing lost or
duplicated."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

REPO = Path(__file__).resolve().parents[2]


def _scenario(tmp_path: Path, stuck_while: Path) -> Path:
    data = {
        "name": "tiny", "seed": 3,
        "start": {"utc": "2024-05-01T03:00:00Z", "lat": 37.5, "lon": 127.0},
        "trajectory": {"kind": "segments", "segments": [
            {"stop": {"duration": 1}}, {"accelerate": {"to_speed": 5.0, "accel": 1.5}},
            {"straight": {"duration": 2}}]},
        "sensors": {"imu": {"preset": "ideal", "rate": 50}},
        "estimators": [{"name": "tests.campaign_estimators:Stuck", "label": "stuck",
                        "config": {"stuck_while": str(stuck_while)}}],
    }
    path = tmp_path / "tiny.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize("sig, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_signal_stops_a_campaign_with_a_stuck_worker(tmp_path, sig, code):
    flag = tmp_path / "stuck"
    flag.write_text("")
    scenario = _scenario(tmp_path, flag)
    argv = [sys.executable, "-m", "simulator.cli", "campaign", str(scenario), "--runs", "2",
            "--workers", "1", "-o", "mc"]
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    proc = subprocess.Popen(argv, cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 600  # a hang guard, generous for a loaded machine
    while not (tmp_path / "mc" / "campaign.json").exists():  # the runs are under way
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline
        time.sleep(0.05)
    time.sleep(1.0)  # the worker is inside the stuck estimator
    proc.send_signal(sig)
    rc = proc.wait(timeout=30)  # a hang, not a speed check: it ends in well under a second
    _, err = proc.communicate()
    assert rc == code, err
    assert "Traceback" not in err and ("terminated" in err or "interrupted" in err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mc", "stuck", "tiny.yaml"]
    assert not list((tmp_path / "mc" / "parts").glob("*.parquet")) if (
        tmp_path / "mc" / "parts").exists() else True
    flag.unlink()
    rerun = subprocess.run(argv, cwd=tmp_path, env=env, capture_output=True, text=True,
                           timeout=300)
    assert rerun.returncode == 0, rerun.stderr
    assert "2 result(s) ok, 0 failed" in rerun.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mc", "tiny.yaml"]
