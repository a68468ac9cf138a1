"""``repeat`` in a segment list: a block driven several times is the same drive as the block
written out, its zone reaches the segments that name none, and its problems are reported at
their own line inside the block."""

from __future__ import annotations

import textwrap

import pytest
import yaml

from simulator.drive import build_drive
from simulator.errors import InputError
from simulator.scenario import load_scenario, validate_data

BLOCK = [{"turn": {"angle": 90, "radius": 30}}, {"straight": {"length": 50}},
         {"straight": {"length": 20, "zone": "tunnel"}}]


def _data(segments: list) -> dict:
    return {"name": "loop", "start": {"lat": 37.5, "lon": 127.0},
            "trajectory": {"kind": "segments", "rate": 20, "segments": [
                {"accelerate": {"to_speed": 8, "accel": 1.0}}, *segments]},
            "vehicle": "rigid"}


def test_a_repeat_is_the_block_written_out():
    repeated = validate_data(_data([{"repeat": {"times": 4, "segments": BLOCK}}]), "r.yaml")
    written = validate_data(_data(BLOCK * 4), "w.yaml")
    assert repeated["trajectory"]["segments"] == written["trajectory"]["segments"]
    a = build_drive(repeated).truth.table()
    b = build_drive(written).truth.table()
    assert a.equals(b)
    # the four right turns close the loop: back at the start heading
    assert abs(a["yaw"].iloc[-1] - a["yaw"].iloc[0]) < 1e-6


def test_the_resolved_scenario_lists_plain_segments_and_validates_again():
    resolved = validate_data(_data([{"repeat": {"times": 2, "segments": BLOCK}}]), "r.yaml")
    kinds = [next(iter(s)) for s in resolved["trajectory"]["segments"]]
    assert "repeat" not in kinds and len(kinds) == 1 + 2 * len(BLOCK)
    assert validate_data(resolved, "again.yaml") == resolved


def test_a_zone_on_the_block_reaches_its_segments_that_name_none():
    resolved = validate_data(_data([{"repeat": {"times": 2, "segments": BLOCK,
                                                "zone": "canyon"}}]), "r.yaml")
    zones = [next(iter(s.values())).get("zone") for s in resolved["trajectory"]["segments"]]
    assert zones == [None, *["canyon", "canyon", "tunnel"] * 2]


@pytest.mark.parametrize("block, key, words", [
    ({"times": 0, "segments": BLOCK}, "trajectory.segments.1.repeat.times", "below the minimum 1"),
    ({"times": 2, "segments": [{"turn": {"angle": 90, "radius": -3}}]},
     "trajectory.segments.1.repeat.segments.0.turn.radius", "greater than 0"),
    ({"times": 2, "segments": [{"repeat": {"times": 2, "segments": BLOCK}}]},
     "trajectory.segments.1.repeat.segments.0.repeat", "unknown segment"),
    ({"times": 2, "segments": []}, "trajectory.segments.1.repeat.segments",
     "at least 1 item"),
])
def test_problems_inside_a_block_name_their_key_and_line(tmp_path, block, key, words):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(_data([{"repeat": block}]), sort_keys=False))
    with pytest.raises(InputError) as caught:
        load_scenario(path, [], None)
    text = str(caught.value)
    assert f"{key}:" in text and words in text, text
    assert f"{path}:" in text and f"{path}: " not in text  # with a line number


def test_shipped_style_text(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(textwrap.dedent("""\
        name: laps
        start: {lat: 37.5, lon: 127.0}
        vehicle: rigid
        trajectory:
          kind: segments
          segments:
            - accelerate: {to_speed: 8, accel: 1.0}
            - repeat:
                times: 3
                segments:
                  - turn: {angle: 90, radius: 30}
                  - straight: {length: 40}
        """))
    scenario = load_scenario(path, [], None)
    assert len(scenario.data["trajectory"]["segments"]) == 7
