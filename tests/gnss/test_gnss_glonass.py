"""GLONASS: the node table against direct integration, the carrier frequencies against the ICD's
table, the slot-to-channel map against a real receiver's RINEX header (refdata 1f)."""

from __future__ import annotations

import numpy as np
from test_gnss_orbits import REF, _need

from simulator.gnss.glonass import (
    GLONASS_MAX_AGE_S,
    SLOT_CHANNELS,
    StateTable,
    carrier_frequencies_hz,
    rk4_step,
)
from simulator.gnss.navfiles import read_rinex_nav


def _direct(state0: np.ndarray, lunisolar: np.ndarray, dt_s: float, step_s: float = 5.0
            ) -> np.ndarray:
    """RK4 from t_b straight to t_b + dt in equal steps of at most ``step_s``."""
    n = max(1, int(np.ceil(abs(dt_s) / step_s)))
    h = dt_s / n
    state = state0
    for _ in range(n):  # recursive in time
        state = rk4_step(state, lunisolar, h)
    return state


def test_node_table_matches_direct_integration():
    """The table (RK4 at 30 s, cubic Hermite between nodes) against RK4 at 5 s straight to each
    instant, for the real records of refdata 1e: within 1 mm and 1e-5 m/s over +-30 min
    (measured: 0.17 mm and 3e-8 m/s)."""
    nav = read_rinex_nav(_need(REF / "gnss/multignss_2023-03-14_gnss_lib_py"
                               / "BRDM00DLR_S_20230730000_01D_MN.rnx"))
    glo = nav[nav["system"] == "R"]
    state0 = glo[["glo_x", "glo_y", "glo_z", "glo_vx", "glo_vy", "glo_vz"]].to_numpy()
    lunisolar = glo[["glo_ax", "glo_ay", "glo_az"]].to_numpy()
    table = StateTable(state0, lunisolar)
    worst_pos, worst_vel = 0.0, 0.0
    for dt_s in (-1777.3, -905.0, -31.7, 0.0, 12.5, 437.9, 1199.2, GLONASS_MAX_AGE_S):
        pos, vel = table.state(np.arange(len(glo)), np.full(len(glo), dt_s))
        direct = _direct(state0, lunisolar, dt_s)
        worst_pos = max(worst_pos, np.abs(pos - direct[:, :3]).max())
        worst_vel = max(worst_vel, np.abs(vel - direct[:, 3:]).max())
    print(f"\ntable vs direct RK4: {worst_pos * 1e3:.4f} mm, {worst_vel:.2e} m/s")
    assert worst_pos < 1e-3 and worst_vel < 1e-5


def test_rk4_orbit_keeps_its_energy():
    """Without lunisolar terms the motion in the rotating frame conserves the Jacobi integral
    v^2/2 - mu/r - J2 term - omega^2 (x^2 + y^2)/2 (an analytic invariant): over a full
    11 h 15 min revolution at 60 s steps it changes by less than 1e-6 of its size."""
    from simulator.gnss.constants import A_E_GLO_M, J2_GLO, MU_GLO_M3_S2, OMEGA_E_GLO_RAD_S

    def jacobi(s: np.ndarray) -> float:
        r = np.linalg.norm(s[:3])
        sin_lat2 = (s[2] / r) ** 2
        potential = MU_GLO_M3_S2 / r * (1 - J2_GLO * (A_E_GLO_M / r) ** 2
                                        * (1.5 * sin_lat2 - 0.5))
        return 0.5 * s[3:] @ s[3:] - potential - 0.5 * OMEGA_E_GLO_RAD_S**2 * (s[0]**2 + s[1]**2)

    state = np.array([5763751.46, 11834326.17, 21858871.09, -1299.09, 2693.78, -1114.94])
    start = jacobi(state)
    for _ in range(676):  # 676 x 60 s = one revolution
        state = rk4_step(state, np.zeros(3), 60.0)
    assert abs(jacobi(state) - start) < 1e-6 * abs(start)


def test_fdma_frequencies_are_the_icd_table():
    """ICD 2008 Table 3.1: k = -7 ... +6; G1 1598.0625 ... 1605.375 MHz, G2 1242.9375 ...
    1248.625 MHz; k = 0 at 1602 / 1246 MHz."""
    g1, g2 = carrier_frequencies_hz(np.array([-7, 0, 6]))
    np.testing.assert_allclose(g1, [1598.0625e6, 1602.0e6, 1605.375e6])
    np.testing.assert_allclose(g2, [1242.9375e6, 1246.0e6, 1248.625e6])
    assert set(SLOT_CHANNELS.values()) == set(range(-7, 7)) - {-6, -5}
    # antipodal slots (four apart in a plane) share a channel
    for slot, channel in SLOT_CHANNELS.items():
        partner = (slot - 1) // 8 * 8 + (slot - 1 + 4) % 8 + 1
        assert SLOT_CHANNELS[partner] == channel


def test_slot_channels_match_a_real_receiver_header():
    """The 'GLONASS SLOT / FRQ #' line GnssLogger wrote on a Pixel 6 (refdata 1f)."""
    path = _need(REF / "gnss/multignss_obs_samples_gnss_lib_py/pixel6.23o")
    line = next(x for x in path.read_text().splitlines() if "GLONASS SLOT / FRQ #" in x)
    fields = line[4:60].split()
    pairs = {int(fields[i][1:]): int(fields[i + 1]) for i in range(0, len(fields), 2)}
    assert len(pairs) == 6
    assert all(SLOT_CHANNELS[slot] == channel for slot, channel in pairs.items())
    # and refdata 1e's navigation records: R01 channel 1, R02 channel -4
    nav = read_rinex_nav(_need(REF / "gnss/multignss_2023-03-14_gnss_lib_py"
                               / "BRDM00DLR_S_20230730000_01D_MN.rnx"))
    glo = nav[nav["system"] == "R"].groupby("sv")["glo_channel"].first()
    assert all(SLOT_CHANNELS[slot] == channel for slot, channel in glo.items())


