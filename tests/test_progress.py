"""Progress in a log (stderr not a terminal): plain lines with what is done and what is left,
printed by a timer while an item takes long; nothing for work shorter than the interval."""

from __future__ import annotations

import time

from simulator import progress as progress_module
from simulator.progress import progress


def _wait_for_line(capsys, start: str, timeout_s: float = 60.0) -> str:
    """The first line of stderr that begins with ``start``, once the timer has printed it (a
    hang guard, not a speed check)."""
    deadline, err = time.monotonic() + timeout_s, ""
    while time.monotonic() < deadline:
        err += capsys.readouterr().err
        found = [line for line in err.splitlines() if line.startswith(start)]
        if found:
            return found[0]
        time.sleep(0.01)
    raise AssertionError(f"no progress line {start!r}: {err!r}")


def test_lines_say_what_is_done_and_left_while_an_item_takes_long(capsys, monkeypatch):
    monkeypatch.setattr(progress_module, "LINE_INTERVAL_S", 0.01)
    seen, lines = [], []
    for item in progress(range(5), "runs", True):
        if item == 2:  # two done, this one still running
            lines.append(_wait_for_line(capsys, "runs: 2 of 5 done"))
        seen.append(item)
    assert seen == [0, 1, 2, 3, 4]
    first = lines[0]
    assert first.startswith("runs: 2 of 5 done (40 %), 3 left; ")
    assert "so far, about" in first and "to go" in first
    assert capsys.readouterr().err.splitlines()[-1].startswith("runs: 5 done in ")


def test_no_line_for_work_shorter_than_the_interval(capsys, monkeypatch):
    monkeypatch.setattr(progress_module, "LINE_INTERVAL_S", 3600.0)
    assert list(progress(iter([1, 2, 3]), "quick", True, total=3)) == [1, 2, 3]
    assert capsys.readouterr().err == ""


def test_disabled_returns_the_items_themselves():
    items = [1, 2]
    assert progress(items, "x", False) is items
