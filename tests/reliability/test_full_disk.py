"""A file system that fills up while a command writes: exit 2, one message, nothing of the output
left (no ``.NAME.tmp``, no half-written file), the inputs unchanged, the temporary folder empty.

The full disk is stood in for by the file-size limit (``RLIMIT_FSIZE``, set with
``resource.setrlimit`` in the command's own process, ``SIGXFSZ`` ignored): a write that would
pass it fails with ``OSError`` (``EFBIG``) at the write call, as one on a full disk fails with
``ENOSPC``, through the same code; it needs no mount, so it also runs where
``test_small_filesystem`` (a real tmpfs in a private mount namespace) is skipped, and it reaches
a Dask worker's process. A writer patched to fail would not exercise the real writers
(pyarrow, matplotlib, the isolated estimator's answer)."""

from __future__ import annotations

import os
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from simulator.cli import main
from tests.reliability.checks import one_message, tree
from tests.reliability.drives import shared_dataset, straight_drive  # noqa: F401 (fixture)

REPO = Path(__file__).resolve().parents[2]


def _landnav_on_a_full_disk(args: list[str], cwd: Path, max_file_bytes: int
                            ) -> subprocess.CompletedProcess:
    """``landnav ARGS`` in a process whose files cannot grow past ``max_file_bytes``; its
    temporary folder is ``cwd/tmp``."""
    def cap() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (max_file_bytes, max_file_bytes))

    (cwd / "tmp").mkdir()
    env = {**os.environ, "PYTHONPATH": str(REPO), "TMPDIR": str(cwd / "tmp")}
    return subprocess.run([sys.executable, "-m", "simulator.cli", *args], cwd=cwd, env=env,
                          preexec_fn=cap, capture_output=True, text=True, timeout=600)


SLOW = pytest.mark.slow  # each case about 4 s of CPU (a landnav process); two run by default
CASES = {
    "generate": (lambda ds: ["generate", "s.yaml", "-o", "out"], 20_000),
    "run": (lambda ds: ["run", "s.yaml", "-o", "out"], 20_000),
    "estimate": (lambda ds: ["estimate", str(ds), "-e", "dead_reckoning", "-o", "out.parquet"],
                 2_000),
    "estimate a plug-in": (lambda ds: ["estimate", str(ds), "-e",
                                       "tests.reliability.hostile_plugins:Holds", "-o",
                                       "out.parquet"], 2_000),
    "report": (lambda ds: ["score", str(ds), "--solution", "sol.parquet", "--report", "out",
                           "--json", "out.json"], 20_000),  # both or neither
}


@pytest.mark.skipif(not hasattr(resource, "RLIMIT_FSIZE"), reason="needs RLIMIT_FSIZE")
@pytest.mark.parametrize("case", [pytest.param(c, marks=SLOW) if c in ("run", "estimate", "report")
                                  else c for c in CASES])
def test_a_full_disk_leaves_nothing_and_one_message(dataset, tmp_path, case):
    args, limit = CASES[case]
    if case == "report":
        assert main(["estimate", str(dataset), "-e", "dead_reckoning", "-o",
                     str(tmp_path / "sol.parquet")]) == 0
    (tmp_path / "s.yaml").write_text(straight_drive(
        100, sensors="  imu: {preset: ideal, rate: 50}\n",
        tail="estimators: [{name: 'tests.reliability.hostile_plugins:Holds'}]\n"))
    before = {"cwd": tree(tmp_path), "dataset": tree(dataset.parent)}
    done = _landnav_on_a_full_disk(args(dataset), tmp_path, limit)
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    assert [line for line in done.stderr.splitlines() if line.strip()] == [
        done.stderr.strip()], done.stderr
    assert "File too large" in done.stderr
    # the message names the output (a plug-in's answer: the temporary folder it is written in)
    assert done.stderr.startswith(("error: out", f"error: {tmp_path / 'tmp'}:")), done.stderr
    assert list((tmp_path / "tmp").iterdir()) == []
    (tmp_path / "tmp").rmdir()
    assert {"cwd": tree(tmp_path), "dataset": tree(dataset.parent)} == before


