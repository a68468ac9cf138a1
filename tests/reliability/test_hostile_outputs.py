"""Hostile and careless output paths on every writing command: existing files without
``--force``, outputs inside the input dataset, file-system errors, concurrent writers, SIGTERM.
Each ends with exit 2 (143/130 for signals), one message naming the path, no traceback, and a
file system unchanged apart from what the user named."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from simulator.cli import main
from tests.reliability.checks import refused
from tests.reliability.drives import straight_drive

REPO = Path(__file__).resolve().parents[2]
SCENARIO = straight_drive(200, sensors="  imu: {preset: ideal, rate: 50}\n"
                                       "  gnss: {rate: 1, outputs: [fix, raw]}\n")


@pytest.fixture(scope="module")
def dataset(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("hostile_out")
    scenario = root / "s.yaml"
    scenario.write_text(SCENARIO)
    assert main(["generate", str(scenario), "-o", str(root / "ds")]) == 0
    return root / "ds"


@pytest.fixture
def solution(dataset, tmp_path) -> Path:
    path = tmp_path / "sol.parquet"
    assert main(["estimate", str(dataset), "-e", "gnss_only", "-o", str(path)]) == 0
    return path


def test_estimate_refuses_to_overwrite(dataset, solution, capsys):
    refused(["estimate", str(dataset), "-e", "gnss_only", "-o", str(solution)], capsys,
             [solution.parent, dataset], "already exists; use --force")


def test_estimate_never_writes_into_the_dataset(dataset, capsys):
    for target in (dataset / "imu.parquet", dataset / "new.parquet"):
        refused(["estimate", str(dataset), "-e", "gnss_only", "-o", str(target), "--force"],
                 capsys, [dataset], "is inside the input")


def test_export_nmea_never_overwrites_the_manifest(dataset, capsys):
    refused(["export", str(dataset), "--nmea", str(dataset / "manifest.json"), "--force"],
             capsys, [dataset], "is inside the input")


def test_score_json_refuses_to_overwrite(dataset, solution, tmp_path, capsys):
    target = tmp_path / "scores.json"
    target.write_text("{}")
    refused(["score", str(dataset), "--solution", str(solution), "--json", str(target)],
             capsys, [tmp_path, dataset], "already exists; use --force")
    assert main(["score", str(dataset), "--solution", str(solution), "--json", str(target),
                 "--force"]) == 0
    assert target.read_text() != "{}"


def test_export_rinex_refuses_existing_files_and_writes_both_or_none(dataset, tmp_path, capsys):
    out = tmp_path / "rinex"
    out.mkdir()
    (out / f"{dataset.name}.nav").write_text("mine")
    refused(["export", str(dataset), "--rinex", str(out)], capsys, [tmp_path, dataset],
             "already exists")
    assert sorted(p.name for p in out.iterdir()) == [f"{dataset.name}.nav"]


@pytest.mark.parametrize("option", ["--json", "--nmea", "--rinex", "-o"])
def test_output_is_a_folder_or_file_of_the_wrong_kind(dataset, solution, tmp_path, capsys,
                                                      option):
    folder = tmp_path / "a_folder"
    folder.mkdir()
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    args = {
        "--json": ["score", str(dataset), "--solution", str(solution), "--json", str(folder)],
        "--nmea": ["export", str(dataset), "--nmea", str(folder)],
        "--rinex": ["export", str(dataset), "--rinex", str(a_file)],
        "-o": ["estimate", str(dataset), "-e", "gnss_only", "-o", str(a_file / "x.parquet")],
    }[option]
    refused(args, capsys, [tmp_path, dataset], str(folder if option in ("--json", "--nmea")
                                                       else a_file))


@pytest.mark.parametrize("where", ["read-only folder", "/proc"])
def test_unwritable_parent(dataset, tmp_path, capsys, where):
    """A folder the process may not write into (root may write anywhere a mode allows, so
    /proc stands in for a read-only volume when the tests run as root)."""
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    target = Path("/proc/landnav-test.parquet") if where == "/proc" or os.geteuid() == 0 \
        else locked / "s.parquet"
    try:
        refused(["estimate", str(dataset), "-e", "gnss_only", "-o", str(target)],
                 capsys, [tmp_path], "cannot write here")
    finally:
        locked.chmod(0o700)


def test_dangling_symlink_as_output(dataset, tmp_path, capsys):
    link = tmp_path / "dangling.parquet"
    link.symlink_to(tmp_path / "nowhere" / "x.parquet")
    refused(["estimate", str(dataset), "-e", "gnss_only", "-o", str(link)], capsys,
             [tmp_path], "dangling symbolic link")


def test_generate_under_an_existing_file(tmp_path, capsys):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(SCENARIO)
    (tmp_path / "f").write_text("x")
    refused(["generate", str(scenario), "-o", str(tmp_path / "f" / "ds")], capsys, [tmp_path],
             "is a file, not a folder")


def test_a_claimed_folder_is_refused_and_a_stale_claim_taken_over(tmp_path, capsys):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(SCENARIO)
    claim = tmp_path / ".ds.tmp"
    claim.mkdir()
    (claim / ".landnav-owner").write_text(str(os.getpid()))  # a live process holds it
    refused(["generate", str(scenario), "-o", str(tmp_path / "ds")], capsys, [tmp_path],
             f"process {os.getpid()}")
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    (claim / ".landnav-owner").write_text(dead)  # its writer was killed
    assert main(["generate", str(scenario), "-o", str(tmp_path / "ds")]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ds", "s.yaml"]


def _landnav(args: list[str], cwd: Path) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    # as from a terminal: a shell without job control starts background jobs with SIGINT
    # ignored, and Python keeps an ignored SIGINT ignored
    return subprocess.Popen([sys.executable, "-m", "simulator.cli", *args], cwd=cwd, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


LONG = SCENARIO.replace("straight: {length: 200}", "straight: {duration: 1800}").replace(
    "rate: 50}", "rate: 100}")


def test_two_concurrent_generations_into_one_folder(tmp_path):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(LONG)
    procs = [_landnav(["generate", str(scenario), "-o", "ds", "--seed", str(seed)], tmp_path)
             for seed in (1, 2)]
    results = [(p.wait(timeout=300), *p.communicate()) for p in procs]
    codes = sorted(r[0] for r in results)
    assert codes == [0, 2], results
    loser = next(r for r in results if r[0] == 2)
    assert "Traceback" not in loser[2] and "ds" in loser[2]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ds", "s.yaml"]
    assert main(["estimate", str(tmp_path / "ds"), "-e", "gnss_only", "-o",
                 str(tmp_path / "sol.parquet")]) == 0  # the survivor is complete and readable


@pytest.mark.parametrize("sig, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
@pytest.mark.parametrize("command", ["generate", "run"])
def test_signal_during_generation_leaves_nothing(tmp_path, sig, code, command):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(LONG)
    proc = _landnav([command, str(scenario), "-o", "out"], tmp_path)
    deadline = time.monotonic() + 600  # a hang guard, generous for a loaded machine
    while not any(p.name.startswith(".out") for p in tmp_path.iterdir()):
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.02)
    proc.send_signal(sig)
    rc = proc.wait(timeout=30)  # a hang, not a speed check: it ends in about 0.1 s
    _, err = proc.communicate()
    assert rc == code, err
    assert "Traceback" not in err and ("terminated" in err or "interrupted" in err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]
    rerun = _landnav([command, str(scenario), "-o", "out"], tmp_path)
    assert rerun.wait(timeout=300) == 0, rerun.communicate()


def test_names_that_are_not_utf8(dataset, tmp_path, capsys):
    bad = os.fsdecode(b"out\xff")
    scenario = tmp_path / "s.yaml"
    scenario.write_text(SCENARIO)
    refused(["generate", str(scenario), "-o", str(tmp_path / bad)], capsys, [tmp_path],
            "is not valid UTF-8 text")
    refused(["estimate", str(dataset), "-e", "gnss_only", "-o",
             str(tmp_path / f"{bad}.parquet")], capsys, [tmp_path], "is not valid UTF-8 text")


@pytest.mark.parametrize("stdout, code", [("full", 2), ("closed", 0)])
def test_full_or_closed_standard_output(tmp_path, stdout, code):
    """A full standard output is one message (the dataset itself is written); a closed one
    loses only what would be printed."""
    scenario = tmp_path / "s.yaml"
    scenario.write_text(SCENARIO)
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    argv = [sys.executable, "-m", "simulator.cli", "generate", str(scenario), "-o",
            str(tmp_path / "ds")]
    if stdout == "full":
        with open("/dev/full", "w") as full:
            done = subprocess.run(argv, env=env, stdout=full, stderr=subprocess.PIPE,
                                  text=True, timeout=300)
    else:
        done = subprocess.run(argv, env=env, stderr=subprocess.PIPE, text=True, timeout=300,
                              preexec_fn=lambda: os.close(1))
    assert done.returncode == code, done.stderr
    assert "Traceback" not in done.stderr
    if code == 2:
        assert done.stderr.count("error:") == 1 and "standard output" in done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ds", "s.yaml"]


def test_thread_settings_leave_the_bytes_unchanged(tmp_path):
    """The same dataset with OpenBLAS on one and on two threads (before, three truth rows of
    this drive differed by 3e-17)."""
    scenario = tmp_path / "s.yaml"
    scenario.write_text((REPO / "scenarios" / "quickstart.yaml").read_text())
    for threads in ("1", "2"):
        env = {**os.environ, "PYTHONPATH": str(REPO), "OPENBLAS_NUM_THREADS": threads}
        subprocess.run([sys.executable, "-m", "simulator.cli", "generate", str(scenario), "-o",
                        str(tmp_path / threads)], env=env, check=True, capture_output=True,
                       timeout=600)
    files = sorted(p.name for p in (tmp_path / "1").glob("*.parquet"))
    assert files == sorted(p.name for p in (tmp_path / "2").glob("*.parquet"))
    for name in files:
        assert (tmp_path / "1" / name).read_bytes() == (tmp_path / "2" / name).read_bytes(), name


@pytest.mark.parametrize("where, words", [
    ("under a file", "is a file, not a folder"), ("dangling link", "dangling symbolic link"),
    ("/proc", "cannot write here")])
def test_campaign_outputs_that_cannot_be_written(tmp_path, capsys, where, words):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(SCENARIO + "estimators: [gnss_only]\n")
    (tmp_path / "f").write_text("x")
    (tmp_path / "dangling").symlink_to(tmp_path / "nowhere")
    out = {"under a file": tmp_path / "f" / "mc", "dangling link": tmp_path / "dangling",
           "/proc": Path("/proc/landnav-mc")}[where]
    refused(["campaign", str(scenario), "--runs", "1", "--workers", "1", "-o", str(out)],
            capsys, [tmp_path], words)


def test_a_file_error_no_writer_named_is_not_blamed_on_the_standard_output(monkeypatch,
                                                                              capsys):
    """An ``OSError`` naming a file that reaches the command line untranslated is one message
    naming that file (it was printed as 'cannot write to the standard output' before, as a
    campaign's lock on a full disk showed)."""
    import simulator.commands.schema as schema

    def fails(args):
        raise OSError(28, "No space left on device", "out/.mc.lock")

    monkeypatch.setattr(schema, "run", fails)
    assert main(["schema"]) == 2
    printed = capsys.readouterr()
    assert printed.err == "error: out/.mc.lock: No space left on device\n"
