"""The International Geomagnetic Reference Field (IGRF): main field at geodetic positions.

The model coefficients are those ``ppigrf`` ships (``IGRF14.shc``), read from its package
directory without importing it; the synthesis follows ``ppigrf.igrf`` operation for operation
(geodetic to geocentric conversion, Schmidt semi-normalised associated Legendre functions by
Wertz's recursion, coefficients interpolated linearly in time between the five-yearly models,
back to geodetic north and up), so the field is the package's own to the last bit. It is
written out here because ``ppigrf`` imports pandas (about 0.3 s), which a dataset without GNSS
and faults otherwise never needs. ``tests/test_mag.py`` compares it with ``ppigrf.igrf``.

Public names
------------
igrf_ned.

References
----------
Alken et al., "International Geomagnetic Reference Field: the thirteenth generation", Earth
Planets Space 73, 49 (2021). Wertz (ed.), *Spacecraft Attitude Determination and Control*, 1978,
appendix H (Legendre recursion). Laundal, ``ppigrf`` (MIT licence), ``ppigrf.py``.
"""

from __future__ import annotations

import datetime as dt
import functools
import importlib.util
from pathlib import Path

import numpy as np

RE_KM = 6371.2  # geomagnetic reference radius, km
# WGS-84 as ppigrf writes it: first eccentricity squared and semi-major axis, km
_E2 = 0.00669437999014
_A_KM = 6378.137


