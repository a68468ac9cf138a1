"""Group delays per signal (``signal_group_delay_s``) against the interface documents' user
formulas, and through the receiver on refdata 1e's real Galileo and BeiDou records: each
signal's code carries its own BGD / TGD, the carrier none."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pytest
from gnss_helpers import drive, receiver
from test_gnss_orbits import REF, _need

from simulator.gnss.constants import C_M_S
from simulator.gnss.signals import signal_group_delay_s

F_E1, F_E5A, F_E5B = 1575.42e6, 1176.45e6, 1207.14e6
BGD_A, BGD_B = 3.4e-9, 3.9e-9  # BGD(E1,E5a), BGD(E1,E5b), s: the order of real values
TGD1, TGD2 = 2.1e-8, -1.5e-9  # BeiDou, s


def test_galileo_signals_take_the_icds_bgd_formulas():
    """OS SIS ICD 5.1.5: a single-frequency user of E1 with the I/NAV (E1,E5b) clock applies
    dt - BGD(E1,E5b), of E5b dt - (f_E1/f_E5b)^2 BGD(E1,E5b); with the F/NAV (E1,E5a) clock E1
    takes BGD(E1,E5a) and E5a (f_E1/f_E5a)^2 BGD(E1,E5a). The two clocks describe the same E1
    signal, dt_F - BGD(E1,E5a) = dt_I - BGD(E1,E5b): E5a against the I/NAV clock is dt_F -
    (f_E1/f_E5a)^2 BGD(E1,E5a) written with dt_I."""
    dt_inav = 1.0e-4
    dt_fnav = dt_inav - BGD_B + BGD_A

    def user_clock(code, clock, primary):
        return clock - float(signal_group_delay_s("E", code, primary, BGD_A, BGD_B))

    assert user_clock("1C", dt_inav, BGD_B) == pytest.approx(dt_inav - BGD_B, abs=1e-18)
    assert user_clock("7Q", dt_inav, BGD_B) == pytest.approx(
        dt_inav - (F_E1 / F_E5B) ** 2 * BGD_B, abs=1e-18)
    assert user_clock("5Q", dt_fnav, BGD_A) == pytest.approx(
        dt_fnav - (F_E1 / F_E5A) ** 2 * BGD_A, abs=1e-18)
    assert user_clock("1C", dt_fnav, BGD_A) == pytest.approx(user_clock("1C", dt_inav, BGD_B),
                                                             abs=1e-18)
    # either clock gives every signal the same code delay in the pseudorange
    for code in ("5Q", "7Q"):
        assert user_clock(code, dt_inav, BGD_B) == pytest.approx(
            user_clock(code, dt_fnav, BGD_A), abs=1e-18)
    # the ionosphere-free E1/E5b combination of I/NAV users sees the clock itself
    g = (F_E1 / F_E5B) ** 2
    combo = (g * user_clock("1C", dt_inav, BGD_B) - user_clock("7Q", dt_inav, BGD_B)) / (g - 1)
    assert combo == pytest.approx(dt_inav, abs=1e-18)


def test_beidou_and_gps_signals_take_their_icds_terms():
    """BDS SIS ICD B1I 5.2.4.10: B1I users apply dt - TGD1, B2I users dt - TGD2 (the clock is
    B3I's); B2a has no term in D1/D2. IS-GPS-200 20.3.3.3.3.2: L1 T_GD, L2 gamma T_GD."""
    assert float(signal_group_delay_s("C", "2I", TGD1, TGD1, TGD2)) == TGD1
    assert float(signal_group_delay_s("C", "7I", TGD1, TGD1, TGD2)) == TGD2
    assert float(signal_group_delay_s("C", "5P", TGD1, TGD1, TGD2)) == 0.0
    tgd = -1.1e-8
    assert float(signal_group_delay_s("G", "1C", tgd, tgd, 0.0)) == tgd
    assert float(signal_group_delay_s("G", "2W", tgd, tgd, 0.0)) == pytest.approx(
        (77 / 60) ** 2 * tgd, rel=1e-12)
    assert float(signal_group_delay_s("R", "2C", 0.0, 0.0, 0.0)) == 0.0


def test_receiver_applies_each_records_bgd_and_tgd2_per_signal():
    """On refdata 1e's records (40 N 130 E, 2023-03-14 01:40 UTC: E02, C01, C02 in view): the
    satellite clock of each
    Galileo and BeiDou signal differs from its primary signal's by what the ICDs give with the
    record's own BGD / TGD1 / TGD2 (m, to float rounding), the truth's group_delay column is
    that term, and the carrier, which carries no group delay, has the same clock on every
    signal: lambda Phi - the code's sat_clock difference closes exactly."""
    mixed = _need(REF / "gnss/multignss_2023-03-14_gnss_lib_py/BRDM00DLR_S_20230730000_01D_MN.rnx")
    truth = drive([{"stop": {"duration": 20}}], rate_hz=1.0,
                  start={"lat": 40.0, "lon": 130.0, "alt": 50.0, "heading": 0.0},
                  utc=dt.datetime(2023, 3, 14, 1, 40))
    out = receiver(preset="geodetic", constellation=str(mixed), systems=["galileo", "beidou"],
                   signals={"galileo": ["1C", "5Q", "7Q"], "beidou": ["2I", "7I"]},
                   tracking_noise=0.0).generate(truth, np.random.default_rng(1))
    raw, nav = out["gnss_raw"], out["gnss_nav"]
    wide = raw.pivot_table(index=["system", "sv", "t"], columns="signal",
                           values=["sat_clock", "group_delay"])
    checked = 0
    for (system, sv), rows in wide.groupby(level=[0, 1]):
        rec = nav[(nav["system"] == system) & (nav["sv"] == sv)]
        assert len(rec) == 1  # one record over the 20 s
        tgd, tgd2 = float(rec["tgd"].iloc[0]), float(rec["tgd2"].iloc[0])
        clock = rows["sat_clock"]
        if system == "E":
            assert tgd != 0 and tgd2 != 0
            inav = (int(rec["data_source"].iloc[0]) & 2) == 0
            primary = tgd2 if inav else tgd
            expect = {"5Q": primary + ((F_E1 / F_E5A) ** 2 - 1) * tgd,
                      "7Q": primary + ((F_E1 / F_E5B) ** 2 - 1) * tgd2}
            base = "1C"
        else:
            expect = {"7I": tgd2}
            primary, base = tgd, "2I"
        for code, delay in expect.items():
            if code not in clock or clock[code].isna().all():
                continue
            np.testing.assert_allclose(clock[base] - clock[code], C_M_S * (delay - primary),
                                       atol=1e-6)
            np.testing.assert_allclose(rows["group_delay"][code], C_M_S * delay, atol=1e-6)
            checked += 1
    print(f"\n{checked} Galileo/BeiDou secondary signals checked")
    assert checked >= 3
