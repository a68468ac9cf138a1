"""Real recordings imported as datasets (refdata 3a comma2k19, 3b GSDC 2022): the streams
against the source files, the frame and time conventions against independent evidence in the
recordings themselves, estimators run and scored against the reference, an estimator refused by
name when the recording lacks what it needs, and variants of the formats (optional columns
absent, another column order, no magnetometer) imported from the documentation's layout."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from simulator.cli import main
from simulator.dataset.io import open_dataset
from tests.conftest import SHARED

COMMA = Path("vehicle") / "comma2k19_rav4_2018-08-02_seg40"
GSDC = Path("vehicle") / "gsdc2022_pixel_2021-04-29_mtv"


def _refdata() -> Path:
    if not (SHARED / "refdata").is_dir():
        pytest.skip(f"reference data not available: {SHARED / 'refdata'} is absent "
                    "(a user's clone has no ../shared; CI has it)")
    return SHARED / "refdata"


@pytest.fixture(scope="module")
def comma(tmp_path_factory):
    source = _refdata() / COMMA
    out = tmp_path_factory.mktemp("c2k") / "dataset"
    assert main(["import", "comma2k19", str(source), "-o", str(out)]) == 0
    return source, open_dataset(out)


@pytest.fixture(scope="module")
def gsdc(tmp_path_factory):
    source = _refdata() / GSDC
    out = tmp_path_factory.mktemp("gsdc") / "dataset"
    assert main(["import", "gsdc", str(source / "device_gnss.csv"),
                 str(source / "ground_truth.csv"), "-o", str(out)]) == 0
    return source, open_dataset(out)


def test_comma2k19_streams_match_the_segment(comma):
    source, dataset = comma
    manifest = dataset.manifest
    assert manifest["reference"] is True and "global_pose" in manifest["reference_source"]
    assert "ephemeris" in manifest["lacks"]["gnss_raw"]
    accel = np.load(source / "processed_log/IMU/accelerometer/value")
    imu = dataset.read("imu")
    np.testing.assert_array_equal(imu[["accel_x", "accel_y", "accel_z"]].to_numpy(), accel)
    # every stream keeps its own timestamps: the IMU's spacing is the log's, not resampled
    boot = np.load(source / "processed_log/IMU/accelerometer/t")
    np.testing.assert_allclose(np.diff(imu["t"].to_numpy()), np.diff(boot), atol=1e-9)
    raw = np.load(source / "processed_log/GNSS/raw_gnss_ublox/value")
    assert len(dataset.read("gnss_raw")) == len(raw)
    for name in ("imu", "odometer", "gnss_fix", "gnss_raw", "truth", "mag"):
        t = dataset.read(name)["t"].to_numpy()
        assert t.min() >= 0.0 and np.all(np.diff(t) >= 0)
    # the specific force's sign: a car on a road feels about -g on its down axis
    assert -10.5 < imu["accel_z"].mean() < -9.0
    # the magnetometer in tesla (the log's values are of microtesla size)
    field = np.linalg.norm(dataset.read("mag")[["mag_x", "mag_y", "mag_z"]], axis=1)
    assert 20e-6 < np.median(field) < 70e-6


def test_comma2k19_reference_and_fix_conventions(comma):
    """Independent evidence for the conventions chosen: the reference's velocity in its own
    body frame points forward (the quaternion turns body vectors into ECEF), the receiver's
    altitude is ellipsoidal (it agrees with the pose's ellipsoidal height, where the geoid is
    32 m below the ellipsoid), and the fixes' epochs agree with the reference's times."""
    _, dataset = comma
    truth = dataset.read("truth")
    from simulator.earth import ned_to_body

    v_body = ned_to_body(truth["roll"].to_numpy(), truth["pitch"].to_numpy(),
                         truth["yaw"].to_numpy(), truth[["vn", "ve", "vd"]].to_numpy())
    assert np.all(v_body[:, 0] > 0.98 * truth["speed"].to_numpy())
    assert np.all(np.abs(v_body[:, 1]) < 0.05 * truth["speed"].to_numpy() + 0.2)
    fix = dataset.read("gnss_fix")
    t = fix["t"].to_numpy()
    alt_ref = np.interp(t, truth["t"], truth["alt"])
    assert abs(np.median(fix["alt"] - alt_ref)) < 5.0
    # the fixes are stamped with their epochs (UTC ms of the fix), the reference with its
    # camera frames' GPS times: the two agree to about 0.1 s (the best fit is 0.12 s; stamped
    # at their arrival in the log the fixes would be 0.2 s later)
    delays = np.arange(-0.5, 0.51, 0.02)
    misfit = [np.median(np.hypot(
        np.radians(fix["lat"] - np.interp(t + d, truth["t"], truth["lat"])) * 6.371e6,
        np.radians(fix["lon"] - np.interp(t + d, truth["t"], truth["lon"])) * 5.04e6))
        for d in delays]
    assert -0.05 < delays[int(np.argmin(misfit))] < 0.2


def test_comma2k19_ins_runs_against_the_reference_and_tc_is_refused(comma, tmp_path, capsys):
    _, dataset = comma
    scores = tmp_path / "scores.json"
    assert main(["score", str(dataset.path), "-e", "ins_odo_ekf", "-e", "gnss_only",
                 "--json", str(scores)]) == 0
    out = capsys.readouterr().out
    assert "scored against a reference" in out
    result = json.loads(scores.read_text())
    # the receiver's own fixes are about 2 m from comma's pose; the INS/odometer filter must
    # not be worse than twice that
    assert result["gnss_only"]["horizontal"]["rms"] < 4.0
    assert result["ins_odo_ekf"]["horizontal"]["rms"] < 2 * result["gnss_only"]["horizontal"][
        "rms"]
    assert main(["estimate", str(dataset.path), "-e", "tc_ekf", "-o",
                 str(tmp_path / "tc.parquet")]) == 2
    err = capsys.readouterr().err
    assert "broadcast ephemeris" in err and "Traceback" not in err
    assert not (tmp_path / "tc.parquet").exists()


def test_gsdc_streams_and_the_range_identity(gsdc):
    """The raw rows against the CSV, and SPEC section 5's identity at the reference position:
    pseudorange + sat_clock - iono - tropo - |R r_s - r| is one clock per system and band up
    to the phone's noise (median absolute deviation under 10 m)."""
    source, dataset = gsdc
    csv = pd.read_csv(source / "device_gnss.csv")
    raw = dataset.read("gnss_raw")
    measured = csv[(csv["MessageType"] == "Raw") & csv["RawPseudorangeMeters"].notna()]
    assert len(raw) == len(measured)
    np.testing.assert_array_equal(np.sort(raw["pseudorange"]),
                                  np.sort(measured["RawPseudorangeMeters"]))
    assert set(raw["system"]) <= {"G", "R", "E", "C", "J"}
    from estimators.toolbox.gnss_model import predict
    from simulator.earth import geodetic_to_ecef

    truth = dataset.read("truth")
    first = raw[raw["t"] == raw["t"].iloc[0]]
    row = truth.iloc[int(np.argmin(np.abs(truth["t"] - first["t"].iloc[0])))]
    r = geodetic_to_ecef(np.radians(row["lat"]), np.radians(row["lon"]), row["alt"]).ravel()
    geometric, _, _ = predict(first[["sat_x", "sat_y", "sat_z"]].to_numpy(),
                              first[["sat_vx", "sat_vy", "sat_vz"]].to_numpy(), r, np.zeros(3))
    residual = (first["pseudorange"] + first["sat_clock"] - first["iono"] - first["tropo"]
                - geometric).to_numpy()
    band = first["system"] + np.round(first["frequency"] / 50e6).astype(int).astype(str)
    spread = residual - pd.Series(residual).groupby(band.to_numpy()).transform("median")
    assert np.median(np.abs(spread)) < 10.0


