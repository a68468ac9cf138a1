"""The broadcast ionosphere's residual over one epoch's sky, split into what the satellites
share and what each has alone.

A receiver datasheet gives the residual as fractions of each satellite's broadcast delay I_i
(``simulator.datasheet.iono_residual_fractions``): a part c common to every satellite and a
smooth field f g(x) over the pierce points x on the broadcast model's 350 km shell, g of unit
variance and correlation exp(-d^2 / (2 L^2)) between pierce points d apart (L
``IONO_CORRELATION_LENGTH_KM``, docs/gnss-errors.md). So the slant error is
I_i (c + f g(x_i)). Satellites close in the sky share their field, but the field is not
common to all of them: over the 1000-2600 km that one epoch's pierce points span it has a
gradient, and a gradient across the sky is a range error that grows with the direction
towards the satellite, which the position takes in whole (a common error goes into the
clock; an error independent between satellites averages down). Taken as common plus an
independent share per satellite, the gradient was missed: on the quickstart (seed 2) it puts
2.3 m into the fix's east, against an east sigma of 0.5 m.

The split here is the best linear predictor of g(x_i) from the field's value g0 and its
gradient at the receiver's own zenith pierce point (Rasmussen & Williams 2006, *Gaussian
Processes for Machine Learning*, section 9.4: derivative observations of a Gaussian process;
for the squared-exponential kernel Cov(g(x), g0) = rho(x) = exp(-|x|^2 / (2 L^2)),
Cov(g(x), grad g) = rho(x) x / L^2, Var(grad g) = I / L^2):

    g(x) = rho(x) g0 + rho(x) (x / L) . (L grad g) + r(x),
    Var r(x) = 1 - rho(x)^2 (1 + |x|^2 / L^2),

with x the pierce point's offset (north, east) from the zenith pierce point along the shell,
and g0 and the scaled gradient L grad g three unit-variance quantities shared by the epoch's
satellites. ``field_gains`` gives the coefficients rho (1, x_n / L, x_e / L) and the
remainder's variance fraction, which the satellite keeps as its own error: 0.6 % of the
field's variance at 45 deg elevation (x of 340 km), 16 % at 20 deg (840 km), half at 10 deg
(1280 km).

The pierce point's Earth-centred angle from the receiver is the broadcast model's own
approximation (``simulator.datasheet.pierce_angle_sc``, IS-GPS-200 Figure 20-4), the offset
psi times the shell's radius along the azimuth.

``residual_terms`` puts the two together on an epoch's pseudoranges: four quantities of unit
variance shared by the satellites (c / |c|, g0 and the scaled gradient) with their
coefficients in metres, and each satellite's own variance (f I_i)^2 r(x_i); a satellite
without elevation or azimuth keeps the whole field as its own. Read by
``toolbox.range_budget`` (for ``fgo_tc``, the shared quantities as variables, and the tightly
coupled filters, as states).

Public names
------------
pierce_offsets_km, field_gains, residual_terms, SHARED_TERMS.
"""

from __future__ import annotations

import numpy as np

from simulator.datasheet import (
    EARTH_MEAN_RADIUS_KM,
    IONO_CORRELATION_LENGTH_KM,
    IONO_SHELL_HEIGHT_KM,
    pierce_angle_sc,
)

# the quantities shared by an epoch's satellites (``residual_terms``)
SHARED_TERMS = ("iono_common", "iono_field", "iono_north", "iono_east")


def pierce_offsets_km(elevation_rad: np.ndarray, azimuth_rad: np.ndarray) -> np.ndarray:
    """North and east offsets (km, shape (m, 2)) of the signals' ionospheric pierce points from
    the receiver's zenith pierce point, along the shell (module docstring)."""
    psi = pierce_angle_sc(elevation_rad) * np.pi
    distance = (EARTH_MEAN_RADIUS_KM + IONO_SHELL_HEIGHT_KM) * psi
    az = np.asarray(azimuth_rad, dtype=float)
    return np.stack([distance * np.cos(az), distance * np.sin(az)], axis=-1)


def field_gains(elevation_rad: np.ndarray, azimuth_rad: np.ndarray,
                length_km: float = IONO_CORRELATION_LENGTH_KM
                ) -> tuple[np.ndarray, np.ndarray]:
    """Per signal, the coefficients (m, 3) of the field's value, north and east gradient at
    the zenith pierce point (unit variance each, the gradient scaled by L) on the signal's
    field value, and the variance fraction (m,) left to it alone (module docstring)."""
    x = pierce_offsets_km(elevation_rad, azimuth_rad) / length_km
    x2 = np.sum(x * x, axis=-1)
    rho = np.exp(-0.5 * x2)
    gains = rho[:, None] * np.column_stack([np.ones(len(x2)), x])
    remainder = np.clip(1.0 - rho**2 * (1.0 + x2), 0.0, 1.0)
    return gains, remainder


def residual_terms(delay_m: np.ndarray, elevation_rad: np.ndarray | None,
                   azimuth_rad: np.ndarray | None, common: float, field: float
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The broadcast ionosphere's residual I_i (c + f g(x_i)) on an epoch's pseudoranges of
    broadcast delays ``delay_m`` (m,), ``common`` = |c| and ``field`` = f the fractions of
    ``simulator.datasheet.iono_residual_fractions`` (module docstring): the coefficients
    (4, m), m, of the ``SHARED_TERMS`` (unit variance each) and each satellite's own variance
    (m,), m^2. The coefficients' squares and the own variance add up to (c^2 + f^2) I_i^2."""
    m = len(delay_m)
    el = np.full(m, np.nan) if elevation_rad is None else elevation_rad
    az = np.full(m, np.nan) if azimuth_rad is None else azimuth_rad
    gains, remainder = field_gains(el, az)
    known = np.isfinite(remainder)
    gains = np.where(known[:, None], gains, 0.0)
    remainder = np.where(known, remainder, 1.0)
    shared = np.vstack([common * delay_m, field * gains.T * delay_m])
    return shared, remainder * (field * delay_m) ** 2
