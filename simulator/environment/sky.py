"""What the sky looks like from a road: which satellites are in line of sight, which arrive only
by a reflection (non-line-of-sight, NLOS), and the extra path of the reflection.

An urban canyon is modelled as an infinitely long street along the vehicle's heading with
facades of height H on both sides at half the street width w/2 from the antenna (the vehicle is
on the street's centre line). A satellite at azimuth az and elevation el, at angle
alpha = az - heading to the street, is in line of sight when the ray clears the facade on its
side: tan(el) >= H |sin alpha| / (w / 2). A blocked satellite is still received by specular
reflection off the opposite facade when the reflected ray clears the facade on the satellite's
side, i.e. when its image point, 3 w / 2 from that facade, sees over it:
tan(el) >= H |sin alpha| / (3 w / 2). The reflection adds the path 2 (w / 2) cos(el) |sin alpha|
(the classic image-antenna geometry of a vertical reflector, Groves 2013 section 10.4.2).

Public functions
----------------
canyon_visibility.

References
----------
Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed.,
2013, section 10.4.2 (non-line-of-sight reception, path delay of a reflection off a building).
"""

from __future__ import annotations

import numpy as np


def canyon_visibility(azimuth_rad: np.ndarray, elevation_rad: np.ndarray, heading_rad: np.ndarray,
                      building_height_m: np.ndarray, street_width_m: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Line-of-sight and NLOS masks and the NLOS extra path in a street canyon.

    Parameters
    ----------
    azimuth_rad, elevation_rad : array_like
        Satellite direction seen from the antenna (azimuth from north, clockwise), rad.
    heading_rad : array_like
        Direction of the street (the vehicle heading), rad.
    building_height_m, street_width_m : array_like
        Facade height above the antenna and distance between the facades, m.

    Returns
    -------
    los : ndarray of bool
        Direct signal received.
    nlos : ndarray of bool
        Direct signal blocked, reflection off the opposite facade received.
    extra_path_m : ndarray
        Additional path length of the reflected signal (0 where not NLOS), m.

    All arguments broadcast together.
    """
    sin_alpha = np.abs(np.sin(np.asarray(azimuth_rad) - np.asarray(heading_rad)))
    tan_el = np.tan(elevation_rad)
    half = 0.5 * np.asarray(street_width_m, dtype=float)
    height = np.asarray(building_height_m, dtype=float)
    above = np.asarray(elevation_rad) > 0
    los = above & (tan_el * half >= height * sin_alpha)
    nlos = above & ~los & (tan_el * 3.0 * half >= height * sin_alpha)
    extra = np.where(nlos, 2.0 * half * np.cos(elevation_rad) * sin_alpha, 0.0)
    return los, nlos, extra
