"""The standard atmosphere: temperature and pressure against height, and the pressure altitude.

ICAO Standard Atmosphere (ICAO Doc 7488/3, 1993), identical below 32 km to the U.S. Standard
Atmosphere 1976 and defined here up to 80 km geopotential: layers of constant temperature
gradient in geopotential height H = r0 h / (r0 + h), hydrostatic pressure in each layer
(ICAO Doc 7488/3, eqs. 12-13 in their usual form)::

    p = p_b (T_b / (T_b + L (H - H_b)))^(g0 / (R L))    L != 0
    p = p_b exp(-g0 (H - H_b) / (R T_b))                 L == 0

Heights are geometric (m above mean sea level) unless a name says ``geopotential``.

Public names
------------
P0_PA, T0_K, geopotential_height, temperature_k, pressure_pa, pressure_altitude_m.
"""

from __future__ import annotations

import numpy as np

from simulator.earth import G0_M_S2

P0_PA = 101325.0  # sea-level pressure of the standard atmosphere, Pa
T0_K = 288.15  # sea-level temperature of the standard atmosphere, K
R_AIR_J_KG_K = 287.05287  # specific gas constant of dry air, J/(kg K) (ICAO Doc 7488/3)
R0_M = 6356766.0  # Earth radius used for geopotential height, m (ICAO Doc 7488/3)

# layer base geopotential heights (m) and temperature gradients (K/m), ICAO Doc 7488/3 Table D
_BASE_H_M = np.array([0.0, 11000.0, 20000.0, 32000.0, 47000.0, 51000.0, 71000.0])
_GRADIENT_K_M = np.array([-6.5e-3, 0.0, 1.0e-3, 2.8e-3, 0.0, -2.8e-3, -2.0e-3])


def _layer_bases() -> tuple[np.ndarray, np.ndarray]:
    """Temperature and pressure at each layer base, integrated upward from sea level."""
    temps, pressures = [T0_K], [P0_PA]
    for i in range(len(_BASE_H_M) - 1):
        dh = _BASE_H_M[i + 1] - _BASE_H_M[i]
        t_top = temps[i] + _GRADIENT_K_M[i] * dh
        pressures.append(_layer_pressure(pressures[i], temps[i], _GRADIENT_K_M[i], dh))
        temps.append(t_top)
    return np.array(temps), np.array(pressures)


def _layer_pressure(p_base: np.ndarray, t_base: np.ndarray, gradient: np.ndarray,
                    dh: np.ndarray) -> np.ndarray:
    gradient = np.asarray(gradient, dtype=float)
    lapse = np.where(gradient == 0.0, 1.0, gradient)
    power = p_base * (t_base / (t_base + lapse * dh)) ** (G0_M_S2 / (R_AIR_J_KG_K * lapse))
    isothermal = p_base * np.exp(-G0_M_S2 * dh / (R_AIR_J_KG_K * t_base))
    return np.where(gradient == 0.0, isothermal, power)


_BASE_T_K, _BASE_P_PA = _layer_bases()


def geopotential_height(h_m: np.ndarray) -> np.ndarray:
    """Geopotential height H = r0 h / (r0 + h), m, of a geometric height h, m."""
    h_m = np.asarray(h_m, dtype=float)
    return R0_M * h_m / (R0_M + h_m)


def _layer(height_geopotential_m: np.ndarray) -> np.ndarray:
    return np.clip(np.searchsorted(_BASE_H_M, height_geopotential_m, side="right") - 1,
                   0, len(_BASE_H_M) - 1)


def temperature_k(h_m: np.ndarray) -> np.ndarray:
    """Standard-atmosphere temperature, K, at geometric height h, m (-5 km ... 80 km)."""
    height = geopotential_height(h_m)
    i = _layer(height)
    return _BASE_T_K[i] + _GRADIENT_K_M[i] * (height - _BASE_H_M[i])


def pressure_pa(h_m: np.ndarray) -> np.ndarray:
    """Standard-atmosphere pressure, Pa, at geometric height h, m (-5 km ... 80 km)."""
    height = geopotential_height(h_m)
    i = _layer(height)
    return _layer_pressure(_BASE_P_PA[i], _BASE_T_K[i], _GRADIENT_K_M[i], height - _BASE_H_M[i])


def pressure_altitude_m(p_pa: np.ndarray) -> np.ndarray:
    """Geometric height, m, at which the standard atmosphere has pressure p, Pa (inverse of
    ``pressure_pa``)."""
    p_pa = np.asarray(p_pa, dtype=float)
    # the layer is the last base whose pressure is at least p
    i = np.clip(len(_BASE_P_PA) - 1 - np.searchsorted(_BASE_P_PA[::-1], p_pa, side="left"),
                0, len(_BASE_P_PA) - 1)
    t_b, p_b, grad = _BASE_T_K[i], _BASE_P_PA[i], _GRADIENT_K_M[i]
    lapse = np.where(grad == 0.0, 1.0, grad)
    power = t_b / lapse * ((p_pa / p_b) ** (-R_AIR_J_KG_K * lapse / G0_M_S2) - 1.0)
    isothermal = -R_AIR_J_KG_K * t_b / G0_M_S2 * np.log(p_pa / p_b)
    height = _BASE_H_M[i] + np.where(grad == 0.0, isothermal, power)
    return R0_M * height / (R0_M - height)
