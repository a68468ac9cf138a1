"""The mixed RINEX 3.04 navigation writer (``write_rinex_nav``): GPS, Galileo, BeiDou, GLONASS
(and QZSS) records read back by landnav's reader and by georinex (an independent reader) to the
format's resolution, and RTKLIB's single-point solution from those records (its own orbit and
clock code per system) agrees with landnav's satellite positions and clocks to millimetres."""

from __future__ import annotations

import datetime as dt
import warnings

import numpy as np
import pandas as pd
import pytest
from test_gnss_orbits import REF, _need

from simulator.earth import geodetic_to_ecef
from simulator.gnss.constants import C_M_S
from simulator.gnss.constellation import sky_navigation
from simulator.gnss.ephemeris import STATE_KEYS, ephemeris_arrays, gather, select_ephemeris
from simulator.gnss.navfiles import read_rinex_nav
from simulator.gnss.receiver import look_angles, signal_geometry
from simulator.gnss.rinex_writer import write_rinex_nav
from simulator.timebase import GPS_EPOCH, utc_to_gps
from tests.gnss.rtklib import code_observations, single_point

START = dt.datetime(2024, 5, 1, 3, 0, 0)  # UTC
LEAP_S = 18
KEYS = ["system", "sv", "week", "toe"]


def _mixed_sky() -> pd.DataFrame:
    """An hour of the default sky: the GPS almanac's records and the nominal Galileo, BeiDou
    (MEO, IGSO, GEO) and GLONASS constellations."""
    week, _ = utc_to_gps(START)
    return sky_navigation("gps-almanac", ["gps", "galileo", "beidou", "glonass"], START,
                          3600.0, reference_week=week)


def _sorted(nav: pd.DataFrame) -> pd.DataFrame:
    return nav.sort_values(KEYS, kind="stable").reset_index(drop=True)


def test_mixed_file_reads_back_with_our_reader(tmp_path):
    """Every value of every system's records comes back to D19.12's 12 digits, the header's
    ionosphere coefficients and leap seconds with it."""
    nav = _mixed_sky()
    assert set(nav["system"]) == {"G", "E", "C", "R"}
    path = write_rinex_nav(tmp_path / "mixed.nav", nav, LEAP_S, [1e-8, 0.0, -6e-8, 0.0],
                           [9e4, 0.0, -2e5, 0.0])
    text = path.read_text()
    assert text.splitlines()[0][20] == "N" and text.splitlines()[0][40] == "M"
    back = read_rinex_nav(path)
    pd.testing.assert_frame_equal(_sorted(back)[nav.columns], _sorted(nav), check_dtype=False,
                                  rtol=1e-11, atol=1e-300)
    assert back.attrs["leap_seconds"] == LEAP_S
    np.testing.assert_allclose(back.attrs["iono_alpha"], [1e-8, 0.0, -6e-8, 0.0])


def test_real_mixed_file_round_trips_with_its_time_corrections(tmp_path):
    """Refdata 1e's DLR file (GPS, Galileo, BeiDou, GLONASS, QZSS) read, written and read
    again: the same records and the same TIME SYSTEM CORR lines."""
    src = _need(REF / "gnss/multignss_2023-03-14_gnss_lib_py/BRDM00DLR_S_20230730000_01D_MN.rnx")
    nav = read_rinex_nav(src)
    path = write_rinex_nav(tmp_path / "again.nav", nav, nav.attrs["leap_seconds"],
                           time_corrections=nav.attrs["time_corrections"])
    back = read_rinex_nav(path)
    assert set(back["system"]) == {"G", "E", "C", "R", "J"}
    pd.testing.assert_frame_equal(_sorted(back), _sorted(nav), check_dtype=False, rtol=1e-11,
                                  atol=1e-300)
    assert back.attrs["time_corrections"] == nav.attrs["time_corrections"]


def test_mixed_file_reads_back_with_georinex(tmp_path):
    """georinex finds every record of every system with the Keplerian elements, group delays
    and Galileo data source, and the GLONASS state vectors and channels, in its own names."""
    georinex = pytest.importorskip("georinex")
    nav = _mixed_sky()
    nav = nav[nav.groupby("system")["sv"].rank(method="dense") <= 3]  # georinex is slow
    assert set(nav["sv"][nav["system"] == "C"]) == {1, 2, 3}  # GEOs among them
    path = write_rinex_nav(tmp_path / "mixed.nav", nav, LEAP_S)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        theirs = georinex.load(path).to_dataframe().reset_index()
    theirs = theirs.dropna(subset=["SVclockBias"])
    theirs = theirs.assign(system=theirs["sv"].str[0], sv=theirs["sv"].str[1:].astype(int))
    kepler = {"sqrt_a": "sqrtA", "e": "Eccentricity", "m0": "M0", "omega0": "Omega0",
              "i0": "Io", "omega": "omega", "omega_dot": "OmegaDot", "toe": "Toe",
              "af0": "SVclockBias"}
    week_column = {"G": "GPSWeek", "E": "GALWeek", "C": "BDTWeek"}
    for system in ("G", "E", "C"):
        ours = nav[nav["system"] == system].sort_values(["sv", "week", "toe"])
        got = theirs[(theirs["system"] == system)].dropna(subset=["sqrtA"]).sort_values(
            ["sv", "time"])
        assert len(got) == len(ours) > 0, system
        for mine, name in {**kepler, "week": week_column[system]}.items():
            np.testing.assert_allclose(got[name], ours[mine], rtol=1e-11, atol=1e-300,
                                       err_msg=f"{system} {mine}")
    gal = theirs[theirs["system"] == "E"].dropna(subset=["sqrtA"])
    assert (gal["DataSrc"] == 517).all()
    glo = nav[nav["system"] == "R"].sort_values(["sv", "week", "toe"])
    got = theirs[theirs["system"] == "R"].dropna(subset=["X"]).sort_values(["sv", "time"])
    assert len(got) == len(glo) > 0
    for mine, name in (("glo_x", "X"), ("glo_vy", "dY"), ("glo_z", "Z")):
        np.testing.assert_allclose(got[name], glo[mine], rtol=1e-11)  # georinex: m
    np.testing.assert_array_equal(got["FreqNum"], glo["glo_channel"])
    # the GLONASS epochs are UTC: t_b (GPS time) minus the leap seconds
    gps_s = (glo["week"] * 604800 + glo["toe"]).to_numpy()
    utc_s = (pd.to_datetime(got["time"]) - pd.Timestamp(GPS_EPOCH)).dt.total_seconds()
    np.testing.assert_allclose(utc_s.to_numpy(), gps_s - LEAP_S)


