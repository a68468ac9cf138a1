"""Solutions from anywhere (issue 17, "what must be shown"): one RTKLIB solution of the
quickstart as RTKLIB wrote it (.pos with lat/lon/height in GPST, .pos with ECEF in UTC, NMEA)
and as Parquet and CSV scores the same within the formats' rounding; Parquet unit metadata is
honoured; solutions that cannot be the dataset's are refused with exit 2 and a likely cause."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from simulator.cli import main
from simulator.replay import write_solution
from simulator.scoring.readers import read_solution_file
from tests.scoring_helpers import offset_solution

DATA = Path(__file__).parent / "data"
REPO = Path(__file__).resolve().parents[2]


def _gps(ds) -> tuple[int, float]:
    g = ds.manifest["gps_time_start"]
    return g["week"], g["tow"]


def _score(ds, tmp_path: Path, *files: Path, extra: tuple[str, ...] = ()) -> dict:
    out = tmp_path / "scores.json"
    assert main(["score", str(ds.path), "--solution", *map(str, files), *extra,
                 "--json", str(out)]) == 0
    return json.loads(out.read_text())


def test_one_solution_in_five_formats_scores_the_same(quickstart, tmp_path, capsys):
    frame, _, uses_gnss = read_solution_file(DATA / "quickstart_llh_gpst.pos", _gps(quickstart))
    assert uses_gnss
    write_solution(frame, tmp_path / "as_parquet.parquet")
    frame.to_csv(tmp_path / "as_csv.csv", index=False)
    files = [DATA / "quickstart_llh_gpst.pos", DATA / "quickstart_xyz_utc.pos",
             DATA / "quickstart_rtklib.nmea", tmp_path / "as_parquet.parquet",
             tmp_path / "as_csv.csv"]
    scores = _score(quickstart, tmp_path, *files)
    assert "RTKLIB UTC solution" in capsys.readouterr().err
    reference = scores["quickstart_llh_gpst"]
    assert 0.5 < reference["horizontal"]["rms"] < 5.0  # an SPP solution of the drive
    for label, s in scores.items():
        # .pos: 1e-9 deg and 0.1 mm; NMEA: 1e-7 arc-minutes and 1 mm; ECEF: 0.1 mm
        for group, key in (("horizontal", "rms"), ("horizontal", "cep95"),
                           ("horizontal", "max"), ("vertical", "rms")):
            assert s[group][key] == pytest.approx(reference[group][key], abs=2e-3), label
        assert s["coverage"] == reference["coverage"], label
        assert s["rows"]["position"] == reference["rows"]["position"], label
    # the standard deviations of the .pos file survive into Parquet and CSV
    for label in ("as_parquet", "as_csv"):
        assert scores[label]["nees"]["position"] == pytest.approx(
            reference["nees"]["position"], rel=1e-9)


def _radians_table(sol: pd.DataFrame, units: dict[str, str]) -> pa.Table:
    table = pa.Table.from_pandas(sol, preserve_index=False)
    fields = [f.with_metadata({"unit": units[f.name]}) if f.name in units else f
              for f in table.schema]
    return table.cast(pa.schema(fields))


def test_radians_with_unit_metadata_score_as_degrees(quickstart, tmp_path, capsys):
    truth = quickstart.read("truth")
    sol = offset_solution(truth.iloc[::10], dpos=(2.0, 1.0, -1.0), datt_deg=(1.0, 2.0, 3.0))
    write_solution(sol, tmp_path / "spec.parquet")
    odd = sol.copy()
    odd[["lat", "lon"]] = np.radians(odd[["lat", "lon"]])
    odd[["roll", "pitch", "yaw"]] = np.degrees(odd[["roll", "pitch", "yaw"]])
    units = {"lat": "rad", "lon": "rad", "roll": "deg", "pitch": "deg", "yaw": "deg"}
    pq.write_table(_radians_table(odd, units), tmp_path / "odd.parquet")
    scores = _score(quickstart, tmp_path, tmp_path / "spec.parquet", tmp_path / "odd.parquet")
    err = capsys.readouterr().err
    assert "column lat in 'rad' (its unit metadata) converted to 'deg'" in err
    assert "column yaw in 'deg'" in err
    spec, converted = scores["spec"], scores["odd"]
    assert converted["horizontal"]["rms"] == pytest.approx(spec["horizontal"]["rms"], abs=1e-6)
    assert spec["horizontal"]["rms"] == pytest.approx(np.hypot(2.0, 1.0), abs=1e-4)
    assert converted["attitude"] == pytest.approx(spec["attitude"], abs=1e-9)


@pytest.mark.parametrize(("damage", "message"), [
    (lambda s: s.assign(lat=np.radians(s["lat"]), lon=np.radians(s["lon"])), "look like radians"),
    (lambda s: s.assign(lat=s["lat"] - 45.0), "another dataset"),
    (lambda s: s.assign(t=s["t"] + 270018.0), "GPS time of week"),
    (lambda s: s.assign(yaw=np.degrees(s["yaw"])), "yaw has values beyond 2 pi: degrees?"),
    (lambda s: s.iloc[:0], "the solution has no rows"),
])
def test_a_solution_that_cannot_be_the_datasets_exits_2(quickstart, tmp_path, capsys, damage,
                                                         message):
    truth = quickstart.read("truth")
    bad = damage(offset_solution(truth.iloc[::10]))
    path = tmp_path / "bad.csv"
    bad.to_csv(path, index=False)
    assert main(["score", str(quickstart.path), "--solution", str(path)]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and message in err and "Traceback" not in err


def test_solution_and_estimator_scored_together(quickstart, tmp_path):
    truth = quickstart.read("truth")
    path = tmp_path / "mine.csv"
    offset_solution(truth.iloc[::10], dpos=(1.0, 0.0, 0.0)).to_csv(path, index=False)
    scores = _score(quickstart, tmp_path, path, extra=("-e", "gnss_only"))
    assert set(scores) == {"mine", "gnss_only"}
    assert scores["mine"]["horizontal"]["rms"] == pytest.approx(1.0, abs=1e-5)


def test_sensor_errors_of_the_true_values_are_zero_and_of_zeros_the_true_rms(quickstart,
                                                                             tmp_path):
    truth, sensors = quickstart.read("truth"), quickstart.read("truth_sensors")
    sol = offset_solution(truth.iloc[::10])
    on_grid = np.isin(np.round(sol["t"], 6), np.round(sensors["t"], 6))
    sol = sol.loc[on_grid].reset_index(drop=True)
    true = sensors.set_index(np.round(sensors["t"], 6)).loc[np.round(sol["t"], 6)]
    names = ["gyro_bias_z", "accel_bias_x", "odometer_scale_factor", "clock_bias"]
    exact = sol.assign(**{n: true[n].to_numpy() for n in names})
    zeros = sol.assign(**dict.fromkeys(names, 0.0))
    write_solution(exact, tmp_path / "exact.parquet")
    write_solution(zeros, tmp_path / "zeros.parquet")
    scores = _score(quickstart, tmp_path, tmp_path / "exact.parquet", tmp_path / "zeros.parquet")
    for name in names:
        assert scores["exact"]["sensor_errors"][name] == {"rms": 0.0, "final": 0.0}
        values = true[name].to_numpy()
        values = values[np.isfinite(values)]
        assert scores["zeros"]["sensor_errors"][name]["rms"] == pytest.approx(
            np.sqrt(np.mean(values ** 2)), rel=1e-12)
        assert scores["zeros"]["sensor_errors"][name]["final"] == pytest.approx(-values[-1])


def test_module_class_is_found_from_the_current_directory(quickstart, tmp_path):
    """As a console script runs it: sys.path starts with the script's folder, not the current
    directory; the plug-in module lies in the current directory."""
    work = tmp_path / "work"
    work.mkdir()
    (work / "my_plugin.py").write_text(textwrap.dedent("""\
        from estimators.builtin.baselines import GnssOnly

        class Mine(GnssOnly):
            name = "mine"
        """))
    script = tmp_path / "bin" / "landnav_script.py"
    script.parent.mkdir()
    script.write_text("import sys\nfrom simulator.cli import main\nsys.exit(main())\n")
    result = subprocess.run(
        [sys.executable, str(script), "score", str(quickstart.path), "-e", "my_plugin:Mine"],
        cwd=work, capture_output=True, text=True, env={"PYTHONPATH": str(REPO), "PATH": ""})
    assert result.returncode == 0, result.stderr
    assert "my_plugin:Mine" in result.stdout or "mine" in result.stdout


def test_nmea_without_rmc_or_altitude_takes_the_dataset_date(tmp_path):
    """A bare GGA (no RMC, empty altitude): the date is the dataset's start date, UTC 03:00:10
    is GPS 03:00:28 (18 leap seconds), 10 s after a start at GPS week 2312, 270018 s."""
    body = "GPGGA,030010.00,3733.9903602,N,12658.6785914,E,1,06,1.0,,M,,M,,"
    checksum = 0
    for ch in body:
        checksum ^= ord(ch)
    path = tmp_path / "bare.nmea"
    path.write_text(f"${body}*{checksum:02X}\r\n")
    frame, _, _ = read_solution_file(path, (2312, 270018.0))
    assert frame["t"].tolist() == [pytest.approx(10.0)]
    assert frame["lat"].iloc[0] == pytest.approx(37 + 33.9903602 / 60, abs=1e-9)
    assert frame["lon"].iloc[0] == pytest.approx(126 + 58.6785914 / 60, abs=1e-9)
    assert np.isnan(frame["alt"].iloc[0]) and np.isnan(frame["vn"].iloc[0])
