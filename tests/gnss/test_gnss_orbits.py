"""Broadcast ephemeris, navigation readers and atmospheric models against real data and
published tables (refdata README sections 1a, 1b, 2, 3b, 5)."""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from simulator.earth import ecef_to_geodetic
from simulator.gnss.atmosphere import klobuchar_delay, niell_mapping, saastamoinen_delay
from simulator.gnss.constants import C_M_S, SECONDS_PER_WEEK
from simulator.gnss.ephemeris import ephemeris_arrays, gather, satellite_state, select_ephemeris
from simulator.gnss.navfiles import read_navigation, read_rinex_nav, read_yuma
from simulator.timebase import GPS_EPOCH

SHARED = Path(__file__).resolve().parents[3] / "shared"
REF = SHARED / "refdata"


def _need(path: Path) -> Path:
    if not path.exists():
        pytest.skip(f"reference data {path} not available (needs the shared/ folder beside the "
                    "repository checkout)")
    return path


def read_sp3_positions(path: Path) -> pd.DataFrame:
    """Minimal SP3-a/c reader for the tests: epoch (GPS s since 1980-01-06), system (RINEX
    letter; G where SP3-a writes none), sv, x, y, z (m), clock_s (the satellite clock, s; NaN
    where the file has none)."""
    rows, epoch = [], None
    for line in path.read_text().splitlines():
        if line.startswith("* "):
            f = line[2:].split()
            stamp = dt.datetime(*(int(x) for x in f[:5]), int(float(f[5])))
            epoch = (stamp - GPS_EPOCH).total_seconds()
        elif line.startswith("P") and epoch is not None:
            system = line[1] if line[1].isalpha() else "G"
            xyz = [float(line[4 + 14 * k: 18 + 14 * k]) * 1e3 for k in range(3)]
            clock_us = float(line[46:60] or "999999.999999")
            rows.append((epoch, system, int(line[2:4]), *xyz,
                         np.nan if clock_us >= 999999.0 else clock_us * 1e-6))
    return pd.DataFrame(rows, columns=["epoch", "system", "sv", "x", "y", "z", "clock_s"])


@pytest.mark.parametrize("folder, nav_name, sp3_name", [
    ("gnss/arl1_2015-07-19_gnsstk", "arlm2000.15n", "test_input_sp3_nav_2015_200.sp3"),
    ("gnss/igs_2010-07-01_rtklib", "brdc1820.10n", "igs15904.sp3"),
])
def test_broadcast_orbit_against_precise_orbit(folder, nav_name, sp3_name):
    nav = read_rinex_nav(_need(REF / folder / nav_name))
    # brdc1820.10n sets PRN 01 (SVN 49, unusable in 2010) unhealthy in 13 of its 14 records;
    # its one 'healthy' record is not a valid orbit: leave out satellites that are mostly
    # unhealthy during the day, as a receiver's health monitoring would
    mostly_bad = nav.groupby("sv")["health"].apply(lambda h: (h != 0).mean() > 0.5)
    nav = nav[~nav["sv"].isin(mostly_bad[mostly_bad].index)]
    sp3 = read_sp3_positions(_need(REF / folder / sp3_name))
    week0 = int(nav["week"].min())
    eph = ephemeris_arrays(nav, week0)
    t = sp3["epoch"].to_numpy() - week0 * SECONDS_PER_WEEK
    idx = select_ephemeris(eph, sp3["sv"].to_numpy(), t, max_age_s=2 * 3600.0)
    use = idx >= 0
    state = satellite_state(gather(eph, idx[use]), t[use])
    diff = state["pos"] - sp3[["x", "y", "z"]].to_numpy()[use]
    err = np.linalg.norm(diff, axis=1)
    rms = float(np.sqrt(np.mean(err**2)))
    assert use.sum() > 1000
    # issue 5: 3-D RMS below 5 m; refdata README: median 1.47 m (ARL1), 1.64 m (IGS)
    assert rms < 5.0, rms
    assert 0.5 < np.median(err) < 2.5


def _gsdc():
    folder = REF / "vehicle/gsdc2022_pixel_2021-04-29_mtv"
    raw = pd.read_csv(_need(folder / "device_gnss.csv"))
    raw = raw[(raw["ConstellationType"] == 1) & (raw["SignalType"] == "GPS_L1")]
    return raw.reset_index(drop=True), read_rinex_nav(_need(folder / "brdc1190.21n"))


def test_satellite_states_against_google_gsdc2022():
    raw, nav = _gsdc()
    week0 = int(nav["week"].min())
    eph = ephemeris_arrays(nav, week0)
    nanos = raw["ReceivedSvTimeNanosSinceGpsEpoch"].to_numpy(dtype=np.int64)
    t_sv = (nanos - np.int64(week0 * SECONDS_PER_WEEK) * 1_000_000_000) / 1e9
    idx = select_ephemeris(eph, raw["Svid"].to_numpy(), t_sv)
    assert (idx >= 0).all()
    rec = gather(eph, idx)
    t = t_sv
    for _ in range(3):  # t = t_sv - dt_sv (IS-GPS-200 20.3.3.3.3.1)
        t = t_sv - satellite_state(rec, t)["clock_s"]
    state = satellite_state(rec, t)
    pos_ref = raw[[f"SvPosition{a}EcefMeters" for a in "XYZ"]].to_numpy()
    vel_ref = raw[[f"SvVelocity{a}EcefMetersPerSecond" for a in "XYZ"]].to_numpy()
    assert len(raw) >= 40
    # issue 5 asks for centimetres; measured: 0.9 mm, 0.8 mm/s, 0.6 um, 1e-10 m/s
    assert np.abs(state["pos"] - pos_ref).max() < 0.005
    assert np.abs(state["vel"] - vel_ref).max() < 0.005
    assert np.abs(C_M_S * state["clock_s"] - raw["SvClockBiasMeters"]).max() < 0.001
    assert np.abs(C_M_S * state["clock_drift_s_s"] - raw["SvClockDriftMetersPerSecond"]
                  ).max() < 1e-6


