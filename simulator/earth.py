"""Earth model and frames: the one home of landnav's shared geodesy and attitude math.

Holds the WGS-84 ellipsoid, its radii of curvature, normal gravity, the Earth rotation rate, the
transport rate, conversions between geodetic, ECEF and local NED coordinates, and the
Euler-angle / direction-cosine-matrix / quaternion helpers every other module uses.

Conventions (SPEC section 2): ECEF is WGS-84; the navigation frame is local NED; the body frame is
FRD; attitude is roll, pitch, yaw (ZYX Euler, yaw from true north, clockwise positive). Latitude
and longitude are in radians inside this module unless a name ends in ``_deg``.

Public functions
----------------
radii_of_curvature, radii_of_curvature_from_sin, normal_gravity, normal_gravity_from_sin,
gravity_ned, earth_rate_ned, transport_rate_ned, geodetic_rates, geodetic_to_ecef, ecef_to_geodetic,
ned_to_ecef_matrix, ecef_to_ned, ned_to_ecef, ned_to_ecef_vector, euler_to_dcm, ned_to_body,
ned_to_body_trig, ned_to_body_components, body_to_ned_components, dcm_to_euler, euler_to_quat,
quat_to_dcm, quat_to_euler, quat_multiply, rotvec_to_quat, quat_to_rotvec, wrap_angle, skew.

References
----------
Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed.,
2013 (cited as "Groves"). NIMA TR8350.2, *Department of Defense World Geodetic System 1984*,
3rd ed. (cited as "TR8350.2").
"""

from __future__ import annotations

import functools

import numpy as np

A_M = 6378137.0  # WGS-84 semi-major axis, m (TR8350.2 Table 3.1)
F = 1.0 / 298.257223563  # WGS-84 flattening (TR8350.2 Table 3.1)
E2 = F * (2.0 - F)  # first eccentricity squared
B_M = A_M * (1.0 - F)  # semi-minor axis, m
OMEGA_E_RAD_S = 7.292115e-5  # Earth rotation rate, rad/s (TR8350.2 Table 3.1; SPEC section 2)
GM_M3_S2 = 3.986004418e14  # Earth gravitational constant, m^3/s^2 (TR8350.2 Table 3.1)
GAMMA_E_M_S2 = 9.7803253359  # normal gravity at the equator, m/s^2 (TR8350.2 eq. 4-1)
GAMMA_P_M_S2 = 9.8321849378  # normal gravity at the poles, m/s^2 (TR8350.2 eq. 4-1)
SOMIGLIANA_K = 0.00193185265241  # Somigliana constant k = b*gp/(a*ge) - 1 (TR8350.2 eq. 4-1)
M_RATIO = 0.00344978650684  # m = w^2 a^2 b / GM (TR8350.2 eq. 4-3)
G0_M_S2 = 9.80665  # standard gravity g_0, m/s^2 (unit conversions of "mg", "g")



@functools.cache
def _pymap3d():
    """pymap3d and its WGS-84 ellipsoid, imported on first use: about 10 ms of a start (it loads
    dateutil), which the generation of a drive without ECEF conversions does not need."""
    import pymap3d

    return pymap3d, pymap3d.Ellipsoid.from_name("wgs84")


