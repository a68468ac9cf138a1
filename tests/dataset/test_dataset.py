"""Datasets on disk: SPEC section 5 layout, units in the Parquet metadata, byte-identical
regeneration, atomic writes, refusal to overwrite."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
import yaml

from simulator import columns as col
from simulator.cli import main
from simulator.dataset.events import events_table
from simulator.dataset.generate import generate_streams
from simulator.dataset.io import open_dataset
from simulator.dataset.parquet import read_table, write_table
from simulator.errors import InputError
from simulator.scenario import validate_data
from simulator.tables import as_frame

REPO = Path(__file__).resolve().parents[2]
QUICK = REPO / "scenarios" / "quickstart.yaml"


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("ds") / "quick"
    assert main(["generate", str(QUICK), "-o", str(out), "--seed", "5",
                 "--set", "sensors.imu.output=increment"]) == 0
    return out


def test_layout_and_manifest(dataset):
    ds = open_dataset(dataset)
    m = ds.manifest
    assert m["format"] == "landnav-dataset/1"
    assert m["seed"] == 5 and m["scenario"]["seed"] == 5
    assert "sensors.imu.output=increment" in m["overrides"]
    assert m["scenario"]["sensors"]["imu"]["output"] == "increment"
    assert m["gps_time_start"] == {"week": 2312, "tow": pytest.approx(3 * 86400 + 3 * 3600 + 18)}
    assert m["origin"] == {"lat": 37.5665, "lon": 126.978, "alt": 40.0}
    assert set(m["streams"]) == {"truth", "imu", "odometer", "baro", "gnss_fix", "gnss_raw",
                                 "gnss_nav", "truth_gnss", "truth_sensors", "events"}
    assert m["streams"]["imu"]["rate_hz"] == pytest.approx(100.0)
    assert m["sensors"]["imu"]["preset"] == "bosch-smi130"
    truth = ds.read("truth")
    assert list(truth.columns) == list(col.TRUTH)
    assert m["streams"]["truth"]["rows"] == len(truth)
    assert np.all(np.diff(truth.t) > 0)


def test_units_in_field_metadata(dataset):
    schema = pq.read_schema(dataset / "truth.parquet")
    units = {f.name: f.metadata[b"unit"].decode() for f in schema}
    assert units == col.TRUTH
    # the dataset's IMU writes increments: angle and velocity changes over each interval
    assert open_dataset(dataset).units("imu")["gyro_x"] == "rad"
    assert open_dataset(dataset).units("imu")["accel_x"] == "m/s"


def test_same_seed_gives_identical_files(dataset, tmp_path):
    again = tmp_path / "again"
    assert main(["generate", str(QUICK), "-o", str(again), "--seed", "5",
                 "--set", "sensors.imu.output=increment"]) == 0
    for name in ("truth.parquet", "imu.parquet", "odometer.parquet", "baro.parquet",
                 "gnss_fix.parquet", "gnss_raw.parquet", "truth_gnss.parquet", "events.parquet",
                 "truth_sensors.parquet", "manifest.json"):
        assert (again / name).read_bytes() == (dataset / name).read_bytes(), name


def test_refuses_to_overwrite_without_force(dataset, capsys):
    before = (dataset / "manifest.json").read_bytes()
    assert main(["generate", str(QUICK), "-o", str(dataset)]) == 2
    assert "--force" in capsys.readouterr().err
    assert (dataset / "manifest.json").read_bytes() == before


def test_force_replaces_and_leaves_no_temporaries(tmp_path):
    out = tmp_path / "ds"
    assert main(["generate", str(QUICK), "-o", str(out)]) == 0
    assert main(["generate", str(QUICK), "-o", str(out), "--force", "--seed", "9"]) == 0
    assert json.loads((out / "manifest.json").read_text())["seed"] == 9
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ds"]


def test_failed_generation_leaves_nothing(tmp_path, monkeypatch):
    """A write that fails (here every Parquet file, the truth written early in a worker thread
    included) leaves no output directory and no temporary one."""
    from simulator.dataset import generate as gen
    from simulator.dataset import parquet

    def boom(*args, **kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr(parquet, "write_table", boom)
    with pytest.raises(RuntimeError):
        gen.generate_dataset(__import__("simulator.scenario", fromlist=["x"]).load_scenario(
            QUICK), tmp_path / "ds")
    assert list(tmp_path.iterdir()) == []


def test_not_a_dataset(tmp_path, capsys):
    with pytest.raises(InputError, match="not a landnav dataset"):
        open_dataset(tmp_path)
    (tmp_path / "manifest.json").write_text("{broken")
    with pytest.raises(InputError, match="corrupt manifest"):
        open_dataset(tmp_path)


def test_corrupt_stream_file(dataset, tmp_path):
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(dataset, copy)
    (copy / "imu.parquet").write_bytes(b"not parquet at all")
    with pytest.raises(InputError, match="imu.parquet"):
        open_dataset(copy).read("imu")


def _no_gnss_scenario(path: Path) -> Path:
    """The quick-start drive (tunnel and estimators included) with an IMU, odometer, barometer
    and magnetometer and no GNSS."""
    data = yaml.safe_load(QUICK.read_text())
    data["sensors"] = {"imu": {"preset": "automotive", "rate": 100, "output": "increment"},
                       "odometer": {"preset": "abs-wheel-speed"},
                       "baro": {"preset": "bosch-bmp280"}, "mag": {"preset": "automotive"}}
    path.write_text(yaml.safe_dump(data))
    return path


def test_generate_without_gnss_and_faults_does_not_import_pandas(tmp_path):
    """Importing pandas is a third of the whole generation of an hour's drive: a scenario
    without GNSS and faults (but with a magnetometer) is generated without it, and reads back as
    before."""
    scenario, out = _no_gnss_scenario(tmp_path / "s.yaml"), tmp_path / "out"
    code = ("import sys\nfrom simulator.cli import main\n"
            f"assert main(['generate', {str(scenario)!r}, '-o', {str(out)!r}]) == 0\n"
            "print(sorted(m for m in sys.modules if m.split('.')[0] == 'pandas'))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            cwd=REPO, env={**os.environ, "PYTHONPATH": str(REPO)}, check=True)
    assert result.stdout.splitlines()[-1] == "[]"
    ds = open_dataset(out)
    assert set(ds.stream_names) == {"truth", "imu", "odometer", "baro", "mag", "events",
                                    "truth_sensors"}
    assert list(ds.read("truth").columns) == list(col.TRUTH)
    assert set(ds.read("truth")["zone"]) == {"", "tunnel"}
    assert ds.read("odometer")["ticks"].dtype == np.int64
    assert list(ds.read("events")["kind"]) == ["zone"]


def test_program_ends_generate_with_its_exit_code_and_complete_files(tmp_path):
    """``landnav generate`` ends without the interpreter's teardown: its exit code, its printed
    line and its files are those of a normal end; a bad scenario still exits with 2 and its
    message, and nothing is written."""
    scenario, out = _no_gnss_scenario(tmp_path / "s.yaml"), tmp_path / "out"
    run = [sys.executable, "-m", "simulator.cli", "generate"]
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    done = subprocess.run([*run, str(scenario), "-o", str(out)], capture_output=True,
                          text=True, cwd=REPO, env=env)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(f"wrote {out} ")
    manifest = json.loads((out / "manifest.json").read_text())
    rows = manifest["streams"]["imu"]["rows"]
    assert rows == int(manifest["duration"] * 100)  # 100 Hz increments over the whole drive
    assert open_dataset(out).read("imu").shape == (rows, 7)
    bad = subprocess.run([*run, str(tmp_path / "missing.yaml"), "-o", str(tmp_path / "no")],
                         capture_output=True, text=True, cwd=REPO, env=env)
    assert bad.returncode == 2
    assert "missing.yaml: file not found" in bad.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "s.yaml"]


def test_program_into_a_closed_pipe_ends_quietly(tmp_path):
    """``landnav generate ... | head -0``: the dataset is written, and the line that cannot be
    printed ends the program with code 1 and no traceback."""
    scenario, out = _no_gnss_scenario(tmp_path / "s.yaml"), tmp_path / "out"
    done = subprocess.Popen([sys.executable, "-m", "simulator.cli", "generate", str(scenario),
                             "-o", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            cwd=REPO, env={**os.environ, "PYTHONPATH": str(REPO)})
    done.stdout.close()
    stderr = done.stderr.read().decode()
    assert done.wait() == 1
    assert all(line.startswith("sensors: ") for line in stderr.splitlines())  # progress only
    assert open_dataset(out).has("imu")


def test_column_tables_and_dataframes_write_the_same_files(tmp_path):
    """The writer gives the same bytes for a stream whether it is a column table or the
    DataFrame of it (text, integers, NaN as null, empty tables)."""
    data = yaml.safe_load(_no_gnss_scenario(tmp_path / "s.yaml").read_text())
    tables = generate_streams(validate_data(data, "s.yaml"), False, frames=False).streams
    tables["nan"] = {"t": np.array([0.0, 1.0, 2.0]), "x": np.array([1.0, np.nan, 3.0])}
    tables["empty"] = events_table([])
    units = {"nan": {"t": "s", "x": "m"}, "empty": col.EVENTS}
    for name, table in tables.items():
        assert isinstance(table, dict)
        unit = units[name] if name in units else col.STREAMS[name][1]
        write_table(table, tmp_path / f"{name}-columns.parquet", unit)
        write_table(as_frame(table), tmp_path / f"{name}-frame.parquet", unit)
        assert ((tmp_path / f"{name}-columns.parquet").read_bytes()
                == (tmp_path / f"{name}-frame.parquet").read_bytes()), name
    assert read_table(tmp_path / "nan-columns.parquet")["x"].isna().tolist() == [False, True,
                                                                                  False]