CAMPAIGN = straight_drive(100, sensors="  imu: {preset: ideal, rate: 50}\n  odometer: {rate: 10}\n",
                          tail="estimators: [dead_reckoning]\n")


@pytest.fixture
def short_tmp_path():
    """A folder with a short path: a campaign's workers listen on a Unix socket in TMPDIR,
    whose path may not exceed 107 bytes (pytest's own tmp_path under xdist comes near)."""
    folder = Path(tempfile.mkdtemp(prefix="fd-"))
    yield folder
    shutil.rmtree(folder, ignore_errors=True)


@pytest.mark.skipif(not hasattr(resource, "RLIMIT_FSIZE"), reason="needs RLIMIT_FSIZE")
def test_a_campaign_stops_on_a_full_disk_and_resumes(short_tmp_path, monkeypatch, capsys):
    """The runs' datasets cannot be written (the limit is below a dataset's size): the
    campaign stops with exit 2 and one message naming the folder and what to do (before, every
    run was recorded as failed and it exited 0); the run finished before is kept, no temporary
    is left (the other worker's run unwinds); run again with room, it resumes."""
    monkeypatch.chdir(short_tmp_path)
    (short_tmp_path / "s.yaml").write_text(CAMPAIGN)
    args = ["campaign", "s.yaml", "--workers", "2", "-o", "mc"]
    assert main([*args, "--runs", "1"]) == 0
    before = tree(short_tmp_path)
    done = _landnav_on_a_full_disk([*args, "--runs", "3"], short_tmp_path, 20_000)
    assert done.returncode == 2, done.stderr
    message = one_message(done.stderr)
    assert f"error: {short_tmp_path / 'tmp'}: cannot write here: File too large" in message
    assert "1 finished run(s) kept in mc" in message and "run the same command again" in message
    assert list((short_tmp_path / "tmp").iterdir()) == []
    (short_tmp_path / "tmp").rmdir()
    assert tree(short_tmp_path) == before
    capsys.readouterr()
    assert main([*args, "--runs", "3"]) == 0
    assert "(2 run(s) computed now, 1 already done)" in capsys.readouterr().out


CLUSTER = """import resource, signal, sys
from distributed import LocalCluster
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, ({limit}, {limit}))
with LocalCluster(host="127.0.0.1", n_workers=1, threads_per_worker=2, processes=False,
                  protocol="tcp", dashboard_address=None) as cluster:
    print(cluster.scheduler_address, flush=True)
    sys.stdin.read()
"""


@SLOW  # about 8 s of CPU: a Dask cluster in a process of its own
@pytest.mark.skipif(not hasattr(resource, "RLIMIT_FSIZE"), reason="needs RLIMIT_FSIZE")
def test_a_campaign_on_dask_workers_stops_on_their_full_disk(tmp_path, monkeypatch, capsys):
    """The Dask workers' disk is full (their process's file-size limit): the campaign stops
    with exit 2 and one message naming the workers' folder and host; nothing is recorded."""
    pytest.importorskip("distributed")
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.yaml").write_text(CAMPAIGN)
    (tmp_path / "tmp").mkdir()
    env = {**os.environ, "PYTHONPATH": str(REPO), "TMPDIR": str(tmp_path / "tmp")}
    with subprocess.Popen([sys.executable, "-c", CLUSTER.format(limit=20_000)], env=env,
                          stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True) as cluster:
        try:
            address = cluster.stdout.readline().strip()
            assert address.startswith("tcp://")
            code = main(["campaign", "s.yaml", "--runs", "3", "--scheduler", address, "-o", "mc"])
        finally:
            cluster.stdin.close()  # the cluster ends
    printed = capsys.readouterr()
    assert code == 2, printed.err
    message = one_message(printed.err)
    assert f"error: {tmp_path / 'tmp'}: cannot write here: File too large" in message
    assert "on the Dask worker's host" in message and "0 finished run(s) kept in mc" in message
    assert [p.name for p in (tmp_path / "tmp").iterdir()] == ["dask-scratch-space"]
    assert sorted(p.name for p in (tmp_path / "mc").rglob("*")) == ["campaign.json", "parts"]
