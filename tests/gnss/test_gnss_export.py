"""``landnav export``: RINEX 3.04 observation and navigation files read back with georinex
(an independent reader) give the dataset's values; NMEA sentences parse with pynmeagps with
valid checksums and carry the fixes."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pandas as pd
import pytest
import yaml

from simulator.cli import main
from simulator.dataset.export import export_nmea, export_rinex
from simulator.dataset.io import open_dataset
from simulator.errors import InputError
from simulator.geoid import geoid_undulation_m
from simulator.gnss.navfiles import read_rinex_nav
from simulator.gnss.nmea import nmea_checksum

SCENARIO = {
    "name": "export-test",
    "seed": 5,
    "start": {"utc": "2024-05-01T03:00:00Z", "lat": 37.5665, "lon": 126.978, "alt": 40.0,
              "heading": 90.0},
    "trajectory": {"kind": "segments", "segments": [
        {"stop": {"duration": 5}}, {"accelerate": {"to_speed": 10.0, "accel": 2.0}},
        {"straight": {"length": 100, "zone": "tunnel"}}, {"straight": {"length": 100}}]},
    "environment": {"zones": {"tunnel": {"sky": "none"}}},
    "sensors": {"imu": {"preset": "ideal", "rate": 10}, "gnss": {"rate": 1}},
}


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    root = tmp_path_factory.mktemp("export")
    (root / "s.yaml").write_text(yaml.safe_dump(SCENARIO))
    assert main(["generate", str(root / "s.yaml"), "-o", str(root / "ds")]) == 0
    assert main(["export", str(root / "ds"), "--rinex", str(root / "rinex"),
                 "--nmea", str(root / "out.nmea")]) == 0
    return root, open_dataset(root / "ds")


def test_rinex_observations_read_back_with_georinex(exported):
    georinex = pytest.importorskip("georinex")
    root, ds = exported
    raw = ds.read("gnss_raw")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        obs = georinex.load(root / "rinex" / "ds.obs")
    frame = obs.to_dataframe().reset_index().dropna(subset=["C1C"])
    t0 = pd.Timestamp("2024-05-01T03:00:00") + pd.Timedelta(seconds=18)  # GPS = UTC + 18 s
    # the epochs are the receiver's time tags: the true time plus its clock error
    tag = (frame["time"] - t0).dt.total_seconds()
    frame["t"] = tag.round(2)
    clock = ds.read("truth_gnss").groupby("t")["receiver_clock"].first()
    np.testing.assert_allclose(tag - frame["t"], clock.loc[frame["t"]].to_numpy() / 299792458.0,
                               atol=1.5e-6)  # georinex keeps epochs to the microsecond
    frame["sv"] = frame["sv"].str[1:].astype(int)
    merged = raw.merge(frame, on=["t", "sv"], how="outer", indicator=True)
    assert (merged["_merge"] == "both").all() and len(merged) == len(raw) > 100
    # identical to the file format's resolution (F14.3)
    for ours, theirs in (("pseudorange", "C1C"), ("carrier_phase", "L1C"), ("doppler", "D1C"),
                         ("cn0", "S1C")):
        assert np.abs(merged[ours] - merged[theirs]).max() <= 0.0005 + 1e-9


BASE_SCENARIO = {
    **SCENARIO, "name": "export-base", "environment": {"zones": {}},
    "trajectory": {"kind": "segments", "segments": [{"stop": {"duration": 60}}]},
    "sensors": {"gnss": {"rate": 1, "preset": "geodetic", "outputs": ["raw"]},
                "gnss_base": {"offset": {"east": 2000.0, "north": 500.0, "up": 10.0}}},
}


@pytest.fixture(scope="module")
def exported_with_base(tmp_path_factory):
    root = tmp_path_factory.mktemp("export_base")
    (root / "s.yaml").write_text(yaml.safe_dump(BASE_SCENARIO))
    assert main(["generate", str(root / "s.yaml"), "-o", str(root / "ds")]) == 0
    assert main(["export", str(root / "ds"), "--rinex", str(root / "rinex")]) == 0
    return root, open_dataset(root / "ds")


@pytest.mark.parametrize(("stream", "file", "truth"), [
    ("gnss_raw", "ds.obs", "truth_gnss"), ("gnss_base_raw", "ds_base.obs", "truth_gnss_base")])
def test_rinex_of_every_signal_and_the_base_reads_back_with_georinex(exported_with_base, stream,
                                                                      file, truth):
    """Rover and base files carry C, L, D, S of GPS 1C, 2W and 5Q (the geodetic preset) with
    the LLI; georinex reads back the dataset's values to the format's resolution."""
    georinex = pytest.importorskip("georinex")
    root, ds = exported_with_base
    raw = ds.read(stream)
    header = (root / "rinex" / file).read_text().split("END OF HEADER")[0]
    assert "C1C L1C D1C S1C C2W L2W D2W S2W C5Q L5Q D5Q S5Q" in header
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        obs = georinex.load(root / "rinex" / file, useindicators=True)
    frame = obs.to_dataframe().reset_index()
    t0 = pd.Timestamp("2024-05-01T03:00:00") + pd.Timedelta(seconds=18)
    frame["t"] = (frame["time"] - t0).dt.total_seconds().round(2)
    frame["sv"] = frame["sv"].str[1:].astype(int)
    for signal in ("1C", "2W", "5Q"):
        ours = raw[raw["signal"] == signal]
        theirs = frame.dropna(subset=[f"C{signal}"])
        merged = ours.merge(theirs, on=["t", "sv"], how="outer", indicator=True)
        assert (merged["_merge"] == "both").all() and len(merged) > 100
        for column, code in (("pseudorange", "C"), ("carrier_phase", "L"), ("doppler", "D"),
                             ("cn0", "S")):
            assert np.abs(merged[column] - merged[f"{code}{signal}"]).max() <= 0.0005 + 1e-9
        if signal != "5Q":  # georinex leaves out the LLI of the last signal (a pilot: bit 0
            # only, at each arc's first epoch)
            lli = merged[f"L{signal}lli"].fillna(0).astype(int)
            np.testing.assert_array_equal(lli, merged["lli"] & 3)
    manifest = json.loads((ds.path / "manifest.json").read_text())
    assert manifest["gnss_base"]["x"] == pytest.approx(
        ds.read("truth_gnss_base")["antenna_x"].iloc[0])
    assert ds.has(truth)


def test_rinex_navigation_reads_back_with_georinex_and_our_reader(exported):
    georinex = pytest.importorskip("georinex")
    root, ds = exported
    nav = ds.read("gnss_nav").sort_values("sv").reset_index(drop=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        theirs = georinex.load(root / "rinex" / "ds.nav").to_dataframe().reset_index()
    theirs = theirs.dropna(subset=["sqrtA"]).sort_values("sv").reset_index(drop=True)
    assert len(theirs) == len(nav)
    pairs = {"af0": "SVclockBias", "af1": "SVclockDrift", "m0": "M0", "e": "Eccentricity",
             "sqrt_a": "sqrtA", "toe": "Toe", "omega0": "Omega0", "i0": "Io",
             "omega": "omega", "omega_dot": "OmegaDot", "week": "GPSWeek", "tgd": "TGD"}
    for ours, name in pairs.items():
        np.testing.assert_allclose(theirs[name], nav[ours], rtol=1e-12, atol=1e-300)
    back = read_rinex_nav(root / "rinex" / "ds.nav").sort_values("sv").reset_index(drop=True)
    pd.testing.assert_frame_equal(back[nav.columns], nav, check_dtype=False, rtol=1e-12)
    iono = ds.manifest["sensors"]["gnss"]["broadcast_iono"]
    np.testing.assert_allclose(back.attrs["iono_alpha"], iono["alpha"], rtol=1e-4)
    np.testing.assert_allclose(back.attrs["iono_beta"], iono["beta"], rtol=1e-4)


def test_nmea_sentences_parse_with_valid_checksums(exported):
    pynmeagps = pytest.importorskip("pynmeagps")
    root, ds = exported
    fix = ds.read("gnss_fix")
    lines = (root / "out.nmea").read_bytes().decode("ascii").split("\r\n")[:-1]
    parsed = [pynmeagps.NMEAReader.parse(line, validate=pynmeagps.VALCKSUM) for line in lines]
    kinds = pd.Series([p.msgID for p in parsed])
    assert set(kinds) == {"GGA", "RMC", "VTG", "GSA", "GSV"}
    assert (kinds == "GGA").sum() == len(fix)
    for line in lines:
        body, cs = line[1:].split("*")
        assert cs == nmea_checksum(body)
    gga = [p for p in parsed if p.msgID == "GGA"]
    rmc = [p for p in parsed if p.msgID == "RMC"]
    with_fix = fix["fix"].to_numpy() == 2
    assert with_fix.any() and (~with_fix).any()  # the tunnel gives epochs without a fix
    lat = np.array([g.lat if g.quality else np.nan for g in gga], dtype=float)
    lon = np.array([g.lon if g.quality else np.nan for g in gga], dtype=float)
    np.testing.assert_allclose(lat[with_fix], fix["lat"][with_fix], atol=2e-8)
    np.testing.assert_allclose(lon[with_fix], fix["lon"][with_fix], atol=2e-8)
    assert [g.quality for g in gga] == [1 if f else 0 for f in with_fix]
    # altitude above the geoid plus the EGM96 separation is the fix's ellipsoidal height
    sep = np.array([g.sep if g.quality else np.nan for g in gga], dtype=float)
    alt = np.array([g.alt if g.quality else np.nan for g in gga], dtype=float)
    np.testing.assert_allclose(sep[with_fix], geoid_undulation_m(lat, lon)[with_fix], atol=0.006)
    np.testing.assert_allclose((alt + sep)[with_fix], fix["alt"][with_fix], atol=0.011)
    assert [g.numSV for g in gga] == fix["num_sats"].tolist()
    assert [r.status for r in rmc] == ["A" if f else "V" for f in with_fix]
    speed = np.array([r.spd if r.spd != "" else np.nan for r in rmc], dtype=float)
    np.testing.assert_allclose(speed[with_fix] * 1852 / 3600, fix["speed"][with_fix], atol=1e-3)


def test_nmea_epoch_without_a_finite_position_is_no_fix(exported):
    """A fix row flagged as a fix whose latitude is NaN (a faulted or hand-edited stream) gives
    GGA quality 0 and RMC status V with empty position fields, not quality 1 with no position."""
    from simulator.gnss.nmea import nmea_sentences

    _, ds = exported
    fix = ds.read("gnss_fix").iloc[:3].copy()
    fix["fix"] = 2
    fix.loc[fix.index[1], "lat"] = np.nan
    gga = [line for line in nmea_sentences(fix, ds.read("gnss_raw"), 2000, 0.0)
           if line.startswith("$GPGGA")]
    rmc = [line for line in nmea_sentences(fix, ds.read("gnss_raw"), 2000, 0.0)
           if line.startswith("$GPRMC")]
    assert [g.split(",")[6] for g in gga] == ["1", "0", "1"]
    assert gga[1].split(",")[2:6] == ["", "", "", ""]
    assert [r.split(",")[2] for r in rmc] == ["A", "V", "A"]


def test_library_export_equals_the_command(exported, tmp_path):
    """``simulator.dataset.export`` (what notebooks call) writes the files ``landnav export``
    writes, byte for byte apart from the RINEX header's creation time; refuses to overwrite
    without ``force``; names the caller's option for a dataset without the streams."""
    root, dataset = exported
    obs, nav = export_rinex(dataset, tmp_path)
    assert (obs.name, nav.name) == ("ds.obs", "ds.nav")

    def body(path):
        return [line for line in path.read_text().splitlines() if "PGM / RUN BY" not in line]

    assert body(obs) == body(root / "rinex" / "ds.obs")
    assert body(nav) == body(root / "rinex" / "ds.nav")
    nmea = export_nmea(dataset, tmp_path / "out.nmea")
    assert nmea.read_text() == (root / "out.nmea").read_text()
    with pytest.raises(InputError):
        export_rinex(dataset, tmp_path)
    assert export_rinex(dataset, tmp_path, force=True) == (obs, nav)
    (tmp_path / "no_raw").mkdir()
    for f in dataset.path.iterdir():
        if f.name != "gnss_raw.parquet":
            (tmp_path / "no_raw" / f.name).write_bytes(f.read_bytes())
    manifest = tmp_path / "no_raw" / "manifest.json"
    data = json.loads(manifest.read_text())
    data["streams"].pop("gnss_raw")
    manifest.write_text(json.dumps(data))
    with pytest.raises(InputError, match="my_option needs the 'gnss_raw' stream"):
        export_rinex(open_dataset(tmp_path / "no_raw"), tmp_path / "x", option="my_option")