def test_klobuchar_against_google_gsdc2022():
    raw, nav = _gsdc()
    rx = raw[[f"WlsPosition{a}EcefMeters" for a in "XYZ"]].to_numpy()
    lat, lon, _ = ecef_to_geodetic(rx)
    tow = np.mod(raw["ArrivalTimeNanosSinceGpsEpoch"].to_numpy() / 1e9, SECONDS_PER_WEEK)
    iono = klobuchar_delay(lat, lon, np.radians(raw["SvAzimuthDegrees"].to_numpy()),
                           np.radians(raw["SvElevationDegrees"].to_numpy()), tow,
                           nav.attrs["iono_alpha"], nav.attrs["iono_beta"])
    assert np.abs(iono - raw["IonosphericDelayMeters"].to_numpy()).max() < 0.001  # 0.07 mm


def _table(name: str) -> pd.DataFrame:
    return pd.read_csv(_need(REF / "tables" / name), comment="#")


def test_klobuchar_against_rtklib_table():
    cases = _table("klobuchar_rtklib_utest.csv")
    stamps = pd.to_datetime(cases["gps_epoch"])
    tow = np.array([((s.to_pydatetime() - GPS_EPOCH).total_seconds()) % SECONDS_PER_WEEK
                    for s in stamps])
    alpha, beta = [0.2e-7, -0.8e-8, -0.5e-7, 0.1e-6], [0.2e6, 0.2e6, -0.1e6, -0.1e7]
    got = klobuchar_delay(np.radians(cases["lat_deg"]), np.radians(cases["lon_deg"]),
                          np.radians(cases["az_deg"]), np.radians(cases["el_deg"]), tow,
                          alpha, beta)
    np.testing.assert_allclose(got, cases["delay_m"], rtol=0, atol=1e-8)


def test_saastamoinen_against_rtklib_table():
    cases = _table("saastamoinen_rtklib_utest.csv")
    for _, c in cases.iterrows():
        got = saastamoinen_delay(np.radians(c["lat_deg"]), c["h_m"], np.radians(c["el_deg"]),
                                 humidity=c["rel_humidity"])
        assert abs(float(got) - c["delay_m"]) < 1e-8


def test_loose_rinex_and_yuma_against_each_other():
    """sugl0010.20n (blank-separated fields) against the YUMA almanac of the same days: the
    README's independent check found 1.0-1.35 km median, 2-3 km max (almanac age 2-3 days)."""
    folder = REF / "almanac/maast_2020-01-01"
    nav = read_navigation(_need(folder / "sugl0010.20n"))
    alm = read_yuma(_need(folder / "almyuma_01jan2020.txt"), reference_week=2086)
    assert len(nav) == 418 and nav["sv"].nunique() == 32
    assert len(alm) == 31 and (alm["week"] == 2086).all()
    week0 = 2086
    e_nav, e_alm = ephemeris_arrays(nav, week0), ephemeris_arrays(alm, week0)
    t = 259200.0 + np.arange(0, 86400, 900.0)
    sv = alm["sv"][alm["health"] == 0].to_numpy()
    svs, ts = np.meshgrid(sv, t, indexing="ij")
    i_nav = select_ephemeris(e_nav, svs, ts)
    i_alm = select_ephemeris(e_alm, svs, ts, max_age_s=7 * 86400.0)
    ok = (i_nav >= 0) & (i_alm >= 0)
    d = np.linalg.norm(satellite_state(gather(e_nav, i_nav[ok]), ts[ok])["pos"]
                       - satellite_state(gather(e_alm, i_alm[ok]), ts[ok])["pos"], axis=1)
    assert ok.sum() > 2000
    assert 300.0 < np.median(d) < 2500.0 and d.max() < 6000.0


def test_niell_mapping_against_rtklib_table():
    cases = _table("niell_mapping_rtklib_utest.csv")
    stamps = pd.to_datetime(cases["gps_epoch"])
    doy = np.array([(s - pd.Timestamp(s.year, 1, 1)).total_seconds() / 86400.0 + 1.0
                    for s in stamps])
    m_h, m_w = niell_mapping(np.radians(cases["lat_deg"]), cases["h_m"],
                             np.radians(cases["el_deg"]), doy)
    np.testing.assert_allclose(m_h, cases["mapf_dry"], rtol=0, atol=1e-8)
    np.testing.assert_allclose(m_w, cases["mapf_wet"], rtol=0, atol=1e-8)
