"""Hostile scenario files: alias bombs, self-referencing aliases, deep nesting, impossible dates
and numbers YAML 1.1 reads as text. Each is refused as ``file:line: key: message``, exit 2, quickly
and in little memory, with nothing written."""

from __future__ import annotations

import os
import tracemalloc
from pathlib import Path

import pytest
import yaml

from simulator.cli import main
from simulator.errors import InputError
from simulator.scenario.yamlio import (
    MAX_DEPTH,
    MAX_FILE_BYTES,
    MAX_NODES,
    apply_overrides,
    read_yaml,
)
from tests.reliability.checks import refused
from tests.reliability.drives import straight_drive

GOOD_HEAD = straight_drive(100)


def _alias_bomb(levels: int, fan: int) -> str:
    lines = ["a: &a [" + ",".join(["x"] * fan) + "]"]
    names = "abcdefghijklmnopqrstuvwxyz"
    for i in range(1, levels + 1):
        lines.append(f"{names[i]}: &{names[i]} [" + ",".join([f"*{names[i - 1]}"] * fan) + "]")
    return "\n".join(lines) + "\n"


def _validate(tmp_path: Path, text: str, capsys) -> str:
    path = tmp_path / "hostile.yaml"
    path.write_text(text)
    before = sorted(p.name for p in tmp_path.iterdir())
    code = main(["validate", str(path)])
    out = capsys.readouterr()
    message = out.err + out.out
    assert code == 2
    assert "Traceback" not in message
    assert message.startswith(f"{path}:")
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    return message


@pytest.mark.parametrize("levels", [9, 20])
def test_alias_bomb_refused_in_bounded_memory(tmp_path, levels):
    """The 272-byte class of bomb (nine levels of nine aliases: 387 million values; twenty
    levels: 1.2e19) is refused after building at most MAX_NODES values. Memory is measured
    deterministically (tracemalloc's peak of what the reader allocates, independent of the
    machine's load and of what else the process imported): about 35 MB for either bomb, since
    the reader stops at MAX_NODES values whatever the file would expand to."""
    path = tmp_path / "bomb.yaml"
    path.write_text(_alias_bomb(levels, 9))
    assert path.stat().st_size < 1000
    tracemalloc.start()
    try:
        with pytest.raises(InputError, match=f"expands to more than {MAX_NODES} values"):
            read_yaml(path)
        _, peak_bytes = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak_bytes < 100e6


def test_alias_bomb_in_process(tmp_path, capsys):
    message = _validate(tmp_path, _alias_bomb(12, 9), capsys)
    assert "expands to more than" in message


@pytest.mark.parametrize("text", [
    "name: x\nseed: &a [1, *a]\n",
    "name: x\nstart: &s {lat: 1, lon: 2, more: *s}\n",
])
def test_self_referencing_alias(tmp_path, capsys, text):
    message = _validate(tmp_path, text, capsys)
    assert "alias refers to a mapping or list that contains it" in message


@pytest.mark.parametrize("loader", ["libyaml", "pure-python"])
def test_deep_nesting(tmp_path, capsys, monkeypatch, loader):
    """5000 nested lists: refused with a clean message whichever parser reads it (libyaml stops
    at its own depth limit, PyYAML's own parser runs out of recursion, or the reader's
    MAX_DEPTH check comes first, depending on the versions installed)."""
    if loader == "pure-python":
        monkeypatch.delattr(yaml, "CSafeLoader", raising=False)
    elif not hasattr(yaml, "CSafeLoader"):
        pytest.skip("this PyYAML is built without libyaml")
    message = _validate(tmp_path, "name: " + "[" * 5000 + "]" * 5000 + "\n", capsys)
    assert "nest" in message


def test_nesting_beyond_max_depth(tmp_path, capsys):
    """Nesting deeper than MAX_DEPTH, far below any parser's own limit, is the reader's refusal
    with the line of the innermost list."""
    depth = MAX_DEPTH + 10
    message = _validate(tmp_path, "name: x\nseed: " + "[" * depth + "]" * depth + "\n", capsys)
    assert f":2: seed{'.0' * (MAX_DEPTH - 1)}: nested more than {MAX_DEPTH} levels deep" in message


