"""Jobs that would grow without bound, refused at validation or on reading with the estimate
and the advice: a random fault at a million events a second, hours of 100 Hz GNSS, a campaign
of 2 million runs or 1001 sweep points, a dataset with a gap or shifted times, a solution file
of 3 GB; numbers and dates that used to overflow; ``--set`` values nested or aliased beyond a
file's bounds. Each is one message, exit 2, no traceback, nothing written."""

from __future__ import annotations

import json

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from simulator.faults.base import in_intervals
from tests.reliability.checks import refused
from tests.reliability.drives import shared_dataset, shared_dataset_copy, straight_drive  # noqa: F401 (fixtures)

GNSS = "  gnss: {rate: 1, outputs: [fix]}\n"


@pytest.mark.parametrize("scenario, words", [
    (straight_drive(100, sensors=GNSS, tail="faults:\n  - {kind: gnss_outage, random: {rate: 1e6, "
                              "duration: {distribution: fixed, mean: 1}}}\n"),
     "events, more than one fault may draw"),
    (straight_drive(100, sensors="  gnss: {rate: 100, outputs: [fix, raw]}\n").replace(
        "{length: 100}", "{duration: 97000}"), "GNSS epochs at 100 Hz need about"),
    # 9 h at 10 Hz: 8.7 GB by epochs alone; measured, four systems cost 3.2x GPS's epoch
    (straight_drive(100, sensors="  gnss: {rate: 10, systems: [gps, galileo, beidou, glonass]}"
                                 "\n").replace("{length: 100}", "{duration: 32400}"),
     "need about 55.1 GB (tracking gps, galileo, beidou, glonass)"),
    # 27 h with odometer, barometer and magnetometer at 100 Hz: 12.6 GB, validated before
    (straight_drive(100, sensors="  imu: {preset: ideal, rate: 100}\n  odometer: {rate: 100}\n"
                                 "  baro: {rate: 100}\n  mag: {rate: 100}\n").replace(
        "{length: 100}", "{duration: 97000}"),
     "and 2.91e+07 odometer, barometer and magnetometer samples need about 12.6 GB"),
    (straight_drive(1e300), "is beyond any value a scenario describes"),
    # a sensor at 1e-300 Hz: a truth of one row and an IMU interval of 1e300 s, written
    (straight_drive(100, sensors="  imu: {preset: ideal, rate: 1e-300}\n"),
     "sensors.imu.rate: at 1e-300 Hz one sample period is longer than the 17.67 s drive"),
    (straight_drive(100).replace(
        "start: {lat: 37.5, lon: 127.0}",
        "start: {lat: 37.5, lon: 127.0, utc: '9999-12-31T23:59:59-01:00'}"), "is after 2200"),
    # its offset takes it before year 1 in UTC: early, not late (was 'is after 2200')
    (straight_drive(100).replace(
        "start: {lat: 37.5, lon: 127.0}",
        "start: {lat: 37.5, lon: 127.0, utc: '0001-01-01T00:00:00+14:00'}"),
     "is before 1980-01-06T00:00:00Z (the GPS epoch"),
])
def test_validation_refuses_unbounded_drives(tmp_path, capsys, scenario, words):
    (tmp_path / "s.yaml").write_text(scenario)
    refused(["generate", str(tmp_path / "s.yaml"), "-o", str(tmp_path / "ds")], capsys,
            [tmp_path], words)


def _alias_bomb(levels: int) -> str:
    lines, previous = ["a0: &a0 [x, x, x, x, x, x, x, x, x]"], "a0"
    for i in range(1, levels):
        lines.append(f"a{i}: &a{i} [{', '.join([f'*{previous}'] * 9)}]")
        previous = f"a{i}"
    return "{" + ", ".join(lines) + "}"


@pytest.mark.parametrize("override, words", [
    ("description=" + _alias_bomb(9), "expands to more than 200000 values"),
    (".".join(["a"] * 5000) + "=1", "more than 64 levels deep"),
    ("trajectory.segments=" + "[" * 5000 + "]" * 5000, "trajectory.segments"),
])
def test_set_values_within_the_files_bounds(tmp_path, capsys, override, words):
    (tmp_path / "s.yaml").write_text(straight_drive(100))
    refused(["validate", str(tmp_path / "s.yaml"), "--set", override], capsys, [tmp_path],
            words, prefix=str(tmp_path))


