"""Broadcast-model atmospheric delays a single-frequency receiver applies: the Klobuchar
ionosphere and the Saastamoinen troposphere.

Public functions
----------------
klobuchar_delay, default_weather, saastamoinen_delay.

References
----------
IS-GPS-200N, 20.3.3.5.2.5 and Figure 20-4 (ionospheric model, L1 delay).
Saastamoinen, J., "Atmospheric correction for the troposphere and stratosphere in radio ranging
of satellites", AGU Geophysical Monograph 15, 1972; in the form and with the default weather
(standard atmosphere, relative humidity) of RTKLIB 2.4.2 ``tropmodel`` (Takasu, RTKLIB manual,
appendix E.5), whose published unit-test values are in ``refdata/tables``.
"""

from __future__ import annotations

import numpy as np

from simulator.gnss.constants import C_M_S

SECONDS_PER_DAY = 86400.0


def klobuchar_delay(lat_rad: np.ndarray, lon_rad: np.ndarray, azimuth_rad: np.ndarray,
                    elevation_rad: np.ndarray, gps_tow_s: np.ndarray,
                    alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """L1 slant ionospheric delay of the broadcast model, m (IS-GPS-200 Figure 20-4).

    Parameters
    ----------
    lat_rad, lon_rad : array_like
        Geodetic receiver latitude and longitude, rad.
    azimuth_rad, elevation_rad : array_like
        Satellite azimuth (from north, clockwise) and elevation seen from the receiver, rad.
    gps_tow_s : array_like
        GPS time (seconds of week, or of day) of the measurement.
    alpha, beta : array_like, shape (4,)
        Broadcast coefficients (s, s/semicircle^n).

    All array arguments broadcast together; the result has their broadcast shape.
    """
    az = np.asarray(azimuth_rad, dtype=float)
    el_sc = np.asarray(elevation_rad, dtype=float) / np.pi  # semicircles
    psi = 0.0137 / (el_sc + 0.11) - 0.022  # Earth-centred angle to the pierce point
    phi_i = np.clip(np.asarray(lat_rad, dtype=float) / np.pi + psi * np.cos(az), -0.416, 0.416)
    lam_i = np.asarray(lon_rad, dtype=float) / np.pi + psi * np.sin(az) / np.cos(phi_i * np.pi)
    phi_m = phi_i + 0.064 * np.cos((lam_i - 1.617) * np.pi)  # geomagnetic latitude
    t = np.mod(4.32e4 * lam_i + np.asarray(gps_tow_s, dtype=float), SECONDS_PER_DAY)  # local time
    slant = 1.0 + 16.0 * (0.53 - el_sc) ** 3  # obliquity factor F
    powers = phi_m[..., None] ** np.arange(4)
    amp = np.maximum(powers @ np.asarray(alpha, dtype=float), 0.0)
    per = np.maximum(powers @ np.asarray(beta, dtype=float), 72000.0)
    x = 2.0 * np.pi * (t - 50400.0) / per
    day = amp * (1.0 - x**2 / 2.0 + x**4 / 24.0)
    delay_s = slant * (5e-9 + np.where(np.abs(x) < 1.57, day, 0.0))
    return C_M_S * delay_s


def default_weather(alt_m: np.ndarray, humidity: float = 0.5
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pressure (hPa), temperature (K) and water-vapour pressure (hPa) of the standard atmosphere
    a receiver assumes without a weather sensor (RTKLIB ``tropmodel`` convention; heights are
    clipped to 0 ... 10 km, the model's range)."""
    h = np.clip(np.asarray(alt_m, dtype=float), 0.0, 1e4)
    pres = 1013.25 * (1.0 - 2.2557e-5 * h) ** 5.2568
    temp = 15.0 - 6.5e-3 * h + 273.16
    e = 6.108 * humidity * np.exp((17.15 * temp - 4684.0) / (temp - 38.45))
    return pres, temp, e


def saastamoinen_delay(lat_rad: np.ndarray, alt_m: np.ndarray, elevation_rad: np.ndarray,
                       humidity: float = 0.5) -> np.ndarray:
    """Slant tropospheric delay (hydrostatic + wet), m, Saastamoinen zenith delays mapped with
    1/cos(z) (RTKLIB ``tropmodel``).

    Zenith hydrostatic 0.0022768 p / (1 - 0.00266 cos 2 lat - 0.00028 h_km) and zenith wet
    0.002277 (1255/T + 0.05) e, each divided by cos z (z = zenith angle); zero for satellites
    below the horizon and receivers below -100 m or above 10 km.
    """
    lat = np.asarray(lat_rad, dtype=float)
    alt = np.asarray(alt_m, dtype=float)
    el = np.asarray(elevation_rad, dtype=float)
    pres, temp, e = default_weather(alt, humidity)
    h_km = np.maximum(alt, 0.0) / 1e3
    cos_z = np.cos(np.pi / 2 - el)
    valid = (el > 0) & (alt >= -100.0) & (alt <= 1e4)
    cos_z = np.where(valid, cos_z, 1.0)
    hydro = 0.0022768 * pres / (1.0 - 0.00266 * np.cos(2.0 * lat) - 0.00028 * h_km) / cos_z
    wet = 0.002277 * (1255.0 / temp + 0.05) * e / cos_z
    return np.where(valid, hydro + wet, 0.0)