@functools.cache
def _coefficients() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(epochs in microseconds since 1970, n, m, g, h) of ppigrf's ``IGRF14.shc``; g and h
    have one row per model epoch and one column per (n, m >= 0), h zero for m = 0."""
    spec = importlib.util.find_spec("ppigrf")
    if spec is None or not spec.submodule_search_locations:
        raise ImportError("the magnetometer needs the ppigrf package (its IGRF coefficients)")
    path = Path(next(iter(spec.submodule_search_locations))) / "IGRF14.shc"
    header, years, g, h = 2, [], {}, {}
    for line in path.read_text().splitlines():
        if line.startswith("#"):
            continue
        if header == 2:
            header -= 1
            continue
        if header == 1:
            years = [float(x) for x in line.split()]
            header -= 1
            continue
        parts = line.split()
        if not parts:
            continue
        n, m = int(parts[0]), int(parts[1])
        values = np.array([float(x) for x in parts[2:]])
        if m >= 0:
            g[n, m] = values
        else:
            h[n, -m] = values
    keys = list(g)
    # the .shc epochs are whole years: January 1st, as ppigrf's yearfrac_to_datetime gives them
    epochs = np.array([_us(dt.datetime(int(y), 1, 1)) for y in years])
    g_mat = np.stack([g[k] for k in keys], axis=1)
    h_mat = np.stack([h.get(k, np.zeros(len(years))) for k in keys], axis=1)
    n, m = np.array(keys).T
    return epochs, n, m, g_mat, h_mat


def _us(date: dt.datetime) -> int:
    """A naive UTC datetime as integer microseconds since 1970 (pandas' time axis for Python
    datetimes)."""
    return int(np.datetime64(date, "us").astype(np.int64))


def _legendre(theta_deg: np.ndarray, keys: list[tuple[int, int]]
              ) -> tuple[np.ndarray, np.ndarray]:
    """Schmidt semi-normalised P_n^m(cos theta) and dP/dtheta, shape (len(theta), len(keys))."""
    n_max = max(k[0] for k in keys)
    m_max = max(k[1] for k in keys)
    theta = theta_deg.flatten()[:, np.newaxis]
    theta_rad = np.radians(theta)
    sinth, costh = np.sin(theta_rad), np.cos(theta_rad)
    p, dp, s = {}, {}, {(0, 0): 1.0}
    for n in range(n_max + 1):
        for m in range(n_max + 1):
            p[n, m] = np.zeros_like(theta, dtype=np.float64)
            dp[n, m] = np.zeros_like(theta, dtype=np.float64)
    p[0, 0] = np.ones_like(theta, dtype=np.float64)
    for n in range(1, n_max + 1):
        for m in range(0, min(n + 1, m_max + 1)):
            if n == m:
                p[n, n] = sinth * p[n - 1, m - 1]
                dp[n, n] = sinth * dp[n - 1, m - 1] + costh * p[n - 1, n - 1]
            elif n == 1:
                p[n, m] = costh * p[n - 1, m]
                dp[n, m] = costh * dp[n - 1, m] - sinth * p[n - 1, m]
            else:
                k_nm = ((n - 1)**2 - m**2) / ((2 * n - 1) * (2 * n - 3))
                p[n, m] = costh * p[n - 1, m] - k_nm * p[n - 2, m]
                dp[n, m] = costh * dp[n - 1, m] - sinth * p[n - 1, m] - k_nm * dp[n - 2, m]
            if m == 0:
                s[n, 0] = s[n - 1, 0] * (2.0 * n - 1) / n
            else:
                s[n, m] = s[n, m - 1] * np.sqrt((n - m + 1) * (int(m == 1) + 1.0) / (n + m))
    for n in range(1, n_max + 1):
        for m in range(0, min(n + 1, m_max + 1)):
            p[n, m] *= s[n, m]
            dp[n, m] *= s[n, m]
    return (np.hstack(tuple(p[k] for k in keys)), np.hstack(tuple(dp[k] for k in keys)))


def _geodetic_to_geocentric(lat_deg: np.ndarray, h_km: np.ndarray
                            ) -> tuple[np.ndarray, np.ndarray]:
    """Geocentric colatitude (deg) and radius (km) of geodetic positions."""
    a, b = _A_KM, _A_KM * np.sqrt(1 - _E2)
    lat = np.radians(lat_deg)
    sin2, cos2 = np.sin(lat)**2, np.cos(lat)**2
    tmp = h_km * np.sqrt(a**2 * cos2 + b**2 * sin2)
    beta = np.arctan((tmp + b**2) / (tmp + a**2) * np.tan(lat))
    theta = np.pi / 2 - beta
    r = np.sqrt(h_km**2 + 2 * tmp + a**2 * (1 - (1 - (b / a)**4) * sin2)
                / (1 - (1 - (b / a)**2) * sin2))
    return np.degrees(theta), r


def _geodetic_latitude(theta_deg: np.ndarray, r_km: np.ndarray) -> np.ndarray:
    """Geodetic latitude (rad) of geocentric colatitude and radius: the series of N. Olsen's
    conversion, as ppigrf's ``geoc2geod``."""
    a, b = _A_KM, _A_KM * np.sqrt(1 - _E2)
    e2 = 1.0 - (b / a)**2
    e4, e6 = e2 * e2, e2 * e2 * e2
    e8 = e4 * e4
    a21 = (512.0 * e2 + 128.0 * e4 + 60.0 * e6 + 35.0 * e8) / 1024.0
    a22 = (e6 + e8) / 32.0
    a23 = -3.0 * (4.0 * e6 + 3.0 * e8) / 256.0
    a41 = -(64.0 * e4 + 48.0 * e6 + 35.0 * e8) / 1024.0
    a42 = (4.0 * e4 + 2.0 * e6 + e8) / 16.0
    a43 = 15.0 * e8 / 256.0
    a44 = -e8 / 16.0
    a61 = 3.0 * (4.0 * e6 + 5.0 * e8) / 1024.0
    a62 = -3.0 * (e6 + e8) / 32.0
    a63 = 35.0 * (4.0 * e6 + 3.0 * e8) / 768.0
    a81 = -5.0 * e8 / 2048.0
    a82 = 64.0 * e8 / 2048.0
    a83 = -252.0 * e8 / 2048.0
    a84 = 320.0 * e8 / 2048.0
    gclat = 90 - theta_deg
    scl = np.sin(np.radians(gclat))
    ri = a / r_km
    a2 = ri * (a21 + ri * (a22 + ri * a23))
    a4 = ri * (a41 + ri * (a42 + ri * (a43 + ri * a44)))
    a6 = ri * (a61 + ri * (a62 + ri * a63))
    a8 = ri * (a81 + ri * (a82 + ri * (a83 + ri * a84)))
    ccl = np.sqrt(1 - scl**2)
    s2cl = 2.0 * scl * ccl
    c2cl = 2.0 * ccl * ccl - 1.0
    s4cl = 2.0 * s2cl * c2cl
    c4cl = 2.0 * c2cl * c2cl - 1.0
    s8cl = 2.0 * s4cl * c4cl
    s6cl = s2cl * c4cl + c2cl * s4cl
    dltcl = s2cl * a2 + s4cl * a4 + s6cl * a6 + s8cl * a8
    return dltcl + np.radians(gclat)