def test_gsdc_pseudorange_estimator_against_ground_truth(gsdc, tmp_path):
    _, dataset = gsdc
    scores = tmp_path / "scores.json"
    assert main(["score", str(dataset.path), "-e", "gnss_wls", "--json", str(scores)]) == 0
    result = json.loads(scores.read_text())["gnss_wls"]
    # phone pseudoranges: Google's own WLS positions of these epochs lie 4-8 m from the truth
    assert result["horizontal"]["rms"] < 10.0


def test_variants_of_the_formats_import(shared_dir, tmp_path):
    """A GSDC trace without the optional columns (carrier phase, Google's WLS, ISRB), columns
    in another order, other message types mixed in; a comma2k19 segment without a
    magnetometer: both import, with what they lack left out."""
    source = shared_dir / "refdata" / GSDC
    csv = pd.read_csv(source / "device_gnss.csv")
    optional = [c for c in csv if c.startswith(("AccumulatedDeltaRange", "WlsPosition"))]
    variant = csv.drop(columns=optional + ["IsrbMeters"])
    variant = variant[variant.columns[::-1]]
    status = variant.iloc[:3].copy()
    status["MessageType"] = "Status"
    folder = tmp_path / "trace"
    folder.mkdir()
    pd.concat([variant, status]).to_csv(folder / "device_gnss.csv", index=False)
    shutil.copy(source / "ground_truth.csv", folder / "ground_truth.csv")
    assert main(["import", "gsdc", str(folder), "-o", str(tmp_path / "g")]) == 0
    imported = open_dataset(tmp_path / "g")
    assert not imported.has("gnss_fix")
    assert imported.read("gnss_raw")["carrier_phase"].isna().all()

    segment = tmp_path / "segment"
    shutil.copytree(shared_dir / "refdata" / COMMA, segment)
    shutil.rmtree(segment / "processed_log" / "IMU" / "magnetometer")
    assert main(["import", "comma2k19", str(segment), "-o", str(tmp_path / "c")]) == 0
    assert not open_dataset(tmp_path / "c").has("mag")