def radii_of_curvature(lat_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Meridian (north-south) and transverse (east-west) radii of curvature, m.

    Groves eqs. 2.105 and 2.106: R_N = a (1 - e^2) / (1 - e^2 sin^2 L)^1.5 and
    R_E = a / sqrt(1 - e^2 sin^2 L).
    """
    return radii_of_curvature_from_sin(np.sin(lat_rad))


def radii_of_curvature_from_sin(sin_lat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``radii_of_curvature`` from the sine of the latitude (Groves eqs. 2.105 and 2.106), for
    callers that already have it."""
    re = A_M / np.sqrt(1.0 - E2 * sin_lat * sin_lat)
    return re * re * re * (1.0 - E2) / (A_M * A_M), re


def normal_gravity(lat_rad: np.ndarray, alt_m: np.ndarray) -> np.ndarray:
    """WGS-84 normal gravity magnitude at latitude and ellipsoidal height, m/s^2.

    Somigliana's closed formula (TR8350.2 eq. 4-1) with the second-order height correction
    (TR8350.2 eq. 4-3). Normal gravity includes the centrifugal acceleration of the Earth's
    rotation, so it is what an accelerometer at rest measures (with opposite sign).
    """
    return normal_gravity_from_sin(np.sin(lat_rad), alt_m)


def normal_gravity_from_sin(sin_lat: np.ndarray, alt_m: np.ndarray) -> np.ndarray:
    """``normal_gravity`` from the sine of the latitude (TR8350.2 eqs. 4-1 and 4-3), for callers
    that already have it."""
    s2 = sin_lat * sin_lat
    gamma0 = GAMMA_E_M_S2 * (1.0 + SOMIGLIANA_K * s2) / np.sqrt(1.0 - E2 * s2)
    h = np.asarray(alt_m, dtype=float)
    return gamma0 * (
        1.0 - 2.0 / A_M * (1.0 + F + M_RATIO - 2.0 * F * s2) * h + 3.0 / A_M**2 * h**2
    )


def gravity_ned(lat_rad: np.ndarray, alt_m: np.ndarray) -> np.ndarray:
    """Normal gravity vector in NED, shape (n, 3): (0, 0, gamma) (the deflection is neglected)."""
    g = np.atleast_1d(normal_gravity(lat_rad, alt_m))
    out = np.zeros(g.shape + (3,))
    out[..., 2] = g
    return out


def earth_rate_ned(lat_rad: np.ndarray) -> np.ndarray:
    """Earth rotation rate resolved in NED, shape (n, 3), rad/s (Groves eq. 5.41)."""
    lat = np.atleast_1d(lat_rad)
    return np.stack(
        [OMEGA_E_RAD_S * np.cos(lat), np.zeros_like(lat), -OMEGA_E_RAD_S * np.sin(lat)], axis=-1
    )


def transport_rate_ned(lat_rad: np.ndarray, alt_m: np.ndarray, v_ned: np.ndarray) -> np.ndarray:
    """Transport rate (NED w.r.t. ECEF) resolved in NED, shape (n, 3), rad/s (Groves eq. 5.44)."""
    lat = np.atleast_1d(lat_rad)
    rn, re = radii_of_curvature(lat)
    v = np.atleast_2d(v_ned)
    return np.stack(
        [
            v[..., 1] / (re + alt_m),
            -v[..., 0] / (rn + alt_m),
            -v[..., 1] * np.tan(lat) / (re + alt_m),
        ],
        axis=-1,
    )


def geodetic_rates(lat_rad: np.ndarray, alt_m: np.ndarray, v_ned: np.ndarray,
                   radii: tuple[np.ndarray, np.ndarray] | None = None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Latitude, longitude and height rates (rad/s, rad/s, m/s) of a NED velocity (Groves eq.
    2.111): v_N / (R_N + h), v_E / ((R_E + h) cos L), -v_D. Given a small NED displacement
    (m) instead of a velocity, the same expressions are its change of latitude, longitude
    (rad) and height (m) to first order: the one home of "NED offset to geodetic".

    Parameters
    ----------
    lat_rad, alt_m : float or array, shape (n,); latitude L and ellipsoidal height h.
    v_ned : array, shape (3,) or (n, 3).
    radii : ``radii_of_curvature(lat_rad)`` when the caller already has them.
    """
    rn, re = radii_of_curvature(lat_rad) if radii is None else radii
    v = np.asarray(v_ned)
    return v[..., 0] / (rn + alt_m), v[..., 1] / ((re + alt_m) * np.cos(lat_rad)), -v[..., 2]


def geodetic_to_ecef(lat_rad: np.ndarray, lon_rad: np.ndarray, alt_m: np.ndarray) -> np.ndarray:
    """Geodetic (rad, rad, m) to ECEF, shape (n, 3), m (pymap3d.geodetic2ecef, WGS-84)."""
    pymap3d, wgs84 = _pymap3d()
    x, y, z = pymap3d.geodetic2ecef(lat_rad, lon_rad, alt_m, ell=wgs84, deg=False)
    return np.stack(np.broadcast_arrays(x, y, z), axis=-1)


def ecef_to_geodetic(xyz_m: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ECEF (m), shape (..., 3), to geodetic latitude, longitude (rad) and height (m).

    Uses pymap3d.ecef2geodetic (WGS-84).
    """
    xyz = np.asarray(xyz_m, dtype=float)
    pymap3d, wgs84 = _pymap3d()
    lat, lon, alt = pymap3d.ecef2geodetic(
        xyz[..., 0], xyz[..., 1], xyz[..., 2], ell=wgs84, deg=False
    )
    # pymap3d squeezes the latitude of a single position to a scalar: give every output the
    # input's shape (a one-row array stays one row)
    shape = xyz.shape[:-1]
    return (np.reshape(lat, shape), np.reshape(lon, shape), np.reshape(alt, shape))


def ned_to_ecef_matrix(lat_rad: np.ndarray, lon_rad: np.ndarray) -> np.ndarray:
    """Rotation matrix C_n^e from NED to ECEF, shape (..., 3, 3) (Groves eq. 2.150, transposed)."""
    sl, cl = np.sin(lat_rad), np.cos(lat_rad)
    so, co = np.sin(lon_rad), np.cos(lon_rad)
    return np.stack(
        [
            np.stack([-sl * co, -so, -cl * co], axis=-1),
            np.stack([-sl * so, co, -cl * so], axis=-1),
            np.stack([cl, np.zeros_like(cl), -sl], axis=-1),
        ],
        axis=-2,
    )


def ecef_to_ned(
    xyz_m: np.ndarray, lat0_rad: float, lon0_rad: float, alt0_m: float
) -> np.ndarray:
    """ECEF points to local NED coordinates about a reference point, shape (n, 3), m."""
    ref = geodetic_to_ecef(lat0_rad, lon0_rad, alt0_m)
    c_ne = ned_to_ecef_matrix(lat0_rad, lon0_rad)
    return (np.asarray(xyz_m) - ref) @ c_ne


def ned_to_ecef(ned_m: np.ndarray, lat0_rad: float, lon0_rad: float, alt0_m: float) -> np.ndarray:
    """Local NED coordinates about a reference point (n, 3), m, to ECEF points (n, 3), m
    (the inverse of ``ecef_to_ned``)."""
    ref = geodetic_to_ecef(lat0_rad, lon0_rad, alt0_m)
    c_ne = ned_to_ecef_matrix(lat0_rad, lon0_rad)
    return ref + np.asarray(ned_m) @ c_ne.T


def ned_to_ecef_vector(v_ned: np.ndarray, lat_rad: np.ndarray, lon_rad: np.ndarray) -> np.ndarray:
    """Rotate NED vectors (n, 3) into ECEF at the given positions."""
    c_ne = ned_to_ecef_matrix(lat_rad, lon_rad)
    return np.einsum("...ij,...j->...i", c_ne, v_ned)


def skew(v: np.ndarray) -> np.ndarray:
    """Skew-symmetric (cross-product) matrix of vectors, shape (..., 3, 3)."""
    v = np.asarray(v, dtype=float)
    if v.ndim == 1:  # one vector: 20 times faster than the stacked form (filter inner loops)
        return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    z = np.zeros(v.shape[:-1])
    return np.stack(
        [
            np.stack([z, -v[..., 2], v[..., 1]], axis=-1),
            np.stack([v[..., 2], z, -v[..., 0]], axis=-1),
            np.stack([-v[..., 1], v[..., 0], z], axis=-1),
        ],
        axis=-2,
    )


# 2 pi as the sum of three doubles (Cody and Waite), the first two with 33 significant bits, so
# that k times each of them is exact for whole turns |k| < 2^20
_TWO_PI_PARTS = (float.fromhex("0x1.921fb544p+2"), float.fromhex("0x1.0b4611a6p-32"),
                 float.fromhex("0x1.3198a2e037073p-67"))


def quat_to_rotvec(q: np.ndarray) -> np.ndarray:
    """Rotation vector (rad) of scalar-first unit quaternions, shape (..., 3): the inverse of
    ``rotvec_to_quat``, the shorter of the two rotations (angle in [0, pi])."""
    q = np.asarray(q, dtype=float)
    q = np.where(q[..., :1] < 0.0, -q, q)  # q and -q are the same rotation
    v = q[..., 1:]
    s = np.linalg.norm(v, axis=-1)
    angle = 2.0 * np.arctan2(s, q[..., 0])
    # angle / s, with its limit 2 / q0 (times 1 + s^2 / 3 q0^2) for tiny rotations
    small = s < 1e-6
    k = np.where(small, 2.0 / q[..., 0] * (1.0 + s**2 / (3.0 * q[..., 0] ** 2)),
                 angle / np.where(small, 1.0, s))
    return v * k[..., None]


def wrap_angle(angle_rad: np.ndarray) -> np.ndarray:
    """Wrap angles to [-pi, pi).

    a - 2 pi k with k = round(a / 2 pi) the whole turns, 2 pi k subtracted in three exact parts
    (Cody-Waite argument reduction): as accurate as the angle itself, without the rounding of
    a + pi, and several times cheaper than a floating-point remainder. (Sines and cosines of
    the wrapped angle are also cheaper than those of a large one.)
    """
    a = np.atleast_1d(np.asarray(angle_rad, dtype=float))
    turns = np.rint(a * (1.0 / (2.0 * np.pi)))
    wrapped = a - turns * _TWO_PI_PARTS[0]
    for part in _TWO_PI_PARTS[1:]:
        wrapped -= turns * part
    # a rounding may leave a result a hair outside [-pi, pi): fold it back
    wrapped[wrapped >= np.pi] -= 2.0 * np.pi
    wrapped[wrapped < -np.pi] += 2.0 * np.pi
    return wrapped.reshape(np.shape(angle_rad))[()]


def euler_to_dcm(roll: np.ndarray, pitch: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Body-to-NED DCM C_b^n from ZYX Euler angles (rad), shape (..., 3, 3) (Groves eq. 2.22)."""
    cr, sr = np.cos(roll), np.sin(roll)
    cp, sp = np.cos(pitch), np.sin(pitch)
    cy, sy = np.cos(yaw), np.sin(yaw)
    return np.stack(
        [
            np.stack([cp * cy, -cr * sy + sr * sp * cy, sr * sy + cr * sp * cy], axis=-1),
            np.stack([cp * sy, cr * cy + sr * sp * sy, -sr * cy + cr * sp * sy], axis=-1),
            np.stack([-sp, sr * cp, cr * cp], axis=-1),
        ],
        axis=-2,
    )


def ned_to_body(roll: np.ndarray, pitch: np.ndarray, yaw: np.ndarray,
                v_ned: np.ndarray) -> np.ndarray:
    """Resolve NED vectors (n, 3) in the body frame: C_n^b v = (C_b^n)^T v (Groves eq. 2.22),
    written out so no (n, 3, 3) matrix stack is built."""
    return ned_to_body_trig(np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch),
                            np.cos(yaw), np.sin(yaw), v_ned)


def ned_to_body_trig(cr: np.ndarray, sr: np.ndarray, cp: np.ndarray, sp: np.ndarray,
                     cy: np.ndarray, sy: np.ndarray, v_ned: np.ndarray) -> np.ndarray:
    """``ned_to_body`` from the cosines and sines of roll, pitch and yaw."""
    return ned_to_body_components(cr, sr, cp, sp, cy, sy,
                                  v_ned[..., 0], v_ned[..., 1], v_ned[..., 2])


def ned_to_body_components(cr: np.ndarray, sr: np.ndarray, cp: np.ndarray, sp: np.ndarray,
                           cy: np.ndarray, sy: np.ndarray, vn: np.ndarray, ve: np.ndarray,
                           vd: np.ndarray) -> np.ndarray:
    """``ned_to_body_trig`` of the vectors given by their north, east and down components (no
    (n, 3) array of them need be built); returns shape (..., 3), each component contiguous."""
    h = cy * vn + sy * ve  # north/east rotated into the heading frame
    lateral = cy * ve - sy * vn
    vertical = sp * h + cp * vd
    out = np.empty((3,) + np.broadcast_shapes(np.shape(cr), np.shape(vn)))
    out[0] = cp * h - sp * vd
    out[1] = cr * lateral + sr * vertical
    out[2] = cr * vertical - sr * lateral
    return np.moveaxis(out, 0, -1)


def body_to_ned_components(cr: np.ndarray, sr: np.ndarray, cp: np.ndarray, sp: np.ndarray,
                           cy: np.ndarray, sy: np.ndarray, x: np.ndarray, y: np.ndarray,
                           z: np.ndarray) -> np.ndarray:
    """The inverse of ``ned_to_body_components``: body (FRD) components to NED, C_b^n v, each
    rotation undone in reverse order (roll, pitch, yaw); returns shape (..., 3)."""
    lateral = cr * y - sr * z
    vertical = sr * y + cr * z
    h = cp * x + sp * vertical
    out = np.empty((3,) + np.broadcast_shapes(np.shape(cr), np.shape(x)))
    out[0] = cy * h - sy * lateral
    out[1] = sy * h + cy * lateral
    out[2] = cp * vertical - sp * x
    return np.moveaxis(out, 0, -1)


def dcm_to_euler(c_bn: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ZYX Euler angles (roll, pitch, yaw; rad) of a body-to-NED DCM (Groves eq. 2.23)."""
    c = np.asarray(c_bn)
    roll = np.arctan2(c[..., 2, 1], c[..., 2, 2])
    pitch = -np.arcsin(np.clip(c[..., 2, 0], -1.0, 1.0))
    yaw = np.arctan2(c[..., 1, 0], c[..., 0, 0])
    return roll, pitch, yaw


def euler_to_quat(roll: np.ndarray, pitch: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Body-to-NED quaternion (scalar first, Hamilton), shape (..., 4) (Groves eq. 2.39)."""
    cr, sr = np.cos(roll / 2), np.sin(roll / 2)
    cp, sp = np.cos(pitch / 2), np.sin(pitch / 2)
    cy, sy = np.cos(yaw / 2), np.sin(yaw / 2)
    return np.stack(
        [
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        ],
        axis=-1,
    )


def quat_to_dcm(q: np.ndarray) -> np.ndarray:
    """DCM of a scalar-first unit quaternion, shape (..., 3, 3) (Groves eq. 2.34)."""
    q = np.asarray(q, dtype=float)
    if q.ndim == 1:  # one quaternion: the same matrix built without stacking (filter loops)
        a, b, c, d = (float(x) for x in q)
        return np.array([
            [a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)],
            [2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)],
            [2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d]])
    a, b, c, d = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            np.stack([a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)], -1),
            np.stack([2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)], -1),
            np.stack([2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d], -1),
        ],
        axis=-2,
    )


def quat_to_euler(q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ZYX Euler angles (rad) of a body-to-NED quaternion."""
    return dcm_to_euler(quat_to_dcm(q))


def quat_multiply(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product p * q of scalar-first quaternions, shape (..., 4)."""
    p = np.asarray(p, dtype=float)
    q = np.asarray(q, dtype=float)
    a1, b1, c1, d1 = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    a2, b2, c2, d2 = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            a1 * a2 - b1 * b2 - c1 * c2 - d1 * d2,
            a1 * b2 + b1 * a2 + c1 * d2 - d1 * c2,
            a1 * c2 - b1 * d2 + c1 * a2 + d1 * b2,
            a1 * d2 + b1 * c2 - c1 * b2 + d1 * a2,
        ],
        axis=-1,
    )


def rotvec_to_quat(rotvec: np.ndarray) -> np.ndarray:
    """Quaternion of a rotation vector (rad), shape (..., 4), exact for any angle."""
    v = np.asarray(rotvec, dtype=float)
    angle = np.linalg.norm(v, axis=-1)
    half = 0.5 * angle
    # sin(x/2)/x with its Taylor series near zero, so tiny rotations keep full precision
    small = angle < 1e-6
    safe = np.where(small, 1.0, angle)
    k = np.where(small, 0.5 - angle**2 / 48.0, np.sin(half) / safe)
    return np.concatenate([np.cos(half)[..., None], v * k[..., None]], axis=-1)
