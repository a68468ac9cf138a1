"""Bad scenario input: every class of problem reported as ``file:line: key.path: message``,
all at once, exit code 2, no traceback, nothing written."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from simulator.cli import main
from simulator.scenario import load_scenario

GOOD = """\
name: t
start: {lat: 37.5, lon: 127.0}
trajectory:
  kind: segments
  segments:
    - accelerate: {to_speed: 10, accel: 1.5}
    - straight: {length: 100}
sensors:
  imu: {preset: ideal, rate: 100}
"""


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "scenario.yaml"
    path.write_text(textwrap.dedent(text))
    return path


def _run(args: list[str], capsys) -> tuple[int, str]:
    code = main(args)
    captured = capsys.readouterr()
    return code, captured.err + captured.out


def _generate_fails(path: Path, tmp_path: Path, capsys) -> str:
    out = tmp_path / "out"
    code, text = _run(["generate", str(path), "-o", str(out)], capsys)
    assert code == 2
    assert "Traceback" not in text
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary left behind
    return text


def test_good_scenario_validates(tmp_path, capsys):
    code, text = _run(["validate", str(_write(tmp_path, GOOD))], capsys)
    assert code == 0 and "ok" in text


@pytest.mark.parametrize("edit, key, words", [
    (("rate: 100}", "rate: 100, colour: red}"), "sensors.imu.colour", "unknown key"),
    (("lat: 37.5", "lat: 95"), "start.lat", "above the maximum"),
    (("length: 100}", "length: -5}"), "trajectory.segments.1.straight.length",
     "greater than 0"),
    (("rate: 100}", "rate: fast}"), "sensors.imu.rate", "expected a number"),
    (("rate: 100}", "rate: '100 m'}"), "sensors.imu.rate", "dimension"),
    (("- straight: {length: 100}", "- turn: {angle: 90, radius: 5}"),
     "trajectory.segments.1.turn", "lateral acceleration"),
    (("- straight: {length: 100}", "- slope: {grade: 0.35, length: 100}"),
     "trajectory.segments.1.slope", "steeper"),
    (("- straight: {length: 100}", "- hop: {length: 100}"), "trajectory.segments.1.hop",
     "unknown segment"),
    (("kind: segments", "kind: teleport"), "trajectory.kind", "unknown trajectory kind"),
])
def test_each_class_of_problem(tmp_path, capsys, edit, key, words):
    text = GOOD.replace(*edit)
    path = _write(tmp_path, text)
    code, out = _run(["validate", str(path)], capsys)
    assert code == 2
    line = next(line for line in out.splitlines() if key in line)
    assert line.startswith(f"{path}:")
    assert words in line
    expected_line = next(i for i, t in enumerate(text.splitlines(), 1) if edit[1] in t)
    assert f":{expected_line}: {key}:" in line
    _generate_fails(path, tmp_path, capsys)


def test_wrong_unit_for_gyro_noise_density(tmp_path, capsys):
    from simulator.schema import Context, Number

    ctx = Context("x.yaml")
    Number("rad/s/sqrt(Hz)").check("0.02 m/s", ("sensors", "imu", "gyro", "noise_density"), ctx)
    message = str(ctx.problems[0])
    assert "sensors.imu.gyro.noise_density" in message and "dimension" in message
    assert Number("rad/s/sqrt(Hz)").check("0.02 deg/s/sqrt(Hz)", (), ctx) == pytest.approx(
        0.02 * 3.141592653589793 / 180)


def test_all_problems_at_once(tmp_path, capsys):
    text = GOOD.replace("lat: 37.5", "lat: 95").replace("length: 100}", "length: -5}")
    text = text.replace("rate: 100}", "rate: 100, flavour: x}")
    code, out = _run(["validate", str(_write(tmp_path, text))], capsys)
    assert code == 2
    assert "start.lat" in out and "straight.length" in out and "imu.flavour" in out


def test_malformed_yaml(tmp_path, capsys):
    path = _write(tmp_path, GOOD.replace("kind: segments", "kind: [segments"))
    code, out = _run(["validate", str(path)], capsys)
    assert code == 2 and "malformed YAML" in out and f"{path}:" in out
    _generate_fails(path, tmp_path, capsys)


def test_missing_file(tmp_path, capsys):
    code, out = _run(["validate", str(tmp_path / "nope.yaml")], capsys)
    assert code == 2 and "file not found" in out
    code, out = _run(["generate", str(tmp_path / "nope.yaml"), "-o", str(tmp_path / "o")],
                     capsys)
    assert code == 2 and "file not found" in out and not (tmp_path / "o").exists()


def test_standing_still_manoeuvre(tmp_path, capsys):
    path = _write(tmp_path, GOOD.replace("- accelerate: {to_speed: 10, accel: 1.5}\n", ""))
    code, out = _run(["validate", str(path)], capsys)
    assert code == 2 and "standing still" in out


def test_overrides_are_validated_and_named(tmp_path, capsys):
    path = _write(tmp_path, GOOD)
    code, out = _run(["validate", str(path), "--set", "start.lat=200"], capsys)
    assert code == 2 and f"{path}:--set: start.lat:" in out
    scenario = load_scenario(path, ["trajectory.segments.1.straight.length=250",
                                    "sensors.imu.rate=200"])
    assert scenario.data["trajectory"]["segments"][1]["straight"]["length"] == 250.0
    assert scenario.data["trajectory"]["rate"] == 200.0


def test_resolved_scenario_is_itself_valid(tmp_path):
    from simulator.scenario import validate_data

    resolved = load_scenario(_write(tmp_path, GOOD)).data
    assert validate_data(resolved, "again.yaml") == resolved
    assert resolved["limits"]["lateral_accel"] == pytest.approx(0.8 * 9.80665)
    assert resolved["start"]["utc"] == "2020-01-01T00:00:00Z"
