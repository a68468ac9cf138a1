"""The receiver on several systems (``sensors.gnss.systems``): validation of the key against
the navigation source, the nominal multi-system sky through the receiver (an ideal receiver's
fix from GPS, Galileo, BeiDou and GLONASS together recovers the antenna within a centimetre,
which holds only if every system's orbit, clock and time offset agree on one GPS time), and a
real mixed navigation file (refdata 1e) driving it."""

from __future__ import annotations

import datetime as dt

import numpy as np
from gnss_helpers import drive, receiver
from test_gnss_orbits import REF, _need

from simulator.earth import geodetic_to_ecef
from simulator.gnss.constants import C_M_S
from simulator.gnss.glonass import SLOT_CHANNELS, carrier_frequencies_hz
from simulator.schema import Context
from simulator.sensors.gnss import GNSS_FIELD

DRIVE = [{"stop": {"duration": 5}}, {"accelerate": {"to_speed": 15, "accel": 2.0}},
         {"turn": {"angle": 90, "radius": 40}}, {"straight": {"length": 100}}]
FOUR = ["gps", "galileo", "beidou", "glonass"]


def _problems(**config) -> list[str]:
    ctx = Context("test")
    GNSS_FIELD.check(config, ("sensors", "gnss"), ctx)
    return [f"{p.key_path}: {p.message}" for p in ctx.problems]


def test_systems_key_is_checked_against_the_navigation_source():
    gps_only = _need(REF / "gnss/arl1_2015-07-19_gnsstk/arlm200a.15n")
    problems = _problems(constellation=str(gps_only), systems=["gps", "galileo"])
    assert len(problems) == 1
    assert problems[0].startswith("sensors.gnss.systems: ")
    assert "arlm200a.15n: no galileo navigation record (the file has gps)" in problems[0]
    assert _problems(systems=["gps", "qzss"])[0].startswith("sensors.gnss.systems: qzss needs")
    assert "more than once" in _problems(systems=["gps", "gps"])[0]
    assert "systems" in _problems(systems=["compass"])[0]
    mixed = _need(REF / "gnss/multignss_2023-03-14_gnss_lib_py/BRDM00DLR_S_20230730000_01D_MN.rnx")
    assert _problems(constellation=str(mixed), systems=[*FOUR, "qzss"]) == []


def test_ideal_receiver_on_four_nominal_systems_fixes_within_a_centimetre():
    truth = drive(DRIVE, rate_hz=10.0)
    out = receiver(preset="ideal", clock="tcxo", systems=FOUR).generate(
        truth, np.random.default_rng(3))
    raw, fix = out["gnss_raw"], out["gnss_fix"]
    counts = raw.groupby("system")["sv"].nunique()
    print("\nsatellites tracked per system:", counts.to_dict())
    assert set(counts.index) == {"G", "E", "C", "R"} and (counts >= 3).all()
    k = truth.inertial(fix["t"].to_numpy())
    got = geodetic_to_ecef(np.radians(fix["lat"]), np.radians(fix["lon"]), fix["alt"])
    want = geodetic_to_ecef(k["lat"], k["lon"], k["alt"])
    assert (fix["fix"] == 2).all()
    assert np.linalg.norm(got - want, axis=1).max() < 0.01
    # each satellite's Doppler is on its own carrier: GLONASS on its FDMA channel
    glo = raw[raw["system"] == "R"]
    g1, _ = carrier_frequencies_hz(glo["sv"].map(SLOT_CHANNELS).to_numpy())
    np.testing.assert_allclose(glo["doppler"], -glo["pseudorange_rate"] * g1 / C_M_S)
    bds = raw[raw["system"] == "C"]
    np.testing.assert_allclose(bds["doppler"], -bds["pseudorange_rate"] * 1561.098e6 / C_M_S)
    # and the broadcast elements of every system used are in gnss_nav
    nav = out["gnss_nav"]
    assert set(nav["system"]) == {"G", "E", "C", "R"}
    assert (np.abs(nav.loc[nav["system"] == "R", "glo_x"]) > 0).all()


def test_real_mixed_file_through_the_receiver():
    """refdata 1e's ten satellites (two per system) over Japan on 2023-03-14 00:00 UTC: the
    receiver tracks the visible ones of every system (QZSS and the BeiDou GEOs included), and
    its satellite clocks carry the file's time-system offsets (GGTO, tau_GPS)."""
    mixed = _need(REF / "gnss/multignss_2023-03-14_gnss_lib_py/BRDM00DLR_S_20230730000_01D_MN.rnx")
    truth = drive([{"stop": {"duration": 60}}], rate_hz=1.0,
                  start={"lat": 35.7, "lon": 139.7, "alt": 40.0, "heading": 0.0},
                  utc=dt.datetime(2023, 3, 14, 0, 0))
    out = receiver(preset="ideal", constellation=str(mixed),
                   systems=[*FOUR, "qzss"]).generate(truth, np.random.default_rng(1))
    raw = out["gnss_raw"]
    seen = raw.groupby("system")["sv"].unique().to_dict()
    print("\nseen:", seen)
    assert {"C", "J"} <= set(seen)
    assert set(out["gnss_nav"]["system"]) == {"G", "E", "C", "R", "J"}  # every record used
    # R01 (t_b 00:15 UTC, gamma_n = 0): -tau_n plus GLONASST - GPST = -tau_GPS (header GLGP)
    r01 = raw[(raw["system"] == "R") & (raw["sv"] == 1)]
    assert len(r01) == 61  # 0 ... 60 s
    np.testing.assert_allclose(r01["sat_clock"], C_M_S * (2.470612525940e-05 + 4.4703483582e-08),
                               rtol=0, atol=1e-6)
