"""Inputs that are not regular files: a device (``/dev/zero``, which never ends), a named pipe
(which waits for a writer), a folder, a socket, given as a solution file, a dataset, a
dataset's manifest or stream, a recording or its reference. Each is refused unread, as what it
is (not as "no such file"), with one message and exit 2, within a bounded time: nothing is
opened, so nothing waits or reads forever."""

from __future__ import annotations

import os
import shutil
import socket
from dataclasses import dataclass
from pathlib import Path

import pytest

from simulator.cli import main
from simulator.commands import score
from simulator.errors import InputError, Problem, Terminated
from tests.reliability.checks import refused
from tests.reliability.drives import shared_dataset  # noqa: F401 (fixtures)

ZERO = Path("/dev/zero")


def _special(folder: Path, kind: str, name: str) -> tuple[Path, str]:
    """``folder/name`` made as ``kind``, and the words that name that kind."""
    path = folder / name
    if kind == "device":
        if not ZERO.exists():
            pytest.skip("no /dev/zero on this system")
        path.symlink_to(ZERO)
        return path, "a character device"
    if kind == "pipe":
        os.mkfifo(path)
        return path, "a named pipe"
    if kind == "socket":
        server = socket.socket(socket.AF_UNIX)
        try:
            server.bind(str(path))
        except OSError as exc:  # a path too long for a socket
            pytest.skip(f"cannot make a socket here: {exc}")
        server.close()
        return path, "a socket"
    path.mkdir()
    return path, "a folder"


@pytest.mark.parametrize("kind", ["device", "pipe", "socket", "folder"])
def test_solution_that_is_not_a_file(dataset, tmp_path, capsys, kind):
    path, words = _special(tmp_path, kind, "s.csv")
    refused(["score", str(dataset), "--solution", str(path)], capsys, [dataset.parent],
            f"{words}, not a solution file")


@pytest.mark.parametrize("kind", ["device", "pipe"])
def test_dataset_that_is_not_a_folder(tmp_path, capsys, kind):
    path, words = _special(tmp_path, kind, "ds")
    refused(["export", str(path), "--nmea", str(tmp_path / "o.nmea")], capsys, [],
            f"{words}, not a dataset directory")
    assert not (tmp_path / "o.nmea").exists()


@pytest.mark.parametrize("member, words", [("manifest.json", "a named pipe, not a manifest file"),
                                            ("imu.parquet", "is a named pipe, not a regular")])
def test_dataset_member_that_is_a_pipe(dataset, tmp_path, capsys, member, words):
    copy = tmp_path / "ds"
    shutil.copytree(dataset, copy)
    (copy / member).unlink()
    os.mkfifo(copy / member)
    refused(["score", str(copy), "-e", "dead_reckoning"], capsys, [tmp_path], words)


def test_recording_and_reference_that_are_not_files(tmp_path, capsys):
    pipe, words = _special(tmp_path, "pipe", "obs.rnx")
    refused(["import", "rinex", str(pipe), str(pipe), "-o", str(tmp_path / "out")], capsys,
            [tmp_path], f"{words}, not a recording file")
    zero, words = _special(tmp_path, "device", "ref.csv")
    for name in ("obs.24o", "nav.24n"):  # read only after the reference is checked
        (tmp_path / name).write_text("not RINEX\n")
    refused(["import", "rinex", str(tmp_path / "obs.24o"), str(tmp_path / "nav.24n"),
             "--reference", str(zero), "-o", str(tmp_path / "out")], capsys, [tmp_path],
            f"{words}, not a reference file")
    assert not (tmp_path / "out").exists()


def test_a_stop_while_the_message_prints_is_no_traceback(capsys, monkeypatch):
    """SIGTERM arriving while a refusal is printed (its handler raises ``Terminated`` there):
    exit 143 with its own message, not a traceback from inside the error report."""
    @dataclass(frozen=True)
    class StoppedWhilePrinted(Problem):
        def __str__(self) -> str:
            raise Terminated(15)

    def refuse(args):
        raise InputError([StoppedWhilePrinted("f", None, "", "bad")])

    monkeypatch.setattr(score, "run", refuse)
    assert main(["score", "ds", "-e", "gnss_only"]) == 143
    err = capsys.readouterr().err
    assert "terminated: unfinished outputs were removed" in err and "Traceback" not in err