@pytest.mark.parametrize("utc", ["2024-13-45T99:00:00Z", "2023-02-30T00:00:00Z"])
def test_impossible_date(tmp_path, capsys, utc):
    text = GOOD_HEAD.replace("start: {lat: 37.5", f"start: {{utc: {utc}, lat: 37.5")
    message = _validate(tmp_path, text, capsys)
    assert ":2: start.utc:" in message and "is not a valid ISO 8601 UTC time" in message


def test_an_impossible_date_hides_no_other_problem(tmp_path, capsys):
    """Every problem of the file in one run: the date, an unknown key and a negative rate."""
    text = GOOD_HEAD.replace("start: {lat: 37.5", "start: {utc: 2023-02-30T00:00:00Z, lat: 37.5")
    text += "sensors:\n  imu: {preset: ideal, rate: -100}\nspeeed: 3\n"
    message = _validate(tmp_path, text, capsys)
    assert "start.utc: '2023-02-30T00:00:00Z' is not a valid ISO 8601 UTC time" in message
    assert "sensors.imu.rate:" in message and "speeed" in message


def test_scientific_numbers_are_numbers(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text("a: 1.0e9\nb: 1e-3\nc: -2E+2\nd: '1e9'\ne: 1.5\n")
    data, _ = read_yaml(path)
    assert data == {"a": 1.0e9, "b": 1e-3, "c": -200.0, "d": "1e9", "e": 1.5}
    changed, _ = apply_overrides({}, ["x.y=2.5e3"], "f")
    assert changed == {"x": {"y": 2500.0}}


def test_scientific_duration_reaches_the_physics_check(tmp_path, capsys):
    """``duration: 1.0e9`` is read as a number, so the message is about the value, not its unit."""
    text = GOOD_HEAD + "    - stop: {duration: 1.0e9}\n"
    message = _validate(tmp_path, text, capsys)
    assert "unit" not in message.lower()


@pytest.mark.parametrize("name", ["../../victim", "../x", ".hidden", "a/b", "-rf", "x" * 101,
                                  "a\\\\b", "runs/../x"])
def test_scenario_name_must_be_a_safe_file_name(tmp_path, capsys, name):
    text = GOOD_HEAD.replace("name: t", f"name: {name!r}")
    message = _validate(tmp_path, text, capsys)
    assert ":1: name:" in message and "cannot be a file name" in message


def test_estimator_label_must_be_a_safe_file_name(tmp_path, capsys):
    text = GOOD_HEAD + "estimators:\n  - {name: gnss_only, label: ../../etc/x}\n"
    message = _validate(tmp_path, text, capsys)
    assert "estimators.0.label" in message and "cannot be a file name" in message


def test_unbounded_job_refused_with_advice(tmp_path, capsys):
    text = GOOD_HEAD + "    - stop: {duration: '1e7 s'}\n"
    message = _validate(tmp_path, text, capsys)
    assert "trajectory:" in message and "split it into drives" in message


def _fifo(path: Path) -> Path:
    os.mkfifo(path)
    return path


def _zero_link(path: Path) -> Path:
    path.symlink_to("/dev/zero")
    return path


def _sparse(path: Path) -> Path:
    with path.open("wb") as f:
        f.truncate(MAX_FILE_BYTES + 1)  # no blocks: a size, not data
    return path


@pytest.mark.skipif(not hasattr(os, "mkfifo") or not Path("/dev/zero").exists(),
                    reason="needs named pipes and /dev/zero")
@pytest.mark.parametrize("make, words", [
    (_fifo, "not a regular file"),  # read, it would wait for a writer without end
    (_zero_link, "not a regular file"),  # read, it would fill the memory
    (_sparse, "larger than a scenario may be"),
    (lambda p: p.mkdir() or p, "not a regular file"),
])
@pytest.mark.parametrize("command", ["validate", "run", "campaign"])
def test_a_scenario_that_is_no_regular_file_is_refused_unread(tmp_path, capsys, make, words,
                                                              command):
    path = make(tmp_path / "s.yaml")
    args = {"validate": ["validate", str(path)],
            "run": ["run", str(path), "-o", str(tmp_path / "out")],
            "campaign": ["campaign", str(path), "--runs", "1", "-o", str(tmp_path / "out")]}
    refused(args[command], capsys, [tmp_path], words,
            prefix=str(path) if command == "validate" else "error:")
