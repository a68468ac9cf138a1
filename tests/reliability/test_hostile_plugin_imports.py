"""Plug-in modules that misbehave when imported (hang, loop, wait, crash the interpreter, exit,
abort): every command that imports them (``estimate``, ``run``, ``campaign``, ``validate
--import-plugins``, ``estimators``) imports them in a child process and ends within the time
limit with exit 2 and one message naming the module's file, nothing written. A module that
prints megabytes or forks processes that would outlive it: the command's own output stays
clean and no process of the plug-in is left running."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import pytest

from simulator import isolated
from simulator.cli import main
from tests.reliability.checks import alive, refused
from tests.reliability.drives import (  # noqa: F401 (fixture)
    estimator_scenario,
    shared_dataset,
)

PLUGIN_CLASS = ("from tests.reliability.hostile_plugins import _Base\n\n\n"
                "class Hostile(_Base):\n    pass\n")

# module text -> words of the one message
AT_IMPORT = {
    "hangs": ("import time\ntime.sleep(1e9)\n", "did not finish within 2 s"),
    "loops": ("while True:\n    pass\n", "did not finish within 2 s"),
    "waits": ("import threading\nthreading.Event().wait()\n", "did not finish within 2 s"),
    "segfaults": ("import ctypes\nctypes.string_at(0)\n", "was killed by signal 11"),
    "exits": ("import sys\nsys.exit(0)\n", "exit code 0"),
    "raises_system_exit": ("raise SystemExit(3)\n", "exit code 3"),
    "aborts": ("import os\nos.abort()\n", "was killed by signal 6"),
}
LIMIT = ["--time-limit", "2"]


def _plugin(tmp_path: Path, monkeypatch, module: str, text: str) -> Path:
    """``module.py`` (``text`` then a valid estimator class ``Hostile``) in a folder of its own,
    the current folder; the module's file."""
    folder = tmp_path / "plugins"
    folder.mkdir()
    path = folder / f"{module}.py"
    path.write_text(text + PLUGIN_CLASS)
    monkeypatch.chdir(folder)
    return path


def _scenario(work: Path, module: str) -> Path:
    return estimator_scenario(work, 30, 50, f"[{{name: '{module}:Hostile'}}]")


@pytest.mark.parametrize("module", list(AT_IMPORT))
def test_estimate_with_a_plugin_that_misbehaves_at_import(dataset, tmp_path, monkeypatch,
                                                          capsys, module):
    text, words = AT_IMPORT[module]
    path = _plugin(tmp_path, monkeypatch, module, text)
    work = tmp_path / "work"
    work.mkdir()
    printed = refused(["estimate", str(dataset), "-e", f"{module}:Hostile", "-o",
                       str(work / "sol.parquet"), *LIMIT], capsys, [work, dataset], words)
    assert str(path) in printed
    assert list(work.iterdir()) == []


COMMANDS = {
    "run": lambda scenario, out: ["run", str(scenario), "-o", str(out), *LIMIT],
    "campaign": lambda scenario, out: ["campaign", str(scenario), "--runs", "2", "--workers",
                                       "1", "-o", str(out), *LIMIT],
    # no --time-limit: the default bound, shortened here
    "validate": lambda scenario, out: ["validate", str(scenario), "--import-plugins"],
}


@pytest.mark.parametrize("module", ["hangs", "segfaults"])
@pytest.mark.parametrize("command", list(COMMANDS))
def test_every_command_bounds_a_plugin_import(tmp_path, monkeypatch, capsys, command, module):
    text, words = AT_IMPORT[module]
    path = _plugin(tmp_path, monkeypatch, module, text)
    monkeypatch.setattr(isolated, "CHECK_LIMIT_S", 2.0)
    work = tmp_path / "work"
    work.mkdir()
    scenario = _scenario(work, module)
    printed = refused(COMMANDS[command](scenario, work / "out"), capsys, [work], words,
                      prefix=str(scenario) if command == "validate" else "error:")
    assert str(path) in printed
    assert sorted(p.name for p in work.iterdir()) == ["s.yaml"]


