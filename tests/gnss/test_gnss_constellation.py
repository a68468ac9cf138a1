"""The nominal GPS constellation: the slot table of the SPS Performance Standard reproduced at
its epoch from the broadcast-style elements (through the IS-GPS-200 orbit code), with and without
the expandable slots split, the nominal orbit shape, the two-revolutions-per-sidereal-day
ground-track repeat, and global coverage."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pytest

from simulator.earth import geodetic_to_ecef, ned_to_ecef_matrix
from simulator.gnss.constants import OMEGA_E_DOT_RAD_S
from simulator.gnss.constellation import (
    AFT_PRN,
    EXPANDABLE_SLOTS,
    GHA_EPOCH_RAD,
    NOMINAL_SLOTS,
    RAAN_RATE_RAD_S,
    REPEAT_PERIOD_S,
    SLOT_EPOCH_UTC,
    nominal_gps_navigation,
    nominal_slots,
)
from simulator.gnss.ephemeris import ephemeris_arrays, gather, satellite_state, select_ephemeris
from simulator.timebase import utc_to_gps


def _states(utc: dt.datetime, seconds: np.ndarray, span_s: float = 86400.0,
            expanded: tuple[str, ...] = ()):
    nav = nominal_gps_navigation(utc, span_s, expanded=expanded)
    week, tow = utc_to_gps(utc)
    eph = ephemeris_arrays(nav, week)
    sv = nominal_slots(expanded)["prn"].to_numpy()
    t = tow + np.asarray(seconds, dtype=float)
    idx = select_ephemeris(eph, sv[:, None], t[None, :])
    assert (idx >= 0).all()
    return satellite_state(gather(eph, idx), np.broadcast_to(t, idx.shape))


def _visible(pos: np.ndarray, lat: float, lon: float, mask_deg: float = 5.0) -> np.ndarray:
    """Number of satellites above the mask at each epoch (pos: satellites x epochs x 3)."""
    lat_r, lon_r = np.radians(lat), np.radians(lon)
    los = pos - geodetic_to_ecef(lat_r, lon_r, 0.0)
    los /= np.linalg.norm(los, axis=-1, keepdims=True)
    down = los @ ned_to_ecef_matrix(lat_r, lon_r)[:, 2]
    return (-down > np.sin(np.radians(mask_deg))).sum(axis=0)


@pytest.mark.parametrize("expanded", [(), ("B1", "D2", "F2")])
def test_slot_table_is_reproduced_at_its_epoch(expanded):
    state = _states(SLOT_EPOCH_UTC, np.array([0.0]), expanded=expanded)
    r_e, v_e = state["pos"][:, 0], state["vel"][:, 0]
    # ECEF -> inertial (true-of-date equator, x to the vernal equinox) through the Greenwich
    # hour angle of the epoch; inertial velocity adds omega_e x r
    c, s = np.cos(GHA_EPOCH_RAD), np.sin(GHA_EPOCH_RAD)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    r_i = r_e @ rot.T
    v_i = (v_e + np.cross([0.0, 0.0, OMEGA_E_DOT_RAD_S], r_e)) @ rot.T
    # the orbital plane itself turns with the nodal regression; its node is that of the motion
    # within the plane
    v_i = v_i - np.cross([0.0, 0.0, RAAN_RATE_RAD_S], r_i)
    h = np.cross(r_i, v_i)
    node = np.cross([0.0, 0.0, 1.0], h)
    raan = np.degrees(np.arctan2(node[:, 1], node[:, 0])) % 360.0
    cos_u = np.einsum("ij,ij->i", node, r_i) / (np.linalg.norm(node, axis=1)
                                                 * np.linalg.norm(r_i, axis=1))
    u = np.degrees(np.arccos(np.clip(cos_u, -1, 1)))
    u = np.where(r_i[:, 2] >= 0, u, 360.0 - u)
    inc = np.degrees(np.arccos(h[:, 2] / np.linalg.norm(h, axis=1)))
    want = nominal_slots(expanded)[["raan_deg", "arg_lat_deg"]].to_numpy()
    assert len(want) == 24 + len(expanded)  # each split slot adds one satellite
    np.testing.assert_allclose(raan, want[:, 0], atol=1e-6)
    # published values in 0-360 deg; F2F's 0.456 deg is reproduced as such
    np.testing.assert_allclose(u, want[:, 1], atol=1e-6)
    np.testing.assert_allclose(inc, 55.0, atol=1e-9)
    # circular orbits of the nominal semi-major axis, 26 559.7 km +- 17 km (SPS PS)
    radius = np.linalg.norm(r_e, axis=1)
    assert np.ptp(radius) < 1e-3 and abs(radius.mean() - 26559.7e3) < 17e3


def test_ground_track_repeats_every_sidereal_day_on_any_date():
    utc = dt.datetime(2031, 3, 4, 5, 6)
    t = np.array([0.0, REPEAT_PERIOD_S])
    pos = _states(utc, t, span_s=2 * 86400.0)["pos"]
    assert 86100 < REPEAT_PERIOD_S < 86170  # a sidereal day, lengthened by the node regression
    assert np.abs(pos[:, 1] - pos[:, 0]).max() < 1.0


@pytest.mark.parametrize("lat", [-60.0, -20.0, 0.0, 37.5, 70.0])
def test_at_least_four_satellites_everywhere_all_day(lat):
    """The 24-slot design keeps four or more satellites above a 5 deg mask at every place and
    time (SPS PS 2020, section 3.6 coverage standard, 100 % for the baseline 24 slots)."""
    t = np.arange(0.0, 86400.0, 600.0)
    pos = _states(dt.datetime(2024, 5, 1), t)["pos"]
    for lon in (-150.0, -30.0, 60.0, 127.0):
        visible = _visible(pos, lat, lon)
        assert visible.min() >= 4
        assert 6 <= visible.mean() <= 12


# SPS PS 2008 Table 3.4-1/3.4-2 at 1993-07-01 against the 5th edition (2020) Tables 3.2-1/3.2-2,
# which restate the same slots at 2016-12-31 23:59:43 UTC: (RAAN deg, argument of latitude deg)
# of the expandable slots and their fore/aft locations there (as transcribed in
# github.com/ashfordeOU/kshana, src/constellation.rs)
SPS_PS_2020_EXPANDABLE = {
    "B1": (348.85, 52.37), "B1F": (348.85, 66.33), "B1A": (348.85, 37.77),
    "D2": (108.85, 236.86), "D2F": (108.85, 254.09), "D2A": (108.85, 229.39),
    "F2": (228.85, 316.64), "F2F": (228.85, 331.87), "F2A": (228.85, 305.43),
}


def test_expandable_slots_agree_with_the_2020_edition():
    """Every location moves by the same (RAAN, argument of latitude) shift between the two
    editions, so the fore/aft locations are the same places relative to the baseline slots."""
    here = {**NOMINAL_SLOTS, **{k: v for pair in EXPANDABLE_SLOTS.values()
                                for k, v in pair.items()}}
    shift = np.array([np.subtract(v, here[k]) for k, v in SPS_PS_2020_EXPANDABLE.items()])
    shift = (shift + 180.0) % 360.0 - 180.0
    np.testing.assert_allclose(shift[:, 0], 16.003, atol=0.006)
    np.testing.assert_allclose(shift[:, 1], -28.586, atol=0.006)


def test_fore_and_aft_straddle_their_baseline_slot_in_its_plane():
    for slot, pair in EXPANDABLE_SLOTS.items():
        raan, u = NOMINAL_SLOTS[slot]
        (fore, (raan_f, u_f)), (aft, (raan_a, u_a)) = pair.items()
        assert (fore, aft) == (slot + "F", slot + "A")
        assert raan_f == raan_a == raan
        ahead, behind = (u_f - u) % 360.0, (u - u_a) % 360.0
        assert 5.0 < ahead < 20.0 and 5.0 < behind < 20.0


def test_expanded_slots_replace_their_baseline_slot():
    base = nominal_slots()
    assert list(base["prn"]) == list(range(1, 25)) and list(base["slot"]) == list(NOMINAL_SLOTS)
    full = nominal_slots(["B1", "D2", "F2"])
    assert len(full) == 27 and list(full["prn"]) == list(range(1, 28))
    assert not {"B1", "D2", "F2"} & set(full["slot"])
    # six planes: four slots in A, C, E and five in B, D, F
    per_plane = full.groupby("raan_deg")["slot"].agg(lambda s: sorted({x[0] for x in s}))
    assert len(per_plane) == 6 and all(len(p) == 1 for p in per_plane)
    counts = full.groupby(full["slot"].str[0]).size().to_dict()
    assert counts == {"A": 4, "B": 5, "C": 4, "D": 5, "E": 4, "F": 5}
    # the fore location keeps its slot's PRN, the aft one has its own; the rest is unchanged
    by_slot = full.set_index("slot")
    assert by_slot.loc["B1F", "prn"] == 5 and by_slot.loc["D2F", "prn"] == 14
    assert by_slot.loc["F2F", "prn"] == 22
    assert {s: by_slot.loc[s, "prn"] for s in AFT_PRN} == AFT_PRN
    kept = base[~base["slot"].isin(["B1", "D2", "F2"])]
    np.testing.assert_array_equal(
        by_slot.loc[kept["slot"], ["prn", "raan_deg", "arg_lat_deg"]].to_numpy(),
        kept[["prn", "raan_deg", "arg_lat_deg"]].to_numpy())
    # one slot alone: same PRNs for its pair as in the full set
    d2 = nominal_slots(["D2"]).set_index("slot")
    assert len(d2) == 25 and d2.loc["D2F", "prn"] == 14 and d2.loc["D2A", "prn"] == 26
    with pytest.raises(ValueError, match="not expandable slot"):
        nominal_slots(["A1"])


def test_expanded_constellation_shows_more_satellites():
    t = np.arange(0.0, 86400.0, 600.0)
    utc = dt.datetime(2024, 5, 1)
    pos24 = _states(utc, t)["pos"]
    pos27 = _states(utc, t, expanded=("B1", "D2", "F2"))["pos"]
    mean24, mean27 = [], []
    for lat in (-60.0, -20.0, 0.0, 37.5, 70.0):
        for lon in (-150.0, -30.0, 60.0, 127.0):
            n24, n27 = _visible(pos24, lat, lon), _visible(pos27, lat, lon)
            assert (n27 >= n24).all() and n27.min() >= 4
            mean24.append(n24.mean())
            mean27.append(n27.mean())
    # three more satellites of 24: on average about 27/24 as many in view
    ratio = np.mean(mean27) / np.mean(mean24)
    assert np.mean(mean27) > np.mean(mean24) + 0.5
    assert 1.05 < ratio < 1.2
