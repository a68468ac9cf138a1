"""Corrupt datasets on every command that reads one (estimate, score, export): a missing or
non-numeric column, manifest entries of the wrong type, stream files outside the folder, events
without an end, IMU samples without values, truth whose time runs backwards or whose position
is none. Each gives exit 2,
one message naming the file and what is wrong, no traceback, and nothing written."""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from simulator.cli import main
from tests.reliability.drives import generated_dataset, straight_drive

SCENARIO = straight_drive(150, sensors="  imu: {preset: ideal, rate: 50}\n"
                                       "  odometer: {rate: 10}\n"
                                       "  gnss: {rate: 1, outputs: [fix, raw]}\n",
                          tail="faults:\n  - {kind: gnss_outage, start: 8, duration: 3}\n")


@pytest.fixture(scope="module")
def pristine(tmp_path_factory) -> Path:
    return generated_dataset(tmp_path_factory.mktemp("hostile_ds"), SCENARIO)


def _rewrite(path: Path, change: Callable[[pa.Table], pa.Table]) -> None:
    pq.write_table(change(pq.read_table(path)), path)


def _set_column(table: pa.Table, name: str, values: object) -> pa.Table:
    i = table.schema.get_field_index(name)
    return table.set_column(i, name, pa.array(values))


def _manifest(ds: Path, change: Callable[[dict], None]) -> None:
    manifest = json.loads((ds / "manifest.json").read_text())
    change(manifest)
    (ds / "manifest.json").write_text(json.dumps(manifest))


def _imu_nan(ds: Path) -> None:
    def change(t: pa.Table) -> pa.Table:
        gx = t.column("gyro_x").to_numpy().copy()
        gx[20:30] = np.nan
        return _set_column(t, "gyro_x", gx)
    _rewrite(ds / "imu.parquet", change)


def _truth_backwards(ds: Path) -> None:
    def change(t: pa.Table) -> pa.Table:
        times = t.column("t").to_numpy().copy()
        times[40] = times[5]
        return _set_column(t, "t", times)
    _rewrite(ds / "truth.parquet", change)


