"""Consecutive segments in one zone are one zone row of events.parquet (one scored window)."""

from __future__ import annotations

from simulator.dataset.events import zone_events


def test_consecutive_segments_of_a_zone_make_one_row():
    zones = [(10.0, 20.0, "garage"), (20.0, 35.0, "garage"), (35.0, 40.0, "tunnel"),
             (50.0, 60.0, "garage"), (60.0, 61.0, "garage")]
    rows = [(r["t_start"], r["t_end"], r["detail"]) for r in zone_events(zones)]
    assert rows == [(10.0, 35.0, "garage"), (35.0, 40.0, "tunnel"), (50.0, 61.0, "garage")]
    assert all(r["kind"] == "zone" for r in zone_events(zones))
