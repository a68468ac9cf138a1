"""Broadcast-model atmospheric delays a single-frequency receiver applies: the Klobuchar
ionosphere and the Saastamoinen troposphere with the Niell mapping functions.

Public functions
----------------
klobuchar_pierce_point, klobuchar_obliquity, klobuchar_delay, default_weather,
water_vapour_pressure, saastamoinen_zenith, saastamoinen_delay, niell_mapping, tropo_delay,
broadcast_delays.

References
----------
IS-GPS-200N, 20.3.3.5.2.5 and Figure 20-4 (ionospheric model, L1 delay).
Saastamoinen, J., "Atmospheric correction for the troposphere and stratosphere in radio ranging
of satellites", AGU Geophysical Monograph 15, 1972; in the form and with the default weather
(standard atmosphere, relative humidity) of RTKLIB 2.4.2 ``tropmodel`` (Takasu, RTKLIB manual,
appendix E.5), whose published unit-test values are in ``refdata/tables``.
Niell, A. E., "Global mapping functions for the atmosphere delay at radio wavelengths",
J. Geophys. Res. 101(B2), 3227-3246, 1996.
"""

from __future__ import annotations

import numpy as np

from simulator.gnss.constants import C_M_S

SECONDS_PER_DAY = 86400.0


def klobuchar_pierce_point(lat_rad: np.ndarray, lon_rad: np.ndarray, azimuth_rad: np.ndarray,
                           elevation_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Latitude and longitude (semicircles) of the broadcast model's ionospheric pierce point
    (IS-GPS-200 Figure 20-4): the Earth-centred angle psi = 0.0137 / (E + 0.11) - 0.022
    (E the elevation in semicircles; the model's approximation of a thin shell 350 km up)
    along the azimuth, the latitude clipped to +-0.416. Arguments in rad, broadcast together."""
    az = np.asarray(azimuth_rad, dtype=float)
    el_sc = np.asarray(elevation_rad, dtype=float) / np.pi  # semicircles
    psi = 0.0137 / (el_sc + 0.11) - 0.022  # Earth-centred angle to the pierce point
    phi_i = np.clip(np.asarray(lat_rad, dtype=float) / np.pi + psi * np.cos(az), -0.416, 0.416)
    lam_i = np.asarray(lon_rad, dtype=float) / np.pi + psi * np.sin(az) / np.cos(phi_i * np.pi)
    return phi_i, lam_i


def klobuchar_obliquity(elevation_rad: np.ndarray) -> np.ndarray:
    """The broadcast model's slant / vertical delay, F = 1 + 16 (0.53 - E)^3 (E the elevation
    in semicircles; IS-GPS-200 Figure 20-4)."""
    return 1.0 + 16.0 * (0.53 - np.asarray(elevation_rad, dtype=float) / np.pi) ** 3


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
    phi_i, lam_i = klobuchar_pierce_point(lat_rad, lon_rad, azimuth_rad, elevation_rad)
    phi_m = phi_i + 0.064 * np.cos((lam_i - 1.617) * np.pi)  # geomagnetic latitude
    t = np.mod(4.32e4 * lam_i + np.asarray(gps_tow_s, dtype=float), SECONDS_PER_DAY)  # local time
    slant = klobuchar_obliquity(elevation_rad)
    # phi_m^0..3; the powers 0 and 1 are exact, so only 2 and 3 go through pow
    powers = np.empty(np.shape(phi_m) + (4,))
    powers[..., 0], powers[..., 1] = 1.0, phi_m
    powers[..., 2:] = phi_m[..., None] ** np.arange(2, 4)
    amp = np.maximum(powers @ np.asarray(alpha, dtype=float), 0.0)
    per = np.maximum(powers @ np.asarray(beta, dtype=float), 72000.0)
    x = 2.0 * np.pi * (t - 50400.0) / per
    day = amp * (1.0 - x**2 / 2.0 + x**4 / 24.0)
    delay_s = slant * (5e-9 + np.where(np.abs(x) < 1.57, day, 0.0))
    return C_M_S * delay_s


def default_weather(alt_m: np.ndarray, humidity: float = 0.5
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pressure (hPa), temperature (K) and water-vapour pressure (hPa) a receiver assumes
    without a weather sensor (RTKLIB ``tropmodel`` convention; heights are clipped to
    0 ... 10 km, the model's range).

    This is the receiver's built-in approximation, kept exactly so that the troposphere model
    reproduces RTKLIB's published values; the physical standard atmosphere of landnav is
    ``simulator.environment.atmosphere`` (they agree within 0.09 hPa and 0.01 K below 2 km,
    0.7 hPa and 0.1 K up to 10 km).
    """
    h = np.clip(np.asarray(alt_m, dtype=float), 0.0, 1e4)
    pres = 1013.25 * (1.0 - 2.2557e-5 * h) ** 5.2568
    temp = 15.0 - 6.5e-3 * h + 273.16
    return pres, temp, water_vapour_pressure(temp, humidity)


def water_vapour_pressure(temp_k: np.ndarray, humidity: np.ndarray) -> np.ndarray:
    """Partial pressure of water vapour, hPa, at temperature T (K) and relative humidity (0-1):
    6.108 RH exp((17.15 T - 4684) / (T - 38.45)) (RTKLIB ``tropmodel``)."""
    temp = np.asarray(temp_k, dtype=float)
    return 6.108 * np.asarray(humidity) * np.exp((17.15 * temp - 4684.0) / (temp - 38.45))


def saastamoinen_zenith(lat_rad: np.ndarray, alt_m: np.ndarray, humidity: float = 0.5,
                        weather: tuple[float, float, float] | None = None
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Saastamoinen zenith hydrostatic and wet delays, m:
    0.0022768 p / (1 - 0.00266 cos 2 lat - 0.00028 h_km) and 0.002277 (1255 / T + 0.05) e,
    with ``default_weather`` or measured ``weather`` = (p hPa, T K, e hPa); zero for receivers
    below -100 m or above 10 km (the model's range)."""
    lat = np.asarray(lat_rad, dtype=float)
    alt = np.asarray(alt_m, dtype=float)
    pres, temp, e = default_weather(alt, humidity) if weather is None else weather
    h_km = np.maximum(alt, 0.0) / 1e3
    valid = (alt >= -100.0) & (alt <= 1e4)
    hydro = 0.0022768 * pres / (1.0 - 0.00266 * np.cos(2.0 * lat) - 0.00028 * h_km)
    wet = 0.002277 * (1255.0 / temp + 0.05) * e
    return np.where(valid, hydro, 0.0), np.where(valid, wet, 0.0)


def saastamoinen_delay(lat_rad: np.ndarray, alt_m: np.ndarray, elevation_rad: np.ndarray,
                       humidity: float = 0.5) -> np.ndarray:
    """Slant tropospheric delay (hydrostatic + wet), m: the Saastamoinen zenith delays mapped
    with 1 / cos(z) (z = zenith angle; RTKLIB ``tropmodel``); zero below the horizon."""
    el = np.asarray(elevation_rad, dtype=float)
    hydro, wet = saastamoinen_zenith(lat_rad, alt_m, humidity)
    above = el > 0
    return np.where(above, (hydro + wet) / np.where(above, np.sin(el), 1.0), 0.0)


# Niell (1996) Table 3: hydrostatic (a, b, c) averages and seasonal amplitudes, and wet (a, b, c),
# at latitudes 15, 30, 45, 60, 75 deg; height correction (a, b, c) of the hydrostatic function
_NIELL_LAT_DEG = np.array([15.0, 30.0, 45.0, 60.0, 75.0])
_NIELL_HYDRO_AVG = np.array([
    [1.2769934e-3, 2.9153695e-3, 62.610505e-3], [1.2683230e-3, 2.9152299e-3, 62.837393e-3],
    [1.2465397e-3, 2.9288445e-3, 63.721774e-3], [1.2196049e-3, 2.9022565e-3, 63.824265e-3],
    [1.2045996e-3, 2.9024912e-3, 64.258455e-3]])
_NIELL_HYDRO_AMP = np.array([
    [0.0, 0.0, 0.0], [1.2709626e-5, 2.1414979e-5, 9.0128400e-5],
    [2.6523662e-5, 3.0160779e-5, 4.3497037e-5], [3.4000452e-5, 7.2562722e-5, 84.795348e-5],
    [4.1202191e-5, 11.723375e-5, 170.37206e-5]])
_NIELL_WET = np.array([
    [5.8021897e-4, 1.4275268e-3, 4.3472961e-2], [5.6794847e-4, 1.5138625e-3, 4.6729510e-2],
    [5.8118019e-4, 1.4572752e-3, 4.3908931e-2], [5.9727542e-4, 1.5007428e-3, 4.4626982e-2],
    [6.1641693e-4, 1.7599082e-3, 5.4736038e-2]])
_NIELL_HEIGHT = (2.53e-5, 5.49e-3, 1.14e-3)


def _marini(sin_el: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Marini's continued fraction normalised to 1 at zenith (Niell 1996 eq. 4)."""
    return (1.0 + a / (1.0 + b / (1.0 + c))) / (sin_el + a / (sin_el + b / (sin_el + c)))


def _interp_lat(abs_lat_deg: np.ndarray, table: np.ndarray) -> list[np.ndarray]:
    return [np.interp(abs_lat_deg, _NIELL_LAT_DEG, table[:, k]) for k in range(3)]


def niell_mapping(lat_rad: np.ndarray, alt_m: np.ndarray, elevation_rad: np.ndarray,
                  day_of_year: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Niell hydrostatic and wet mapping functions (Niell 1996, J. Geophys. Res. 101(B2),
    eqs. 4-5 and Table 3).

    Coefficients are interpolated linearly in |latitude| (held constant beyond 15 and 75 deg);
    the hydrostatic ones vary with cos(2 pi (doy - 28) / 365.25), half a year shifted south of
    the equator; the hydrostatic function gets the height correction
    (1 / sin el - m(el; a_ht, b_ht, c_ht)) h_km. ``day_of_year`` counts from 1.0 at
    1 January 00:00. Both are 0 below the horizon.
    """
    lat = np.asarray(lat_rad, dtype=float)
    el = np.asarray(elevation_rad, dtype=float)
    above = el > 0
    sin_el = np.where(above, np.sin(el), 1.0)
    abs_lat = np.abs(np.degrees(lat))
    year = (np.asarray(day_of_year, dtype=float) - 28.0) / 365.25 + np.where(lat < 0, 0.5, 0.0)
    season = np.cos(2.0 * np.pi * year)
    avg = _interp_lat(abs_lat, _NIELL_HYDRO_AVG)
    amp = _interp_lat(abs_lat, _NIELL_HYDRO_AMP)
    a, b, c = (m - w * season for m, w in zip(avg, amp, strict=True))
    h_km = np.asarray(alt_m, dtype=float) / 1e3
    hydro = _marini(sin_el, a, b, c) + (1.0 / sin_el - _marini(sin_el, *_NIELL_HEIGHT)) * h_km
    wet = _marini(sin_el, *_interp_lat(abs_lat, _NIELL_WET))
    return np.where(above, hydro, 0.0), np.where(above, wet, 0.0)


def tropo_delay(lat_rad: np.ndarray, alt_m: np.ndarray, elevation_rad: np.ndarray,
                day_of_year: np.ndarray, humidity: float = 0.5,
                weather: tuple[float, float, float] | None = None) -> np.ndarray:
    """Slant tropospheric delay a receiver applies, m: Saastamoinen zenith delays
    (``saastamoinen_zenith``) mapped with the Niell functions (``niell_mapping``)."""
    hydro, wet = saastamoinen_zenith(lat_rad, alt_m, humidity, weather)
    m_h, m_w = niell_mapping(lat_rad, alt_m, elevation_rad, day_of_year)
    return hydro * m_h + wet * m_w


def broadcast_delays(lat_rad: np.ndarray, lon_rad: np.ndarray, alt_m: np.ndarray,
                     azimuth_rad: np.ndarray, elevation_rad: np.ndarray, gps_tow_s: np.ndarray,
                     day_of_year: np.ndarray, alpha: np.ndarray, beta: np.ndarray,
                     rates: dict[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
    """The delays a single-frequency receiver applies, and their time derivatives.

    ``iono``: Klobuchar (``klobuchar_delay``); ``tropo``: ``tropo_delay`` (standard atmosphere);
    ``zenith``: the zenith troposphere of the same model (broadcast to the slant's shape).
    With ``rates`` (d/dt of ``lat``, ``lon``, ``alt``, ``azimuth``, ``elevation``, per second)
    also ``iono_rate`` and ``tropo_rate`` (m/s), by central differences over +-0.5 s along
    those rates (the models are smooth; the step error is below 1e-6 m/s). Receiver arrays have
    shape (n_epoch,), satellite arrays (n_sat, n_epoch).
    """
    def at(step_s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r = rates or {}
        lat = lat_rad + r.get("lat", 0.0) * step_s
        alt = alt_m + r.get("alt", 0.0) * step_s
        el = np.clip(elevation_rad + r.get("elevation", 0.0) * step_s, -np.pi / 2, np.pi / 2)
        iono = klobuchar_delay(lat, lon_rad + r.get("lon", 0.0) * step_s,
                               azimuth_rad + r.get("azimuth", 0.0) * step_s, el,
                               gps_tow_s + step_s, alpha, beta)
        tropo = tropo_delay(lat, alt, el, day_of_year + step_s / SECONDS_PER_DAY)
        zenith = np.broadcast_to(np.add(*saastamoinen_zenith(lat, alt)), tropo.shape)
        return iono, tropo, zenith

    iono, tropo, zenith = at(0.0)
    out = {"iono": iono, "tropo": tropo, "zenith": zenith}
    if rates is not None:
        half = 0.5
        iono_hi, tropo_hi, _ = at(half)
        iono_lo, tropo_lo, _ = at(-half)
        out["iono_rate"] = (iono_hi - iono_lo) / (2.0 * half)
        out["tropo_rate"] = (tropo_hi - tropo_lo) / (2.0 * half)
    return out
