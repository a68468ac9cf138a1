"""A real file system that fills up while a command writes (a tmpfs of a few MiB, filled
until a few KiB remain: ``small_disk``): exit 2, one message naming the output and saying the
device is full, no traceback, nothing left on the disk (no ``.NAME.tmp``, no half-written file,
no folder made for the output), the inputs unchanged. A campaign keeps what it recorded and
resumes once there is room. Skipped, with the reason, where no private tmpfs can be mounted
(no CAP_SYS_ADMIN and no user namespaces). ``test_full_disk`` stands a file-size limit in for
the full disk where this cannot run."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from simulator.cli import main
from tests.reliability.checks import one_message, tree
from tests.reliability.drives import shared_dataset, straight_drive  # noqa: F401 (fixture)
from tests.reliability.small_disk import on_small_disk

REPO = Path(__file__).resolve().parents[2]
FULL = "cannot write here: no space left on the device"
SLOW = pytest.mark.slow  # each case about 4-8 s of CPU (landnav processes)
SCENARIO = straight_drive(100, sensors="  imu: {preset: ideal, rate: 50}\n  odometer: {rate: 10}\n"
                                       "  gnss: {rate: 1, outputs: [fix, raw]}\n",
                          tail="estimators: [dead_reckoning]\n")

# case: (arguments, KiB left free, the output the message names, DISK the small disk); the
# dataset is 240 KiB, a run's folder 1 MiB; each case fails part-way through its output's files
CASES = {
    "generate": (["generate", "s.yaml", "-o", "disk/out"], 40, "disk/out"),
    "estimate": (["estimate", "DATASET", "-e", "dead_reckoning", "-o", "disk/sol.parquet"], 4,
                 "disk/sol.parquet"),
    "score --report": (["score", "DATASET", "--solution", "sol.parquet", "--report",
                        "disk/report", "--json", "disk/scores.json"], 100, "disk/report"),
    "export into new folders": (["export", "DATASET", "--rinex", "disk/new/rinex", "--nmea",
                                 "disk/new.nmea"], 8, "disk/new/rinex/ds."),
    # checked in the temporary folder first, which is on the full disk (was 'cannot write to
    # the standard output': Arrow's error carried no error number)
    "twin": (["twin", "DATASET", "-o", "disk/twin.yaml"], 8, "DISK/tmp"),
    "run, the dataset written": (["run", "s.yaml", "-o", "disk/out"], 300, "disk/out"),
    "run, nothing written": (["run", "s.yaml", "-o", "disk/out"], 8, "disk/out"),
    # nothing is written until the papers' runs are complete: the report's first file fails
    "reproduce": (["reproduce", "tan2008", "--quick", "--runs", "1", "-o", "disk/repro"], 8,
                  "disk/repro"),
}


@pytest.fixture
def small_disk(tmp_path):
    """``(run, disk)``: ``run(commands, free_kib, **options)`` runs landnav commands in
    ``tmp_path`` with a small tmpfs on ``tmp_path/disk`` (``small_disk.on_small_disk``),
    skipping the test when none can be mounted here."""
    disk = tmp_path / "disk"
    disk.mkdir()
    (tmp_path / "tmp").mkdir()
    env = {"PYTHONPATH": str(REPO), "TMPDIR": str(tmp_path / "tmp")}

    def run(commands: list[list[str]], free_kib: int, **options) -> list[dict]:
        results = on_small_disk(commands, disk, env, free_kib, **options)
        if isinstance(results, str):
            pytest.skip(results)
        return results
    return run, disk


@pytest.mark.parametrize("case", [pytest.param(c, marks=SLOW)
                                  if c.startswith(("run", "reproduce")) else c for c in CASES])
def test_a_full_file_system_leaves_nothing_and_one_message(dataset, tmp_path, small_disk, case):
    run, disk = small_disk
    args, free_kib, named = CASES[case]
    named = named.replace("DISK", str(disk))
    (tmp_path / "s.yaml").write_text(SCENARIO)
    if "sol.parquet" in args:
        assert main(["estimate", str(dataset), "-e", "dead_reckoning", "-o",
                     str(tmp_path / "sol.parquet")]) == 0
    before = {"here": tree(tmp_path), "dataset": tree(dataset)}
    [done] = run([[str(dataset) if a == "DATASET" else a for a in args]], free_kib)
    assert done["code"] == 2, done["stderr"]
    message = one_message(done["stderr"])
    assert message.startswith(f"error: {named}") and FULL in message, message
    assert done["left"] == ["tmp"]  # the temporary folder, empty
    assert {"here": tree(tmp_path), "dataset": tree(dataset)} == before


def test_a_campaign_on_a_full_file_system_is_one_message(tmp_path, small_disk):
    """Not even the campaign's lock (a few bytes beside its folder) can be written: one
    message naming the folder (before: 'cannot write to the standard output'), nothing left."""
    run, _ = small_disk
    (tmp_path / "s.yaml").write_text(SCENARIO)
    before = tree(tmp_path)
    [done] = run([["campaign", "s.yaml", "--runs", "2", "-o", "disk/mc"]], 0, tmp_on_disk=False)
    assert done["code"] == 2, done["stderr"]
    assert one_message(done["stderr"]) == f"error: disk/mc: {FULL}"
    assert done["left"] == ["tmp"]
    assert tree(tmp_path) == before


@SLOW  # about 12 s of CPU: two campaigns of two local workers
def test_a_campaign_stopped_by_a_full_file_system_resumes_with_room(tmp_path, small_disk):
    """Its record is written, no run's table can be: exit 2, one message naming the folder and
    what to do, the record kept (no lock, no temporary); with the space freed the same command
    completes every run."""
    run, _ = small_disk
    (tmp_path / "s.yaml").write_text(SCENARIO)
    args = ["campaign", "s.yaml", "--runs", "3", "--workers", "2", "-o", "disk/mc"]
    full, resumed = run([args, args], 8, tmp_on_disk=False, free_before_next=True)
    assert full["code"] == 2, full["stderr"]
    message = one_message(full["stderr"])
    assert message.startswith(f"error: disk/mc: {FULL}; the campaign stopped, its 0 finished "
                              "run(s) kept in disk/mc"), message
    assert "run the same command again" in message
    assert full["left"] == ["mc", "mc/campaign.json", "mc/parts", "tmp"]
    assert resumed["code"] == 0, resumed["stderr"]
    assert "(3 run(s) computed now, 0 already done)" in resumed["stdout"]
    assert not [p for p in resumed["left"] if os.path.basename(p).startswith(".")]