def _d19(value: float) -> str:
    """A RINEX 2 D19.12 field."""
    mantissa, exponent = f"{value:.12E}".split("E")
    return f"{mantissa}D{int(exponent):+03d}".rjust(19)


def test_rinex2_glonass_file_reads_as_the_rinex3_record(tmp_path):
    """R01's first record of refdata 1e written in the RINEX 2.11 GLONASS layout (Table A11:
    two-digit year, the same fields) reads back to the same table row as the RINEX 3 file."""
    nav3 = read_rinex_nav(_need(REF / "gnss/multignss_2023-03-14_gnss_lib_py"
                                / "BRDM00DLR_S_20230730000_01D_MN.rnx"))
    row = nav3[(nav3["system"] == "R") & (nav3["sv"] == 1)].iloc[0]
    km = {k: row[k] / 1e3 for k in ("glo_x", "glo_y", "glo_z", "glo_vx", "glo_vy", "glo_vz",
                                     "glo_ax", "glo_ay", "glo_az")}
    header = ["     2.11           G: GLONASS NAV DATA                     RINEX VERSION / TYPE",
              "                                                            END OF HEADER"]
    body = [" 1 23  3 14  0 15  0.0" + _d19(row["af0"]) + _d19(row["af1"]) + _d19(172830.0),
            "   " + _d19(km["glo_x"]) + _d19(km["glo_vx"]) + _d19(km["glo_ax"]) + _d19(0.0),
            "   " + _d19(km["glo_y"]) + _d19(km["glo_vy"]) + _d19(km["glo_ay"]) + _d19(1.0),
            "   " + _d19(km["glo_z"]) + _d19(km["glo_vz"]) + _d19(km["glo_az"]) + _d19(0.0)]
    path = tmp_path / "brdc0730.23g"
    path.write_text("\n".join(header + body) + "\n")
    nav2 = read_rinex_nav(path)
    assert len(nav2) == 1 and nav2["system"].iloc[0] == "R"
    columns = ["sv", "week", "toe", "toc", "af0", "af1", "health", "iode", "glo_channel",
               *km]
    np.testing.assert_allclose(nav2[columns].iloc[0].to_numpy(dtype=float),
                               row[columns].to_numpy(dtype=float), rtol=1e-12)


def test_rinex305_glonass_records_have_a_fourth_line(tmp_path):
    """RINEX 3.05 adds a status-flags line to each GLONASS record (Table A10): refdata 1e's
    R01 and G01 records, the former given that line, read as in the 3.04 file."""
    source = _need(REF / "gnss/multignss_2023-03-14_gnss_lib_py"
                   / "BRDM00DLR_S_20230730000_01D_MN.rnx")
    lines = source.read_text().splitlines()
    end = next(i for i, x in enumerate(lines) if "END OF HEADER" in x)
    r01 = next(i for i, x in enumerate(lines) if x.startswith("R01"))
    g01 = next(i for i, x in enumerate(lines) if x.startswith("G01"))
    header = [lines[0].replace("3.04", "3.05", 1)] + lines[1:end + 1]
    flags = "    " + _d19(0.0) + _d19(0.0) + _d19(0.0) + _d19(0.0)
    text = header + lines[r01:r01 + 4] + [flags] + lines[g01:g01 + 8]
    (tmp_path / "v305.rnx").write_text("\n".join(text) + "\n")
    got = read_rinex_nav(tmp_path / "v305.rnx").set_index(["system", "sv"])
    want = read_rinex_nav(source).groupby(["system", "sv"]).first()
    assert list(got.index) == [("G", 1), ("R", 1)]
    for key in got.index:
        np.testing.assert_allclose(got.loc[key, ["toe", "af0", "glo_x", "sqrt_a"]].to_numpy(float),
                                   want.loc[key, ["toe", "af0", "glo_x", "sqrt_a"]].to_numpy(float))


def test_glonass_records_are_never_used_beyond_their_integrated_span():
    """Even when a caller allows older records (an almanac's week), a GLONASS record is not
    selected beyond the +-30 min its orbit is integrated over."""
    from simulator.gnss.ephemeris import ephemeris_arrays, select_ephemeris

    nav = read_rinex_nav(_need(REF / "gnss/multignss_2023-03-14_gnss_lib_py"
                               / "BRDM00DLR_S_20230730000_01D_MN.rnx"))
    eph = ephemeris_arrays(nav, 2253)
    last_tb = nav.loc[(nav["system"] == "R") & (nav["sv"] == 1), "toe"].max()
    t = np.array([last_tb + GLONASS_MAX_AGE_S, last_tb + GLONASS_MAX_AGE_S + 1.0])
    idx = select_ephemeris(eph, 1, t, max_age_s=7 * 86400.0, system="R")
    assert idx[0] >= 0 and idx[1] == -1
    gps = select_ephemeris(eph, 1, t + 86400.0, max_age_s=7 * 86400.0, system="G")
    assert (gps >= 0).all()  # other systems take the caller's limit
