"""Solution files that used to end in a traceback or in quiet nonsense: text in a number
column, dates that are not dates, a GGA without a time, RTKLIB's rows at the Earth's centre,
a single row, negative standard deviations, latitudes, longitudes and heights that no position
has, infinite values, more rows than a replay may ask for. Each is one message and exit 2
naming the file, the line or row and the column, or (the RTKLIB and GGA rows without a
position or time) left out with a note."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from simulator.cli import main
from simulator.dataset.io import open_dataset
from simulator.earth import geodetic_to_ecef
from simulator.scoring import readers
from tests.reliability.checks import refused
from tests.reliability.drives import shared_dataset  # noqa: F401 (fixtures)


def _csv(dataset: Path, path: Path, rows: slice = slice(None), **changes) -> Path:
    truth = open_dataset(dataset).read("truth")
    frame = truth[["t", "lat", "lon", "alt", "vn", "ve", "vd", "roll", "pitch", "yaw"]]
    frame = frame.iloc[rows].copy()
    for column, value in changes.items():
        frame[column] = frame[column].astype(object)
        frame.iloc[len(frame) // 2, frame.columns.get_loc(column)] = value
    frame.to_csv(path, index=False)
    return path


def _pos(dataset: Path, path: Path, first_time: str, ecef_zero: bool = False) -> Path:
    truth = open_dataset(dataset).read("truth")
    lines = ["% program   : hostile test",
             "%  GPST          latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   "
             "sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio"]
    if ecef_zero:
        lines[1] = ("%  GPST          x-ecef(m)      y-ecef(m)      z-ecef(m)   Q  ns   sdx(m)"
                    "   sdy(m)   sdz(m)  sdxy(m)  sdyz(m)  sdzx(m) age(s)  ratio")
    gps = open_dataset(dataset).manifest["gps_time_start"]
    for i, row in enumerate(truth.iloc[::50].itertuples()):
        week, tow = gps["week"], gps["tow"] + row.t
        stamp = first_time if i == 0 else f"{week} {tow:.3f}"
        position = ("0.0000 0.0000 0.0000" if ecef_zero and i < 2 else
                    f"{row.lat:.9f} {row.lon:.9f} {row.alt:.4f}")
        if ecef_zero and i >= 2:
            x, y, z = np.ravel(geodetic_to_ecef(np.radians(row.lat), np.radians(row.lon),
                                                row.alt))
            position = f"{x:.4f} {y:.4f} {z:.4f}"
        lines.append(f"{stamp} {position} 1 8 0.1 0.1 0.2 0 0 0 0.0 0.0")
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("make, words", [
    (lambda ds, p: _csv(ds, p / "s.csv", lat="north"), "'north' is not a number"),
    (lambda ds, p: _csv(ds, p / "s.csv", rows=slice(0, 1)), "only one row"),
    (lambda ds, p: _csv(ds, p / "s.csv").parent, ""),
    (lambda ds, p: _pos(ds, p / "s.pos", "2024/13/45 99:00:00.000"), "not a date and time"),
    (lambda ds, p: _pos(ds, p / "s.pos", "week? 12.0"), "'week?' is not a number"),
])
def test_solution_refused(dataset, tmp_path, capsys, make, words):
    path = make(dataset, tmp_path)
    if path.is_dir():  # negative std: written separately (pandas writes the column here)
        frame = pd.read_csv(path / "s.csv")
        frame["std_n"] = -1.0
        frame.to_csv(path / "s.csv", index=False)
        path, words = path / "s.csv", "std_n has negative values"
    refused(["score", str(dataset), "--solution", str(path)], capsys, [dataset.parent], words)


def test_parquet_times_as_dates(dataset, tmp_path, capsys):
    frame = pd.read_csv(_csv(dataset, tmp_path / "s.csv"))
    frame["t"] = pd.to_datetime(frame["t"], unit="s")
    frame.to_parquet(tmp_path / "s.parquet")
    refused(["score", str(dataset), "--solution", str(tmp_path / "s.parquet")], capsys,
            [dataset.parent], "column t holds datetime64")


def test_rtklib_rows_at_the_earths_centre_have_no_position(dataset, tmp_path, capsys):
    path = _pos(dataset, tmp_path / "s.pos", "", ecef_zero=True)
    lines = path.read_text().splitlines()
    gps = open_dataset(dataset).manifest["gps_time_start"]
    lines[2] = f"{gps['week']} {gps['tow']:.3f}" + lines[2]
    path.write_text("\n".join(lines) + "\n")
    assert main(["score", str(dataset), "--solution", str(path), "--json",
                 str(tmp_path / "s.json")]) == 0
    err = capsys.readouterr().err
    assert "2 row(s) at the Earth's centre" in err
    vertical = pd.read_json(tmp_path / "s.json")["s"]["vertical"]["max"]
    assert vertical < 1.0  # not 6370 km


def test_gga_without_time_left_out(dataset, tmp_path, capsys):
    nmea = tmp_path / "d.nmea"
    assert main(["export", str(dataset), "--nmea", str(nmea)]) == 0
    lines = nmea.read_text().splitlines()
    gga = next(i for i, line in enumerate(lines) if line.startswith("$GPGGA"))
    fields = lines[gga].split("*")[0].split(",")
    fields[1] = ""
    body = ",".join(fields)[1:]
    checksum = 0
    for char in body:
        checksum ^= ord(char)
    lines[gga] = f"${body}*{checksum:02X}"
    nmea.write_text("\r\n".join(lines) + "\r\n")
    assert main(["score", str(dataset), "--solution", str(nmea)]) == 0
    assert "1 GGA sentence(s) without a time left out" in capsys.readouterr().err


def _pos_with(dataset: Path, path: Path, row: int | None = None, field: int = 0,
              value: str = "") -> Path:
    """The RTKLIB file of ``_pos`` with field ``field`` of data row ``row`` replaced."""
    _pos(dataset, path, "")
    lines = path.read_text().splitlines()
    gps = open_dataset(dataset).manifest["gps_time_start"]
    lines[2] = f"{gps['week']} {gps['tow']:.3f}" + lines[2]
    if row is not None:
        fields = lines[2 + row].split()
        fields[field] = value
        lines[2 + row] = " ".join(fields)
    path.write_text("\n".join(lines) + "\n")
    return path


# (file maker, the line or row the message names, its words): the middle row of a CSV is on
# line len // 2 + 2 (after the header); the pos file's data starts on line 3
@pytest.mark.parametrize("make, words", [
    (lambda ds, p: _csv(ds, p / "s.csv", lat=95.0), "lat = 95 lies outside [-90, 90]"),
    (lambda ds, p: _csv(ds, p / "s.csv", lon=-200.0), "lon = -200 lies outside [-180, 360]"),
    (lambda ds, p: _csv(ds, p / "s.csv", alt=2e5), "alt = 200000 lies outside"),
    (lambda ds, p: _csv(ds, p / "s.csv", vn="inf"), "vn = inf is not finite"),
    (lambda ds, p: _csv(ds, p / "s.csv", yaw="-Infinity"), "yaw = -inf is not finite"),
    (lambda ds, p: _pos_with(ds, p / "s.pos", 3, 2, "-91.5"), "line 6: lat = -91.5 lies outside"),
    (lambda ds, p: _pos_with(ds, p / "s.pos", 4, 4, "inf"), "line 7: alt = inf is not finite"),
])
def test_solution_values_no_position_has_are_refused(dataset, tmp_path, capsys, make, words):
    path = make(dataset, tmp_path)
    if path.suffix == ".csv":
        middle = (len(pd.read_csv(path)) // 2) + 2
        words = f"line {middle}: {words}"
    column = words.split(": ")[-1].split(" =")[0]
    printed = refused(["score", str(dataset), "--solution", str(path)], capsys,
                      [dataset.parent, tmp_path], words)
    assert f"error: {path}: {column}: " in printed


def test_parquet_latitude_out_of_range_names_its_row(dataset, tmp_path, capsys):
    frame = pd.read_csv(_csv(dataset, tmp_path / "s.csv"))
    frame.loc[7, "lat"] = np.nan
    frame.loc[9, "lat"] = -90.5
    frame.to_parquet(tmp_path / "s.parquet")
    refused(["score", str(dataset), "--solution", str(tmp_path / "s.parquet")], capsys,
            [dataset.parent, tmp_path], "row 9: lat = -90.5 lies outside [-90, 90]")


def test_text_read_in_chunks_names_the_right_line(dataset, tmp_path, capsys, monkeypatch):
    """A cell that is not a number in a later chunk of the file is named by its own line."""
    monkeypatch.setattr(readers, "_CHUNK_ROWS", 7)
    path = _csv(dataset, tmp_path / "s.csv", pitch="level")
    line = next(i for i, text in enumerate(path.read_text().splitlines(), 1) if "level" in text)
    assert line > 2 * 7
    refused(["score", str(dataset), "--solution", str(path)], capsys, [dataset.parent],
            f"line {line}: 'level' is not a number")


@pytest.mark.parametrize("kind", ["csv", "pos", "parquet", "nmea"])
def test_solutions_longer_than_a_replay_are_refused_as_read(dataset, tmp_path, capsys,
                                                            monkeypatch, kind):
    """More rows than a replay may ask for (10 million, lowered here to 10): refused naming
    the bound, text files in the chunk that crosses it, Parquet from its metadata."""
    monkeypatch.setattr(readers, "MAX_SOLUTION_ROWS", 10)
    monkeypatch.setattr(readers, "_CHUNK_ROWS", 4)
    if kind == "nmea":
        path = tmp_path / "s.nmea"
        assert main(["export", str(dataset), "--nmea", str(path)]) == 0
    elif kind == "pos":
        path = _pos_with(dataset, tmp_path / "s.pos")
    else:
        path = _csv(dataset, tmp_path / "s.csv")
        if kind == "parquet":
            pd.read_csv(path).to_parquet(tmp_path / "s.parquet")
            path = tmp_path / "s.parquet"
    refused(["score", str(dataset), "--solution", str(path)], capsys, [dataset.parent],
            "more than 10 rows")


HEADER = "%  GPST          latitude(deg) longitude(deg)  height(m)   Q  ns\n"


@pytest.mark.parametrize("name, text, words", [
    ("empty.pos", HEADER, "the solution has no rows"),  # was an IndexError
    ("half.pos", HEADER.replace("longitude", "easting"), "neither latitude(deg)"),  # KeyError
    ("speeds.pos", HEADER.replace("ns", "ns vn(m/s) ve(m/s)") + "2300 1.0 37.5 127 10 1 5 0 0\n",
     "some of vn(m/s), ve(m/s), vu(m/s) but not all"),  # was a KeyError
    ("semicolons.csv", "t;lat;lon;alt;vn;ve;vd;roll;pitch;yaw\n0;37;127;0;0;0;0;0;0;0\n",
     "missing column(s) t, lat"),  # was "no rows"
    ("far.csv", "t,lat,lon,alt,vn,ve,vd,roll,pitch,yaw\n1e308,37,127,0,0,0,0,0,0,0\n"
     "1e308,37,127,0,0,0,0,0,0,0\n", "row 1 has t = 1e+308 s after t = 1e+308 s"),  # 309 digits
    ("cut.csv", "t,lat,lon,alt,vn,ve,vd,roll,pitch,yaw\n0,37,127,0,0,0,0,0,0,0\n\n"
     "1,37,127,0,0,0,0,0\n2,37,127,0,0,0,0,0,0,0\n",  # was NaN pitch and yaw, silently
     "line 4: 8 field(s) where the header names 10: no pitch, yaw"),
    ("quoted.csv", 't,lat,lon,alt,vn,ve,vd,roll,pitch,"yaw"\n0,37,127,0,0,0,0,0,0,0\n'
     '1,37,127,0,0,0,0,0,"0,0"\n', "line 3: 9 field(s) where the header names 10: no yaw"),
])
def test_malformed_solution_files(dataset, tmp_path, capsys, name, text, words):
    path = tmp_path / name
    path.write_text(text)
    refused(["score", str(dataset), "--solution", str(path)], capsys, [dataset.parent, tmp_path],
            words)
