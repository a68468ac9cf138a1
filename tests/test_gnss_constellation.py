"""The nominal GPS constellation: the slot table of the SPS Performance Standard reproduced at
its epoch from the broadcast-style elements (through the IS-GPS-200 orbit code), the nominal
orbit shape, the two-revolutions-per-sidereal-day ground-track repeat, and global coverage."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pytest

from simulator.earth import geodetic_to_ecef, ned_to_ecef_matrix
from simulator.gnss.constants import OMEGA_E_DOT_RAD_S
from simulator.gnss.constellation import (
    GHA_EPOCH_RAD,
    NOMINAL_SLOTS,
    RAAN_RATE_RAD_S,
    REPEAT_PERIOD_S,
    SLOT_EPOCH_UTC,
    nominal_gps_navigation,
)
from simulator.gnss.ephemeris import ephemeris_arrays, gather, satellite_state, select_ephemeris
from simulator.timebase import utc_to_gps


def _states(utc: dt.datetime, seconds: np.ndarray, span_s: float = 86400.0):
    nav = nominal_gps_navigation(utc, span_s)
    week, tow = utc_to_gps(utc)
    eph = ephemeris_arrays(nav, week)
    sv = np.arange(1, 25)
    t = tow + np.asarray(seconds, dtype=float)
    idx = select_ephemeris(eph, sv[:, None], t[None, :])
    assert (idx >= 0).all()
    return satellite_state(gather(eph, idx), np.broadcast_to(t, idx.shape))


def test_slot_table_is_reproduced_at_its_epoch():
    state = _states(SLOT_EPOCH_UTC, np.array([0.0]))
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
    want = np.array(list(NOMINAL_SLOTS.values()))
    np.testing.assert_allclose(raan, want[:, 0], atol=1e-6)
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
        lat_r, lon_r = np.radians(lat), np.radians(lon)
        rx = geodetic_to_ecef(lat_r, lon_r, 0.0)
        los = pos - rx
        los /= np.linalg.norm(los, axis=-1, keepdims=True)
        down = los @ ned_to_ecef_matrix(lat_r, lon_r)[:, 2]
        visible = (-down > np.sin(np.radians(5.0))).sum(axis=0)
        assert visible.min() >= 4
        assert 6 <= visible.mean() <= 12