@pytest.mark.parametrize("module", ["hangs", "segfaults", "exits"])
def test_describing_a_plugin_bounds_its_import(tmp_path, monkeypatch, capsys, module):
    """``landnav estimators module:Class`` imports the module in a child process, within the
    bound, and names its file."""
    text, words = AT_IMPORT[module]
    path = _plugin(tmp_path, monkeypatch, module, text)
    monkeypatch.setattr(isolated, "CHECK_LIMIT_S", 2.0)
    printed = refused(["estimators", f"{module}:Hostile"], capsys, [path.parent], words)
    assert str(path) in printed


def test_describing_a_plugin_runs_none_of_it_here(tmp_path, monkeypatch, capsys):
    """A plug-in that works is described as a built-in is, from a child process: its module
    is never imported into landnav's own."""
    _plugin(tmp_path, monkeypatch, "described", "")
    assert main(["estimators", "described:Hostile"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("described:Hostile (described:Hostile)\npaper:")
    assert "described" not in sys.modules


NOISY = ("import sys\nprint('x' * 3_000_000)\nsys.stdout.write('y' * 1_000_000)\n"
         "sys.stdout.flush()\nimport os\nos.write(1, b'z' * 1_000_000)\n")


def test_a_plugin_printing_megabytes_leaves_the_output_clean(dataset, tmp_path, monkeypatch,
                                                            capfd):
    """What a plug-in prints at import (Python's print, a write to file descriptor 1) goes to
    the standard error; the standard output holds the command's one line."""
    _plugin(tmp_path, monkeypatch, "noisy", NOISY)
    out = tmp_path / "sol.parquet"
    assert main(["estimate", str(dataset), "-e", "noisy:Hostile", "-o", str(out)]) == 0
    printed = capfd.readouterr()
    assert printed.out.splitlines() == [printed.out.strip()]
    assert printed.out.startswith(f"wrote {out} (noisy:Hostile: ")
    assert printed.err.count("x" * 1000) >= 3000  # imported twice: checked, then replayed
    assert out.is_file()


FORKS = ("import os, subprocess, sys, time\n"
         "sleeper = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(600)'])\n"
         "forked = os.fork()\n"
         "if forked == 0:\n    time.sleep(600)\n"
         "with open('pids.txt', 'a') as f:\n    f.write(f'{sleeper.pid} {forked}\\n')\n")


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux's /proc")
@pytest.mark.parametrize("command", ["estimate", pytest.param("run", marks=pytest.mark.slow)])
def test_processes_a_plugin_starts_end_with_it(dataset, tmp_path, monkeypatch, capsys,
                                               command):
    """A plug-in that starts a process and forks itself at import: the command completes and
    none of them is left (each child ends its process group)."""
    path = _plugin(tmp_path, monkeypatch, "forks", FORKS)
    work = tmp_path / "work"
    work.mkdir()
    args = (["estimate", str(dataset), "-e", "forks:Hostile", "-o", str(work / "sol.parquet")]
            if command == "estimate" else ["run", str(_scenario(work, "forks")), "-o",
                                           str(work / "out")])
    assert main(args) == 0, capsys.readouterr().err
    pids = [int(p) for p in (path.parent / "pids.txt").read_text().split()]
    assert len(pids) == 4  # two at the check, two at the replay
    deadline = time.monotonic() + 60  # a hang guard: they are killed when the child ends
    while any(alive(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(alive(p) for p in pids)


@pytest.mark.parametrize("command", ["estimate", "run", "campaign"])
def test_the_default_bound_is_stated_in_the_help(capsys, command):
    """``--time-limit``'s help states the default bound on importing a plug-in (written out:
    ``--help`` does not import the module that holds it)."""
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert f"(default {isolated.CHECK_LIMIT_S:g} s)" in text
