"""The geoid: EGM96 undulation N above the WGS-84 ellipsoid, and orthometric heights.

The one home of the geoid. Orthometric height (above mean sea level) is H = h - N, h the
ellipsoidal height (Hofmann-Wellenhof & Moritz, *Physical Geodesy*, 2nd ed., 2006, eq. 4-1
h = H + N). The barometer's pressure follows H (the atmosphere is layered on equipotential
surfaces, not on the ellipsoid), and the NMEA GGA sentence reports H and N.

Model: EGM96 (Lemoine et al., *The Development of the Joint NASA GSFC and NIMA Geopotential
Model EGM96*, NASA/TP-1998-206861), WGS-84 tide-free, on the 15' x 15' grid of NGA's
``WW15MGH`` file, interpolated bilinearly in latitude and longitude (degrees), as RTKLIB's
``geoidh`` does with that file. The grid (``simulator/data/egm96_15min.npz``, 0.7 MB, whole
centimetres) was taken once from the 5' grid of the PyPI package ``egm96`` 0.3.0 by
``tools/make_egm96_grid.py``; why a grid shipped here and not a package: see
``docs/odometer-and-barometer.md``. The 15' grid differs from the 5' one by 3.3 cm rms and at
most 0.71 m (200 000 random points, mountains), far below a barometer's metre-level worries.

Public names
------------
geoid_undulation_m, orthometric_height_m.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

_GRID_FILE = Path(__file__).resolve().parent / "data" / "egm96_15min.npz"


@functools.cache
def _grid() -> tuple[np.ndarray, float, float, float]:
    """The undulation grid, m, indexed [latitude, longitude] from its first node, and that
    node's latitude and longitude and the spacing, degrees (read once per process)."""
    with np.load(_GRID_FILE) as data:
        cm = np.cumsum(np.cumsum(data["undulation_cm_d2"].astype(np.int32), axis=0), axis=1)
        first_lat, first_lon = float(data["first_lat_deg"]), float(data["first_lon_deg"])
        step = float(data["step_deg"])
    return cm / 100.0, first_lat, first_lon, step


def geoid_undulation_m(lat_deg: np.ndarray | float, lon_deg: np.ndarray | float) -> np.ndarray:
    """EGM96 geoid undulation N, m (geoid above the WGS-84 ellipsoid), bilinear on the 15' grid.

    Parameters
    ----------
    lat_deg, lon_deg : array_like
        Geodetic latitude and longitude, degrees (broadcast against each other). Longitude is
        taken modulo 360; latitude is clipped to [-90, 90].

    Returns
    -------
    numpy.ndarray
        N at each point, m (a 0-d array for scalar inputs); NaN where a coordinate is NaN.
    """
    values, lat0, lon0, step = _grid()
    lat, lon = np.broadcast_arrays(np.asarray(lat_deg, dtype=float),
                                   np.asarray(lon_deg, dtype=float))
    known = np.isfinite(lat) & np.isfinite(lon)
    lat = np.clip(np.where(known, lat, 0.0), -90.0, 90.0)
    lon = lon0 + np.mod(np.where(known, lon, 0.0) - lon0, 360.0)
    fi = (lat - lat0) / step
    fj = (lon - lon0) / step
    i = np.clip(np.floor(fi).astype(np.intp), 0, values.shape[0] - 2)
    j = np.clip(np.floor(fj).astype(np.intp), 0, values.shape[1] - 2)
    a, b = fi - i, fj - j
    n = ((1.0 - a) * ((1.0 - b) * values[i, j] + b * values[i, j + 1])
         + a * ((1.0 - b) * values[i + 1, j] + b * values[i + 1, j + 1]))
    return np.where(known, n, np.nan)


def orthometric_height_m(lat_deg: np.ndarray | float, lon_deg: np.ndarray | float,
                         h_m: np.ndarray | float) -> np.ndarray:
    """Height above the EGM96 geoid (mean sea level), m: H = h - N for ellipsoidal height h, m."""
    return np.asarray(h_m, dtype=float) - geoid_undulation_m(lat_deg, lon_deg)