CORRUPTIONS: dict[str, tuple[Callable[[Path], None], str]] = {
    "imu column missing": (lambda ds: _rewrite(ds / "imu.parquet", lambda t: t.drop(["t"])),
                           "imu.parquet: corrupt imu stream: column(s) t missing"),
    "odometer speed as text": (lambda ds: _rewrite(
        ds / "odometer.parquet",
        lambda t: _set_column(t, "speed", [str(v) for v in t.column("speed").to_pylist()])),
        "column speed holds str values, not numbers"),
    "imu samples without value": (_imu_nan, "sample(s) have no value, the first at row 20"),
    "truth time backwards": (_truth_backwards, "truth.parquet: corrupt truth stream: time runs "
                                               "backwards at row 40"),
    "events without t_end": (lambda ds: _rewrite(ds / "events.parquet",
                                                 lambda t: t.drop(["t_end"])),
                             "column(s) t_end missing"),
    "gnss_fix course missing": (lambda ds: _rewrite(ds / "gnss_fix.parquet",
                                                    lambda t: t.drop(["course"])),
                                "column(s) course missing"),
    "stream file outside": (lambda ds: _manifest(
        ds, lambda m: m["streams"]["imu"].update(file="../../etc/passwd")),
        "is not a file inside the dataset folder"),
    "stream file absolute": (lambda ds: _manifest(
        ds, lambda m: m["streams"]["imu"].update(file="/etc/passwd")),
        "is not a file inside the dataset folder"),
    "stream entry not a mapping": (lambda ds: _manifest(
        ds, lambda m: m["streams"].update(imu="imu.parquet")),
        "streams.imu.file: missing or not a file name"),
    "gps week as text": (lambda ds: _manifest(
        ds, lambda m: m["gps_time_start"].update(week="2300")),
        "gps_time_start.week: not an integer"),
    "gps start as list": (lambda ds: _manifest(ds, lambda m: m.update(gps_time_start=[1, 2])),
                          "gps_time_start: not a mapping (got [1, 2])"),  # was a TypeError
    "origin lat as list": (lambda ds: _manifest(ds, lambda m: m["origin"].update(lat=[1])),
                           "origin.lat: not an integer or a number"),
    "not a parquet file": (lambda ds: (ds / "imu.parquet").write_bytes(b"PAR1 garbage"),
                           "imu.parquet: not a readable Parquet file"),
    "manifest not json": (lambda ds: (ds / "manifest.json").write_text("{oops"),
                          "corrupt manifest"),
    "manifest a list": (lambda ds: (ds / "manifest.json").write_text("[]"),
                        "not a landnav-dataset/1 manifest"),
    "imu empty": (lambda ds: _rewrite(ds / "imu.parquet", lambda t: t.slice(0, 0)),
                  "corrupt imu stream: no samples"),
    "imu sample of 1e300": (lambda ds: _rewrite(ds / "imu.parquet", lambda t: _set_column(
        t, "accel_x", np.r_[t.column("accel_x").to_numpy()[:-1], 1e300])),
        "accel_x = 1e+300 at row"),
    "imu unit deg/s": (lambda ds: _rewrite(ds / "imu.parquet", lambda t: t.cast(pa.schema([
        f.with_metadata({"unit": "deg/s" if f.name.startswith("gyro") else
                         (f.metadata or {}).get(b"unit", b"").decode()}) for f in t.schema]))),
        "column gyro_x is in 'deg/s'"),
    "scenario sensors as text": (lambda ds: _manifest(
        ds, lambda m: m["scenario"].update(sensors="imu")),
        "scenario.sensors: not a mapping"),
    "broadcast ionosphere as text": (lambda ds: _manifest(
        ds, lambda m: m["sensors"]["gnss"].update(broadcast_iono="x")),
        "sensors.gnss.broadcast_iono: not a mapping"),
    "gps week -5": (lambda ds: _manifest(ds, lambda m: m["gps_time_start"].update(week=-5)),
                    "-5 is not a GPS week"),
    "gnss_fix latitude 1e300": (lambda ds: _rewrite(ds / "gnss_fix.parquet", lambda t: _set_column(
        t, "lat", np.r_[1e300, t.column("lat").to_numpy()[1:]])),
        "row 0 holds 1e+300, outside [-90, 90]"),
    "gnss_raw pseudorange infinite": (lambda ds: _rewrite(ds / "gnss_raw.parquet",
                                                          lambda t: _set_column(
        t, "pseudorange", np.r_[np.inf, t.column("pseudorange").to_numpy()[1:]])),
        "it cannot be exported"),
    # scored as 1232 km of horizontal error, exit 0, before
    "truth latitude 1e300": (lambda ds: _rewrite(ds / "truth.parquet", lambda t: _set_column(
        t, "lat", np.r_[t.column("lat").to_numpy()[:5], 1e300, t.column("lat").to_numpy()[6:]])),
        "truth.parquet: corrupt truth stream: lat = 1e+300 at row 5"),
}
# which command reads which stream
COMMANDS = {
    "estimate": lambda ds, out: ["estimate", str(ds), "-e", "dead_reckoning", "-o",
                                 str(out / "s.parquet")],
    "score": lambda ds, out: ["score", str(ds), "-e", "gnss_only", "--json",
                              str(out / "s.json")],
    "export": lambda ds, out: ["export", str(ds), "--rinex", str(out / "rinex"), "--nmea",
                               str(out / "x.nmea")],
}
READS = {
    "imu column missing": ("estimate",), "odometer speed as text": ("estimate",),
    "imu samples without value": ("estimate",), "truth time backwards": ("score",),
    "events without t_end": ("score",), "gnss_fix course missing": ("score",),
    "gps week as text": ("export",), "origin lat as list": ("export",),
    "gps start as list": ("score", "export"),
    "not a parquet file": ("estimate",), "imu empty": ("estimate",),
    "imu sample of 1e300": ("estimate",), "imu unit deg/s": ("estimate",),
    "broadcast ionosphere as text": ("export",), "gps week -5": ("export",),
    "gnss_fix latitude 1e300": ("export",), "gnss_raw pseudorange infinite": ("export",),
    "truth latitude 1e300": ("score",),
}


@pytest.mark.parametrize("case, command", [
    (case, command) for case in CORRUPTIONS
    for command in READS.get(case, tuple(COMMANDS))])
def test_corrupt_dataset_refused(pristine, tmp_path, capsys, case, command):
    ds = tmp_path / "ds"
    shutil.copytree(pristine, ds)
    corrupt, words = CORRUPTIONS[case]
    corrupt(ds)
    out = tmp_path / "out"
    out.mkdir()
    code = main(COMMANDS[command](ds, out))
    printed = capsys.readouterr()
    text = printed.err + printed.out
    assert code == 2, text
    assert "Traceback" not in text
    assert words in text, text
    assert str(ds) in text
    assert list(out.iterdir()) == []