def igrf_ned(lat_deg: np.ndarray, lon_deg: np.ndarray, h_km: np.ndarray,
             date: dt.datetime) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """IGRF main field east, north and up (nT, relative to the ellipsoid) at geodetic latitude
    and longitude (deg) and height above the ellipsoid (km), at a naive UTC ``date``: the
    values of ``ppigrf.igrf(lon, lat, h, date)``, each of shape (n,)."""
    lat_deg, lon_deg, h_km = (np.asarray(x, dtype=float).ravel()
                              for x in np.broadcast_arrays(lat_deg, lon_deg, h_km))
    epochs, n, m, g_mat, h_mat = _coefficients()
    theta, r = _geodetic_to_geocentric(lat_deg, h_km)
    # coefficients at the date: linear in time between the bracketing models (pandas'
    # interpolate(method="time"), which ppigrf uses, is np.interp on the microsecond axis)
    x = _us(date)
    coeffs = np.array([[np.interp(x, epochs, c) for c in g_mat.T]
                       + [np.interp(x, epochs, c) for c in h_mat.T]])
    r, theta, phi = (v.reshape((-1, 1)) for v in (r, theta, lon_deg))
    n, m = n.reshape((1, -1)), m.reshape((1, -1))
    p, dp = _legendre(theta, [(int(a), int(b)) for a, b in zip(n[0], m[0], strict=True)])
    phi_rad = np.radians(phi)
    cosmphi, sinmphi = np.cos(phi_rad * m), np.sin(phi_rad * m)
    nn, mm = np.tile(n, 2), np.tile(m, 2)
    degree_map = ((nn >= 1) & (nn <= 13)).astype(int)
    design = degree_map * (RE_KM / r) ** (nn + 2) * (nn + 1) * np.hstack((p * cosmphi,
                                                                          p * sinmphi))
    b_r = design.dot(coeffs.T).T[0]
    design = (- degree_map * (RE_KM / r) ** (nn + 1) * np.hstack((dp * cosmphi, dp * sinmphi))
              * RE_KM / r)
    b_theta = design.dot(coeffs.T).T[0]
    design = (- degree_map * (RE_KM / r) ** (nn + 1) * mm * np.hstack((-p * sinmphi,
                                                                      p * cosmphi))
              * RE_KM / r / np.sin(np.radians(theta)))
    b_phi = design.dot(coeffs.T).T[0]
    theta = theta[:, 0]
    gdlat = _geodetic_latitude(theta, r[:, 0])
    theta_rad = np.radians(theta)
    psi = np.sin(gdlat) * np.sin(theta_rad) - np.cos(gdlat) * np.cos(theta_rad)
    north = -np.cos(psi) * b_theta - np.sin(psi) * b_r
    up = -np.sin(psi) * b_theta + np.cos(psi) * b_r
    return b_phi, north, up
