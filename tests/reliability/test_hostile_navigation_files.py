"""Navigation files named in a scenario are read at validation: a file that is neither RINEX
navigation nor a YUMA almanac, a truncated almanac or RINEX record, a huge file, are refused by
``validate`` naming the scenario key and the file, before anything is generated."""

from __future__ import annotations

from pathlib import Path

import pytest

from simulator.cli import main

SCENARIO = """\
name: t
start: {{utc: 2020-01-02T00:00:00Z, lat: 37.5, lon: 127.0}}
trajectory:
  kind: segments
  segments:
    - accelerate: {{to_speed: 5, accel: 1.5}}
    - straight: {{length: 10}}
sensors:
  gnss: {{constellation: {nav}}}
"""
YUMA = Path(__file__).resolve().parents[3] / "shared" / "refdata" / "almanac" / \
    "maast_2020-01-01" / "almyuma_01jan2020.txt"


def _truncated_yuma(tmp: Path) -> Path:
    if not YUMA.is_file():
        pytest.skip("../shared/refdata is absent (a user's clone has none; CI has it)")
    text = YUMA.read_text()
    cut = tmp / "cut.alm"
    cut.write_text(text[: text.index("week:", 2000)])  # the last record loses its week
    return cut


def _rinex_header_only(tmp: Path) -> Path:
    path = tmp / "head.nav"
    path.write_text(" " * 5 + "2.10           N: GPS NAV DATA" + " " * 25 + "RINEX VERSION / TYPE\n"
                    + " " * 60 + "END OF HEADER\n"
                    + " 1 20  1  2  0  0  0.0 garbage garbage\n")
    return path


CASES = {
    "passwd": (lambda tmp: Path("/etc/passwd"), "neither a RINEX navigation file nor a YUMA"),
    "binary": (lambda tmp: (tmp / "b.bin").write_bytes(bytes(range(256)) * 10) and tmp / "b.bin",
               "neither a RINEX navigation file nor a YUMA"),
    "truncated almanac": (_truncated_yuma, "lacks week"),
    "broken rinex record": (_rinex_header_only, "not a readable RINEX navigation record"),
    "a folder": (lambda tmp: tmp, "is a folder, not a RINEX navigation or YUMA almanac file"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_bad_navigation_file_refused_at_validation(tmp_path, capsys, case):
    make, words = CASES[case]
    nav = make(tmp_path)
    scenario = tmp_path / "s.yaml"
    scenario.write_text(SCENARIO.format(nav=nav))
    before = sorted(p.name for p in tmp_path.iterdir())
    for command in (["validate", str(scenario)],
                    ["generate", str(scenario), "-o", str(tmp_path / "out")]):
        code = main(command)
        printed = capsys.readouterr()
        text = printed.err + printed.out
        assert code == 2, text
        assert "Traceback" not in text
        assert "sensors.gnss.constellation" in text and words in text, text
    assert sorted(p.name for p in tmp_path.iterdir()) == before
