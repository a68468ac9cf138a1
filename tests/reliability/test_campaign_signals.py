"""SIGTERM and SIGINT to a campaign whose worker is stuck in an estimator: the campaign ends
promptly with 143 / 130 and a message, its worker processes are stopped, nothing but finished
runs is left (no lock file, no temporary), and a rerun completes with nothing lost or
duplicated. SIGKILL of the campaign ends its workers too; a stuck run fails at --time-limit;
a port that does not answer as a Dask scheduler is refused at --scheduler-timeout."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pandas as pd
import pytest
import yaml

from simulator.cli import main
from tests.reliability.checks import alive
from tests.reliability.drives import straight_drive

REPO = Path(__file__).resolve().parents[2]
PLUGINS = "tests.reliability.hostile_plugins"


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
    _wait_inside(proc, flag)
    proc.send_signal(sig)
    rc = proc.wait(timeout=300)  # a hang guard: it ends in well under a second when idle
    _, err = proc.communicate()
    assert rc == code, err
    assert "Traceback" not in err and ("terminated" in err or "interrupted" in err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mc", "stuck", "stuck.inside",
                                                          "tiny.yaml"]
    assert not list((tmp_path / "mc" / "parts").glob("*.parquet")) if (
        tmp_path / "mc" / "parts").exists() else True
    flag.unlink()
    (tmp_path / "stuck.inside").unlink()
    rerun = subprocess.run(argv, cwd=tmp_path, env=env, capture_output=True, text=True,
                           timeout=1200)  # a hang guard for a loaded machine
    assert rerun.returncode == 0, rerun.stderr
    assert "2 result(s) ok, 0 failed" in rerun.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mc", "tiny.yaml"]


def _wait_inside(proc: subprocess.Popen, flag: Path) -> None:
    """Until a worker of the campaign ``proc`` is inside the stuck estimator (it made
    ``FLAG.inside``); a hang guard of 20 minutes for a loaded machine."""
    deadline = time.monotonic() + 1200
    while not flag.with_name(f"{flag.name}.inside").exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline
        time.sleep(0.05)


def _descendants(pid: int) -> set[int]:
    """Every process below ``pid`` (from /proc: parent ids)."""
    parents = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            parents[int(entry.name)] = int(stat.rsplit(")", 1)[1].split()[1])
    found, frontier = set(), {pid}
    while frontier:
        frontier = {p for p, parent in parents.items() if parent in frontier} - found
        found |= frontier
    return found


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux's /proc")
def test_workers_end_with_a_killed_campaign(tmp_path):
    flag = tmp_path / "stuck"
    flag.write_text("")
    argv = [sys.executable, "-m", "simulator.cli", "campaign", str(_scenario(tmp_path, flag)),
            "--runs", "2", "--workers", "1", "-o", "mc"]
    proc = subprocess.Popen(argv, cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(REPO)},
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _wait_inside(proc, flag)
    workers = _descendants(proc.pid)
    assert workers
    proc.kill()  # SIGKILL: the campaign cannot stop its workers itself
    proc.wait()
    deadline = time.monotonic() + 300  # a hang guard: they end within a second when idle
    while any(alive(p) for p in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(alive(p) for p in workers)


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux's /proc")
def test_what_a_plugin_forks_in_a_worker_ends_with_the_campaign(tmp_path, capsys):
    """A plug-in that starts a process and forks itself in every run, each meant to sleep 600
    s: when the campaign has ended, none of them is left (each worker ends with its process
    group)."""
    pids = tmp_path / "pids.txt"
    scenario = tmp_path / "s.yaml"
    scenario.write_text(straight_drive(
        20, sensors="  imu: {preset: ideal, rate: 25}\n",
        tail=f"estimators: [{{name: '{PLUGINS}:LeavesSleepers', config: {{pids: '{pids}'}}}}]\n"))
    assert main(["campaign", str(scenario), "--runs", "2", "--workers", "2", "-o",
                 str(tmp_path / "mc")]) == 0, capsys.readouterr().err
    assert "2 result(s) ok, 0 failed" in capsys.readouterr().out
    started = [int(p) for p in pids.read_text().split()]
    assert len(started) == 4  # two in each run
    deadline = time.monotonic() + 60  # a hang guard: they are killed as the campaign ends
    while any(alive(p) for p in started) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(alive(p) for p in started)


def test_the_time_limit_names_itself_when_the_timer_surfaces_as_another_exception():
    """A plug-in interrupted while an extension module initialises raises ImportError, not the
    timer's exception: it is still the time limit (a loaded machine hits it while importing)."""
    from simulator.campaign.worker import TimeLimitExceeded, time_limit

    with pytest.raises(TimeLimitExceeded, match="did not finish within the time limit of 0.05 s"):
        with time_limit(0.05, "slow"):
            try:
                time.sleep(5.0)
            except TimeLimitExceeded:
                raise ImportError("initialization failed") from None
    with pytest.raises(ValueError, match="its own"), time_limit(5.0, "quick"):
        raise ValueError("its own failure, before the limit")


def test_campaign_time_limit_fails_the_stuck_run_and_goes_on(tmp_path):
    """The limit also bounds importing and checking the estimator before the runs: 10 s, as
    importing this test module takes about 3 s of CPU (pytest, matplotlib)."""
    flag = tmp_path / "stuck"
    flag.write_text("")
    argv = [sys.executable, "-m", "simulator.cli", "campaign", str(_scenario(tmp_path, flag)),
            "--runs", "1", "--workers", "1", "-o", "mc", "--time-limit", "10"]
    done = subprocess.run(argv, cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(REPO)},
                          capture_output=True, text=True, timeout=1200)
    assert done.returncode == 0, done.stderr
    assert "0 result(s) ok, 1 failed" in done.stdout
    runs = pd.read_parquet(tmp_path / "mc" / "runs.parquet")
    assert "did not finish within the time limit of 10 s" in runs["error"].iloc[0]


def test_a_port_that_is_not_a_dask_scheduler(tmp_path):
    """A server that accepts connections and says nothing: refused after --scheduler-timeout
    (before, the Dask client waited on without end)."""
    server = socket.create_server(("127.0.0.1", 0))
    held = []
    accept = threading.Thread(target=lambda: held.append(server.accept()), daemon=True)
    accept.start()
    scenario = _scenario(tmp_path, tmp_path / "never")
    argv = [sys.executable, "-m", "simulator.cli", "campaign", str(scenario), "--runs", "1",
            "-o", "mc", "--scheduler", f"tcp://127.0.0.1:{server.getsockname()[1]}",
            "--scheduler-timeout", "2"]
    try:
        done = subprocess.run(argv, cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(REPO)},
                              capture_output=True, text=True, timeout=600)
    finally:
        server.close()
    assert done.returncode == 2, done.stderr
    assert "no Dask scheduler answers within 2 s" in done.stderr
    assert "Traceback" not in done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tiny.yaml"]
