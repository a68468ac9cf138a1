"""Hostile scenario files: alias bombs, self-referencing aliases, deep nesting, impossible dates
and numbers YAML 1.1 reads as text. Each is refused as ``file:line: key: message``, exit 2, quickly
and in little memory, with nothing written."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from simulator.cli import main
from simulator.scenario.yamlio import MAX_DEPTH, apply_overrides, read_yaml
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


def test_alias_bomb_refused_fast_and_small(tmp_path):
    """The 272-byte class of bomb (nine levels of nine aliases: 387 million values) is refused
    after building at most MAX_NODES values, in under 100 MB, measured in a fresh process. (No
    wall-clock assertion: its time, about 0.2 s, is in README's guarantees section.)"""
    path = tmp_path / "bomb.yaml"
    path.write_text(_alias_bomb(9, 9))
    assert path.stat().st_size < 400
    code = (
        "import resource, sys, time\n"
        "from simulator.cli import main\n"
        "t = time.perf_counter()\n"
        f"rc = main(['validate', {str(path)!r}])\n"
        "dt = time.perf_counter() - t\n"
        "peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024\n"
        "print(rc, dt, peak)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60, cwd=Path(__file__).resolve().parents[2])
    rc, seconds, peak_mb = done.stdout.split()[-3:]
    assert int(rc) == 2
    assert "expands to more than" in done.stderr
    assert "Traceback" not in done.stderr
    assert float(seconds) > 0
    assert float(peak_mb) < 100 + _baseline_mb()


def _baseline_mb() -> float:
    # the interpreter with landnav's CLI imported, before any file is read
    code = ("import resource\nimport simulator.cli\n"
            "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60, cwd=Path(__file__).resolve().parents[2])
    return float(done.stdout.split()[-1])


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


def test_deep_nesting(tmp_path, capsys):
    """500 levels: beyond landnav's bound and within the nesting limit of recent libyaml
    builds (PyYAML 6.0.4's refuses about 1000 levels itself, with its own message)."""
    message = _validate(tmp_path, "name: " + "[" * 500 + "]" * 500 + "\n", capsys)
    assert f"nested more than {MAX_DEPTH} levels deep" in message


@pytest.mark.parametrize("utc", ["2024-13-45T99:00:00Z", "2023-02-30T00:00:00Z"])
def test_impossible_date(tmp_path, capsys, utc):
    text = GOOD_HEAD.replace("start: {lat: 37.5", f"start: {{utc: {utc}, lat: 37.5")
    message = _validate(tmp_path, text, capsys)
    assert ":2: start.utc:" in message and "not a valid value" in message


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