def test_rtklib_single_point_from_the_written_file_agrees_with_our_satellites(tmp_path):
    """Pseudoranges made of landnav's geometry and broadcast clocks (no atmosphere, no noise)
    from every satellite above 10 deg at 35 N 117 E (GPS, Galileo, BeiDou with its GEOs and
    IGSOs, GLONASS), solved by RTKLIB's rnx2rtkp with the written file: positions within 1 cm
    of the truth, every residual within 1 cm, inter-system biases within 0.05 ns. A wrong
    epoch time system (BDT, GLONASS UTC), element, sign or unit in any record would move a
    satellite by metres to kilometres."""
    nav = _mixed_sky()
    nav_path = write_rinex_nav(tmp_path / "mixed.nav", nav, LEAP_S)
    week, tow = utc_to_gps(START)
    eph = ephemeris_arrays(nav, week)
    t = tow + 600.0 + np.arange(0.0, 301.0, 30.0)
    lat, lon = np.radians(35.0), np.radians(117.0)
    rx = np.asarray(geodetic_to_ecef(lat, lon, 50.0), dtype=float).reshape(3)
    sats = nav[["system", "sv"]].drop_duplicates()
    system, sv = sats["system"].to_numpy(dtype=str), sats["sv"].to_numpy(dtype=int)
    idx = select_ephemeris(eph, sv[:, None], t[None, :], system=system[:, None])
    geo = signal_geometry(gather(eph, np.maximum(idx, 0), STATE_KEYS), t,
                          np.tile(rx, (len(t), 1)), np.zeros((len(t), 3)))
    look = look_angles(geo["los"], geo["los_rate"], np.full(len(t), lat), np.full(len(t), lon))
    up = (look["elevation"] > np.radians(10.0)).all(axis=1) & (idx >= 0).all(axis=1)
    chosen = [(s, int(n)) for s, n in zip(system[up], sv[up], strict=True)]
    assert {s for s, _ in chosen} == {"G", "E", "C", "R"}
    assert {n for s, n in chosen if s == "C"} & {1, 2, 3, 4, 5}  # a GEO is in view
    channels = dict(nav[nav["system"] == "R"].groupby("sv")["glo_channel"].first())
    code_observations(tmp_path / "obs.rnx", rx, GPS_EPOCH + dt.timedelta(weeks=week), t,
                      chosen, (geo["range"] - C_M_S * geo["clock_s"])[up], channels)
    solved = single_point(tmp_path / "obs.rnx", nav_path)
    residual = np.array([abs(float(r[7])) for r in solved["sat"]])
    error = np.linalg.norm(solved["pos"] - rx, axis=1)
    print(f"\nRTKLIB from the written mixed file, {len(chosen)} satellites: position within "
          f"{error.max() * 1e3:.1f} mm, residuals within {residual.max() * 1e3:.1f} mm, "
          f"inter-system biases within {np.abs(solved['clock'][:, 1:]).max():.3f} ns")
    assert len(solved["pos"]) >= len(t) - 1  # RTKLIB leaves its first epoch unsolved
    assert {r[3][0] for r in solved["sat"]} == {"G", "E", "C", "R"}
    assert error.max() < 0.01 and residual.max() < 0.01
    assert np.abs(solved["clock"][:, 1:]).max() < 0.05


def test_export_of_a_drive_on_a_real_file_keeps_its_time_corrections(tmp_path):
    """``landnav export --rinex`` of a drive whose sky is refdata 1e's file writes the records
    the receiver used, of every system asked for, and the file's TIME SYSTEM CORR lines (the
    offsets its satellite clocks were computed with)."""
    import yaml

    from simulator.cli import main

    src = _need(REF / "gnss/multignss_2023-03-14_gnss_lib_py/BRDM00DLR_S_20230730000_01D_MN.rnx")
    scenario = {"name": "real-sky", "seed": 1,
                "start": {"utc": "2023-03-14T01:40:00Z", "lat": 40.0, "lon": 130.0, "alt": 50.0,
                          "heading": 0.0},
                "trajectory": {"kind": "segments", "segments": [{"stop": {"duration": 10}}]},
                "sensors": {"gnss": {"rate": 1, "preset": "geodetic", "outputs": ["raw"],
                                     "constellation": str(src),
                                     "systems": ["gps", "galileo", "beidou", "glonass"]}}}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(scenario))
    assert main(["generate", str(tmp_path / "s.yaml"), "-o", str(tmp_path / "ds")]) == 0
    assert main(["export", str(tmp_path / "ds"), "--rinex", str(tmp_path / "rinex")]) == 0
    back = read_rinex_nav(tmp_path / "rinex" / "ds.nav")
    source = read_rinex_nav(src)
    assert set(back["system"]) == {"G", "E", "C", "R"}
    for label in ("GAGP", "GLGP"):
        assert back.attrs["time_corrections"][label] == source.attrs["time_corrections"][label]
