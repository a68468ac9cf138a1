"""Consecutive segments in one zone are one zone row of events.parquet (one scored window)."""

from __future__ import annotations

from simulator.dataset.events import zone_events


def test_consecutive_segments_of_a_zone_make_one_row():
    zones = [(10.0, 20.0, "garage"), (20.0, 35.0, "garage"), (35.0, 40.0, "tunnel"),
             (50.0, 60.0, "garage"), (60.0, 61.0, "garage")]
    rows = [(r["t_start"], r["t_end"], r["detail"]) for r in zone_events(zones)]
    assert rows == [(10.0, 35.0, "garage"), (35.0, 40.0, "tunnel"), (50.0, 61.0, "garage")]
    assert all(r["kind"] == "zone" for r in zone_events(zones))


def test_a_raw_only_receiver_still_reports_its_outages(tmp_path):
    """SPEC section 5: every stretch without a GNSS measurement is one gnss_outage row, also when
    the receiver outputs raw measurements only (no fix stream to take the epochs from)."""
    import yaml

    from simulator.cli import main
    from simulator.dataset.io import open_dataset

    scenario = {
        "name": "raw", "start": {"lat": 37.5, "lon": 127.0},
        "trajectory": {"kind": "segments", "segments": [
            {"accelerate": {"to_speed": 10, "accel": 1.5}}, {"straight": {"duration": 30}}]},
        "sensors": {"imu": {"preset": "ideal", "rate": 20},
                    "gnss": {"rate": 1, "outputs": ["raw"]}},
        "faults": [{"kind": "gnss_outage", "start": 10, "duration": 8}],
    }
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(scenario))
    assert main(["generate", str(path), "-o", str(tmp_path / "ds")]) == 0
    ds = open_dataset(tmp_path / "ds")
    assert not ds.has("gnss_fix")
    events = ds.read("events")
    outages = events[events["kind"] == "gnss_outage"]
    assert len(outages) == 1
    assert outages["t_start"].iloc[0] == 10.0 and outages["t_end"].iloc[0] == 18.0
    raw_t = ds.read("gnss_raw")["t"].to_numpy()
    assert not ((raw_t >= 10.0) & (raw_t < 18.0)).any()