def test_bad_sources_give_one_message(tmp_path, capsys):
    assert main(["import", "comma2k19", str(tmp_path), "-o", str(tmp_path / "x")]) == 2
    assert main(["import", "gsdc", str(tmp_path), "-o", str(tmp_path / "y")]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and "global_pose" in err and "device_gnss.csv" in err
    assert not (tmp_path / "x").exists() and not (tmp_path / "y").exists()


def test_twin_follows_the_reference_and_compare_reports_both(comma, tmp_path, capsys):
    """The twin of the comma2k19 minute: its truth follows the recording's reference (the
    recorded-trajectory fit), its sensors are the datasheet's presets at the recording's rates,
    and `compare` reports every statistic on both with the plots."""
    _, real = comma
    scenario = tmp_path / "twin.yaml"
    assert main(["twin", str(real.path), "-o", str(scenario)]) == 0
    assert (tmp_path / "twin.drive.parquet").is_file()
    assert main(["generate", str(scenario), "-o", str(tmp_path / "sim")]) == 0
    sim = open_dataset(tmp_path / "sim")
    assert pd.Timestamp(sim.manifest["utc_start"]) == pd.Timestamp(real.manifest["utc_start"])
    for sensor in ("imu", "odometer", "gnss"):
        assert sim.manifest["datasheet"][sensor]["preset"] == real.manifest["datasheet"][
            sensor]["preset"]
        assert sim.manifest["datasheet"][sensor]["rate"] == real.manifest["datasheet"][
            sensor]["rate"]
    ref, twin = real.read("truth"), sim.read("truth")
    t = twin["t"].to_numpy()
    inside = t <= ref["t"].iloc[-1] - ref["t"].iloc[0]
    lat = np.radians(np.interp(t[inside] + ref["t"].iloc[0], ref["t"], ref["lat"]))
    d_n = np.radians(twin["lat"].to_numpy()[inside]) - lat
    d_e = (np.radians(twin["lon"].to_numpy()[inside])
           - np.radians(np.interp(t[inside] + ref["t"].iloc[0], ref["t"], ref["lon"]))
           ) * np.cos(lat)
    assert np.median(6.371e6 * np.hypot(d_n, d_e)) < 1.0
    report = tmp_path / "cmp"
    assert main(["compare", str(real.path), str(sim.path), "--report", str(report),
                 "-e", "gnss_only"]) == 0
    text = (report / "report.md").read_text()
    for statistic in ("imu.gyro_rms", "imu.accel_rms", "odometer.speed_error_std",
                      "gnss.satellites_per_epoch_median", "gnss.cn0_p50", "gnss.fix_error_p95",
                      "estimator.gnss_only_horizontal_rms_m", "Largest mismatches"):
        assert statistic in text
    for plot in ("imu_psd.png", "cn0.png", "fix_error.png"):
        assert (report / plot).stat().st_size > 1000
    assert "Look first at" in text


def test_the_twin_of_a_simulated_drive_reproduces_its_statistics(quickstart, tmp_path):
    """Closure: the twin of a simulated dataset (same presets, same sky, the trajectory refitted
    from its truth, other random draws) matches it where the statistic is set by the models
    rather than by the draws."""
    from simulator.comparison import compare_datasets

    scenario = tmp_path / "twin.yaml"
    assert main(["twin", str(quickstart.path), "-o", str(scenario)]) == 0
    assert main(["generate", str(scenario), "-o", str(tmp_path / "sim")]) == 0
    rows = {r["statistic"]: r for r in compare_datasets(
        quickstart, open_dataset(tmp_path / "sim"), "gnss_only")["rows"]}
    assert rows["gnss.satellites_per_epoch_median"]["ratio"] == 1.0
    assert 0.97 < rows["gnss.cn0_p50_dbhz"]["ratio"] < 1.03
    assert 0.8 < rows["odometer.speed_error_std_m_s"]["ratio"] < 1.25
    assert 0.6 < rows["estimator.gnss_only_horizontal_rms_m"]["ratio"] < 1.6


def test_smartloc_trace(tmp_path):
    """The smartLoc excerpt: its GPS and GLONASS measurements with their NLOS labels, and the
    heading convention (0 = east, counter-clockwise) checked against the reference's own
    positions: the velocity from heading and speed matches the positions' differences."""
    source = _refdata() / "vehicle" / "smartloc_berlin_2016-06-06" / "tu_chemnitz_berlin_1_raw.csv"
    assert main(["import", "smartloc", str(source), "-o", str(tmp_path / "s")]) == 0
    dataset = open_dataset(tmp_path / "s")
    csv = pd.read_csv(source, sep=";")
    raw = dataset.read("gnss_raw")
    sbas = csv["GNSS identifier (gnssId) []"].str.upper() == "SBAS"
    assert len(raw) == int((~sbas).sum()) - int(
        (csv["Receiver tracking status (recStat) []"].isna()).sum())
    assert set(raw["system"]) == {"G", "R"}
    assert set(raw["nlos"].dropna()) <= {0.0, 1.0} and raw["nlos"].mean() > 0.2
    np.testing.assert_allclose(raw["pseudorange_rate"] * raw["frequency"] / 299792458.0,
                               -raw["doppler"])
    truth = dataset.read("truth")
    from simulator.earth import ecef_to_ned, geodetic_to_ecef

    ecef = geodetic_to_ecef(np.radians(truth["lat"]), np.radians(truth["lon"]),
                            truth["alt"]).reshape(-1, 3)
    ned = ecef_to_ned(ecef, np.radians(truth["lat"].iloc[0]), np.radians(truth["lon"].iloc[0]),
                      truth["alt"].iloc[0])
    t = truth["t"].to_numpy()
    v_pos = np.diff(ned[:, :2], axis=0) / np.diff(t)[:, None]
    v_mid = 0.5 * (truth[["vn", "ve"]].to_numpy()[1:] + truth[["vn", "ve"]].to_numpy()[:-1])
    assert np.median(np.linalg.norm(v_pos - v_mid, axis=1)) < 0.3
    assert main(["estimate", str(dataset.path), "-e", "gnss_wls", "-o",
                 str(tmp_path / "w.parquet")]) == 2


def test_rinex_station_hour(tmp_path):
    """GEONET 0759's hour (refdata 1c) with its navigation file and its F3 position as the
    reference: the satellite states computed from the navigation file put the corrected
    pseudoranges on the geometric ranges up to one clock per epoch (residual spread at the
    station's published level, 0.77 m), and the snapshot least squares lands within metres."""
    folder = _refdata() / "gnss" / "gsi0759_2005-04-02_rtklib"
    out = tmp_path / "rx"
    assert main(["import", "rinex", str(folder / "07590920.05o"), str(folder / "07590920.05n"),
                 "--reference", "35.160866522,139.613842697,68.3892", "-o", str(out)]) == 0
    dataset = open_dataset(out)
    raw = dataset.read("gnss_raw")
    assert raw["t"].nunique() == 120 and set(raw["system"]) == {"G"}
    from estimators.toolbox.gnss_model import predict
    from simulator.earth import geodetic_to_ecef

    station = geodetic_to_ecef(np.radians(35.160866522), np.radians(139.613842697),
                               68.3892).ravel()
    high = raw[raw["elevation"] > np.radians(15.0)]
    geometric, _, _ = predict(high[["sat_x", "sat_y", "sat_z"]].to_numpy(),
                              high[["sat_vx", "sat_vy", "sat_vz"]].to_numpy(), station,
                              np.zeros(3))
    residual = (high["pseudorange"] + high["sat_clock"] - high["iono"] - high["tropo"]
                - geometric).to_numpy(copy=True)
    residual -= pd.Series(residual).groupby(high["t"].to_numpy()).transform("mean").to_numpy()
    assert 0.4 < np.std(residual) < 1.2
    scores = tmp_path / "s.json"
    assert main(["score", str(out), "-e", "gnss_wls", "--json", str(scores)]) == 0
    wls = json.loads(scores.read_text())["gnss_wls"]
    assert wls["horizontal"]["rms"] < 3.0
    # its sigma against the station's published position: no axis overconfident on a real
    # receiver (one hour is one draw of the ionosphere's drive-long error, so no lower bound)
    assert max(wls["consistency"]["position"]["nse"].values()) < 3.0