def test_campaign_task_counts(tmp_path, capsys):
    (tmp_path / "s.yaml").write_text(straight_drive(50, sensors=GNSS,
                                                    tail="estimators: [gnss_only]\n"))
    base = ["campaign", str(tmp_path / "s.yaml"), "-o", str(tmp_path / "mc"), "--workers", "1"]
    refused([*base, "--runs", "1000000", "--sweep", "sensors.gnss.rate=1,2"], capsys,
            [tmp_path], "2,000,000 runs, more than one campaign plans")
    values = ",".join(str(1 + i / 1000) for i in range(1001))
    refused([*base, "--runs", "1", "--sweep", f"sensors.gnss.rate={values}"], capsys,
            [tmp_path], "1,001 sweep points")


@pytest.mark.parametrize("value", ["inf", "nan", "0"])
def test_scheduler_timeout_out_of_range(tmp_path, capsys, value):
    (tmp_path / "s.yaml").write_text(straight_drive(50, sensors=GNSS,
                                                    tail="estimators: [gnss_only]\n"))
    refused(["campaign", str(tmp_path / "s.yaml"), "--runs", "1", "-o", str(tmp_path / "mc"),
             "--scheduler", "tcp://127.0.0.1:1", "--scheduler-timeout", value], capsys,
            [tmp_path], "--scheduler-timeout")


def test_random_fault_mask_is_the_union_of_its_intervals():
    """The binary-search mask against its definition, one pass per interval."""
    rng = np.random.default_rng(7)
    t = np.sort(rng.uniform(0, 100, 5000))
    starts = rng.uniform(0, 100, 300)
    intervals = [(float(a), float(a + d)) for a, d in zip(starts, rng.exponential(0.3, 300),
                                                         strict=True)]
    expected = np.zeros(t.shape, dtype=bool)
    for a, b in intervals:
        expected |= (t >= a) & (t < b)
    assert np.array_equal(in_intervals(t, intervals), expected)
    assert not in_intervals(t, []).any()


def test_huge_solution_file_is_not_read(dataset, tmp_path, capsys):
    big = tmp_path / "solution.dat"
    with big.open("wb") as handle:  # sparse: 3 GB on paper, nothing on the disk
        handle.truncate(3 * 1024**3)
    refused(["score", str(dataset), "--solution", str(big)], capsys, [tmp_path],
            "more than a solution file may be")


def _shift(ds, stream: str, change) -> None:
    path = ds / f"{stream}.parquet"
    table = pq.read_table(path)
    i = table.schema.get_field_index("t")
    t = change(table.column("t").to_numpy().copy())
    pq.write_table(table.set_column(i, table.schema.field(i), pa.array(t)), path)


@pytest.mark.parametrize("change, words", [
    (lambda t: t + 1e12, "outside the drive"),
    (lambda t: t * 1000.0, "in another unit than seconds"),
])
def test_dataset_times_shifted_or_scaled(copy_dataset, tmp_path, capsys, change, words):
    ds = copy_dataset()
    _shift(ds, "imu", change)
    refused(["estimate", str(ds), "-e", "dead_reckoning", "-o", str(tmp_path / "s.parquet")],
            capsys, [ds.parent], words)


def test_a_gap_in_a_recordings_times(copy_dataset, tmp_path, capsys):
    """A recording (its truth a reference that may cover less than its streams) whose last
    fix comes 1e8 s late: refused for the solution rows it would ask for, not allocated."""
    ds = copy_dataset()
    manifest = json.loads((ds / "manifest.json").read_text())
    manifest["reference"] = True
    (ds / "manifest.json").write_text(json.dumps(manifest))
    _shift(ds, "gnss_fix", lambda t: np.r_[t[:-1], t[-1] + 1e8])
    refused(["estimate", str(ds), "-e", "gnss_only", "-o", str(tmp_path / "s.parquet")],
            capsys, [ds.parent], "solution rows, more than one replay may hold")
