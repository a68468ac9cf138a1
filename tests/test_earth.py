"""The Earth model and frame helpers against published values and an independent library."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from simulator import earth


def test_normal_gravity_published_surface_values():
    # TR8350.2 eq. 4-1 defines gamma at the equator and pole; 45 deg and 30 deg values are the
    # ones printed in independent public test suites (refdata tables README).
    lat = np.radians([0.0, 30.0, 45.0, 90.0])
    expected = [9.7803253359, 9.793247269215307, 9.80619776937, 9.8321849378]
    np.testing.assert_allclose(earth.normal_gravity(lat, 0.0), expected, atol=2e-10)


def test_normal_gravity_free_air_gradient():
    # The normal free-air gradient is about -0.3086 mGal/m (Heiskanen & Moritz 1967, eq. 2-124)
    lat = np.radians(45.0)
    gradient = (earth.normal_gravity(lat, 100.0) - earth.normal_gravity(lat, 0.0)) / 100.0
    assert gradient == pytest.approx(-3.086e-6, rel=2e-3)


def test_normal_gravity_table(shared_dir):
    table = pd.read_csv(shared_dir / "refdata/tables/wgs84_normal_gravity.csv", comment="#")
    got = earth.normal_gravity(np.radians(table.lat_deg.to_numpy()), table.h_m.to_numpy())
    np.testing.assert_allclose(got, table.gamma_m_s2, atol=1e-9)


def test_radii_of_curvature_closed_forms():
    rn, re = earth.radii_of_curvature(np.radians([0.0, 90.0]))
    assert re[0] == pytest.approx(earth.A_M)
    assert rn[0] == pytest.approx(earth.A_M * (1 - earth.E2))
    # at the pole both radii equal a^2 / b
    assert rn[1] == pytest.approx(earth.A_M**2 / earth.B_M)
    assert re[1] == pytest.approx(earth.A_M**2 / earth.B_M)


def test_meridian_radius_against_meridian_arc():
    # independent check: a short meridian arc length computed from the ellipse directly
    lat0, lat1 = np.radians(45.0), np.radians(45.001)
    lats = np.linspace(lat0, lat1, 20001)
    x, z = (earth.geodetic_to_ecef(lats, 0.0, 0.0)[:, i] for i in (0, 2))
    arc = np.sum(np.hypot(np.diff(x), np.diff(z)))
    rn, _ = earth.radii_of_curvature(np.radians(45.0005))
    assert rn * (lat1 - lat0) == pytest.approx(arc, rel=1e-9)


def test_ecef_pairs(shared_dir):
    # the source column holds commas, so only the six numeric columns are read
    table = pd.read_csv(shared_dir / "refdata/tables/ecef_geodetic_pairs.csv", comment="#",
                        usecols=range(6), engine="python")
    assert len(table) == 9
    xyz = earth.geodetic_to_ecef(np.radians(table.lat_deg), np.radians(table.lon_deg),
                                 table.h_m.to_numpy())
    np.testing.assert_allclose(xyz, table[["x_m", "y_m", "z_m"]], atol=1e-3)
    lat, lon, h = earth.ecef_to_geodetic(table[["x_m", "y_m", "z_m"]].to_numpy())
    np.testing.assert_allclose(np.degrees(lat), table.lat_deg, atol=1e-7)
    np.testing.assert_allclose(h, table.h_m, atol=1e-3)


def test_ecef_published_pair():
    # pymap3d's test_geodetic: (42, -82, 200 m) <-> (660675.2518247, -4700948.68316, 4245737.66222)
    xyz = earth.geodetic_to_ecef(np.radians(42.0), np.radians(-82.0), 200.0)
    np.testing.assert_allclose(xyz, [660675.2518247, -4700948.68316, 4245737.66222],
                               atol=1e-4)


def test_ecef_to_geodetic_keeps_the_shape_of_one_point():
    """One point as (1, 3) gives arrays of shape (1,) (pymap3d returns its latitude as a
    scalar; a 2D fix held at one epoch broke on it), and the same published pair back."""
    xyz = np.array([[660675.2518247, -4700948.68316, 4245737.66222]])
    lat, lon, alt = earth.ecef_to_geodetic(xyz)
    assert lat.shape == lon.shape == alt.shape == (1,)
    np.testing.assert_allclose([np.degrees(lat[0]), np.degrees(lon[0]), alt[0]],
                               [42.0, -82.0, 200.0], atol=1e-6)


def test_ned_frame_published_enu_example():
    # RTKLIB t_coord.c utest3: at 35 N 140 E the ECEF vector (0.3, 0.4, 0.5) has ENU
    # (-0.499254, 0.393916, 0.309152)
    c_ne = earth.ned_to_ecef_matrix(np.radians(35.0), np.radians(140.0))
    ned = c_ne.T @ np.array([0.3, 0.4, 0.5])
    np.testing.assert_allclose([ned[1], ned[0], -ned[2]], [-0.499254, 0.393916, 0.309152],
                               atol=1e-6)


def test_earth_and_transport_rates():
    lat = np.radians(37.0)
    w = earth.earth_rate_ned(lat)[0]
    assert np.linalg.norm(w) == pytest.approx(earth.OMEGA_E_RAD_S)
    assert w[2] == pytest.approx(-earth.OMEGA_E_RAD_S * np.sin(lat))
    # moving east at v along a parallel turns the frame about the north axis at v / (R_E + h)
    _, re = earth.radii_of_curvature(lat)
    w_en = earth.transport_rate_ned(lat, 100.0, np.array([0.0, 20.0, 0.0]))[0]
    assert w_en[0] == pytest.approx(20.0 / (re + 100.0))
    assert w_en[1] == 0.0


@pytest.mark.parametrize("angles", [(0.1, -0.2, 2.5), (-1.0, 0.7, -3.0), (0.0, 0.0, 0.3)])
def test_attitude_helpers_against_scipy(angles):
    roll, pitch, yaw = angles
    reference = Rotation.from_euler("ZYX", [yaw, pitch, roll]).as_matrix()
    np.testing.assert_allclose(earth.euler_to_dcm(roll, pitch, yaw), reference, atol=1e-14)
    q = earth.euler_to_quat(roll, pitch, yaw)
    np.testing.assert_allclose(earth.quat_to_dcm(q), reference, atol=1e-14)
    np.testing.assert_allclose(earth.quat_to_euler(q), angles, atol=1e-12)
    rotvec = np.array([0.3, -0.2, 0.5])
    q2 = earth.rotvec_to_quat(rotvec)
    np.testing.assert_allclose(earth.quat_to_dcm(q2), Rotation.from_rotvec(rotvec).as_matrix(),
                               atol=1e-14)
    combined = earth.quat_to_dcm(earth.quat_multiply(q, q2))
    np.testing.assert_allclose(combined, reference @ Rotation.from_rotvec(rotvec).as_matrix(),
                               atol=1e-14)


def test_wrap_angle():
    np.testing.assert_allclose(earth.wrap_angle(np.array([3 * np.pi / 2, -3 * np.pi / 2, 0.1])),
                               [-np.pi / 2, np.pi / 2, 0.1])


def test_ned_to_body_is_the_transposed_dcm():
    rng = np.random.default_rng(3)
    roll, pitch, yaw = rng.uniform(-3, 3, (3, 50))
    v = rng.normal(size=(50, 3))
    expected = np.einsum("nji,nj->ni", earth.euler_to_dcm(roll, pitch, yaw), v)
    np.testing.assert_allclose(earth.ned_to_body(roll, pitch, yaw, v), expected, atol=1e-14)


def test_geodetic_rates_of_a_velocity_and_an_offset():
    """Groves eq. 2.111 against the exact ECEF route: a 1 m north and east offset at 45 deg
    moves the geodetic position as the rates say (to the offset's second order), and a
    meridian degree has its tabulated length."""
    from simulator.earth import ecef_to_geodetic, geodetic_rates, ned_to_ecef

    lat0, lon0, alt0 = np.radians(45.0), np.radians(10.0), 300.0
    offset = np.array([1.0, 1.0, -2.0])
    d_lat, d_lon, d_alt = geodetic_rates(lat0, alt0, offset)
    moved = ecef_to_geodetic(ned_to_ecef(offset[None, :], lat0, lon0, alt0))
    lat, lon, alt = (float(np.ravel(x)[0]) for x in moved)
    np.testing.assert_allclose([lat - lat0, lon - lon0], [d_lat, d_lon], rtol=1e-6)
    np.testing.assert_allclose(alt - alt0, d_alt, atol=1e-6)
    # a degree of latitude at 45 deg: 111 132.954 - 559.822 cos 2L + 1.175 cos 4L = 111 131.78 m
    # (the series for the WGS-84 meridian degree, e.g. the "Latitude" article's table)
    metres_per_degree = np.radians(1.0) / geodetic_rates(lat0, 0.0, [1.0, 0.0, 0.0])[0]
    assert abs(metres_per_degree - (111132.954 - 1.175)) < 0.01


def test_single_vector_fast_paths_equal_the_stacked_forms():
    rng = np.random.default_rng(5)
    v = rng.normal(size=(4, 3))
    q = earth.euler_to_quat(*rng.normal(size=(3, 4)))
    np.testing.assert_array_equal(earth.skew(v[1]), earth.skew(v)[1])
    np.testing.assert_allclose(earth.skew(v[2]) @ v[3], np.cross(v[2], v[3]), atol=1e-14)
    np.testing.assert_allclose(earth.quat_to_dcm(q[3]), earth.quat_to_dcm(q)[3], atol=1e-15)


def test_quat_to_rotvec_inverts_rotvec_to_quat():
    rng = np.random.default_rng(11)
    axis = rng.normal(size=(6, 3))
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    angles = np.array([0.0, 1e-9, 1e-4, 0.5, 3.0, np.pi - 1e-6])
    rotvec = axis * angles[:, None]
    np.testing.assert_allclose(earth.quat_to_rotvec(earth.rotvec_to_quat(rotvec)), rotvec,
                               rtol=1e-9, atol=1e-15)
    # -q is the same rotation; beyond pi the shorter rotation the other way comes back
    q = earth.rotvec_to_quat(rotvec[3])
    np.testing.assert_allclose(earth.quat_to_rotvec(-q), rotvec[3], rtol=1e-12)
    long_way = axis[4] * (2 * np.pi - 0.5)
    np.testing.assert_allclose(earth.quat_to_rotvec(earth.rotvec_to_quat(long_way)),
                               -axis[4] * 0.5, rtol=1e-9)


@pytest.mark.parametrize("shape", [(), (1,), (2,), (2, 3)])
def test_ecef_to_geodetic_keeps_the_input_shape(shape):
    """One position in a one-row array gives one-row arrays (pymap3d returns a scalar
    latitude for it, which broke the receiver's 2-D fix when a single epoch held its height)."""
    lat, lon, alt = np.radians(37.5), np.radians(127.0), 40.0
    xyz = np.broadcast_to(earth.geodetic_to_ecef(lat, lon, alt).reshape(3), shape + (3,))
    out = earth.ecef_to_geodetic(xyz)
    assert all(v.shape == shape for v in out)
    np.testing.assert_allclose(out[0], lat, atol=1e-12)
    np.testing.assert_allclose(out[2], alt, atol=1e-6)
