"""Datasets on disk: SPEC section 5 layout, units in the Parquet metadata, byte-identical
regeneration, atomic writes, refusal to overwrite."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from simulator import columns as col
from simulator.cli import main
from simulator.dataset.io import open_dataset
from simulator.errors import InputError

REPO = Path(__file__).resolve().parents[1]
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
                                 "gnss_nav", "truth_gnss", "events"}
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
    assert open_dataset(dataset).units("imu")["gyro_x"] == "rad/s"


def test_same_seed_gives_identical_files(dataset, tmp_path):
    again = tmp_path / "again"
    assert main(["generate", str(QUICK), "-o", str(again), "--seed", "5",
                 "--set", "sensors.imu.output=increment"]) == 0
    for name in ("truth.parquet", "imu.parquet", "odometer.parquet", "baro.parquet",
                 "gnss_fix.parquet", "gnss_raw.parquet", "truth_gnss.parquet", "events.parquet",
                 "manifest.json"):
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
    from simulator.dataset import generate as gen

    def boom(*args, **kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr(gen, "write_dataset", boom)
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
