"""What the sky looks like from a road: through which path each satellite's signal reaches the
antenna in an urban canyon (direct, diffracted over a roof edge, or reflected off facades), the
extra path of that signal and its C/N0 loss.

The canyon is a street box around the antenna, in street axes (x along the vehicle's heading,
y to its right, z up, the antenna at the origin on the street's centre line): the facade lines
of both sides at y = +-w/2 and, closing the street, facades across it at x = ``ahead`` and
x = -``behind`` (a T-junction, an overpass: where the canyon zone ends). Along the side facade
lines stand buildings (``Buildings``, laid out by ``street_buildings``): blocks between cross
streets, buildings of one frontage with gaps between them, each with its own height, as a 3D
city model gives them (Groves 2011; Wang, Groves & Ziebart 2013); every lookup of "the building
at this along-street coordinate" is a ``np.searchsorted`` over them, vectorised over satellites
and epochs. A satellite in direction u = (cos el cos a, cos el sin a, sin el),
a = azimuth - heading, reaches the antenna along these paths, each traced as a ray from the
antenna (image method, Groves 2013 section 10.4.2; the street-canyon box of Bourdeau, Sahmoudi &
Tourneret 2012):

- ``direct``: straight to the satellite; line of sight when it leaves the box over the edge it
  meets (clearance >= 0), otherwise diffracted over that edge;
- one specular reflection off either side facade or either end facade;
- two reflections, right then left facade, or left then right;
- ``scattered``: diffuse scattering off the side facade across the street from the satellite,
  from the part of it the satellite lights above the shadow of the near row (below).

A reflection is possible when the ray meets the named facade line first, at an along-street
coordinate where a building stands, below that building's top (the image method per facade
segment: a reflection point on a gap or a cross street reflects nothing). Every path's last leg
leaves the box where it crosses a facade line: over the roof edge of the building standing there
(its own height: a lower building lets a ray through that a taller one would stop), or, where
the crossing falls in a gap or a cross street, between the side walls of the buildings bounding
it (taken as deep as the block), over the edge of the wall it runs toward; a ray square to the
street leaves a gap freely. Each path's C/N0 loss is the knife-edge diffraction
loss J(nu) of that last edge (ITU-R P.526-15 eq. 31, nu = h sqrt(2 / (lambda d)) for a far
transmitter, h the height of the edge above the ray, d the slant distance to it; 0 dB below
nu = -0.78) plus the loss of every reflection (given by the caller: facades differ; about
15 +- 8 dB, the C/N0 drop of NLOS against LOS signals in the Berlin u-blox log with NLOS labels,
refdata 3d: 44.7 vs 29.1 dB-Hz, sd 8.2, and Hsu 2017/2018's urban NLOS measurements). The
receiver tracks the strongest path (least loss), as its code loop locks onto the strongest
correlation peak: it is line of sight when that is the direct path with clearance >= 0, NLOS
otherwise (diffracted or reflected only). Its extra path is the length of the bent path minus
the direct range: for legs ending at the last reflection point P (or the roof edge E of a
diffracted leg) and a far satellite, sum(|legs|) - P . u. For one reflection off a side facade
this is the image-antenna distance 2 (w/2) cos el |sin a| (Groves 2013 eq. 10.23 geometry); off
the far end facade 2 ahead cos el cos a, which reaches hundreds of metres: the long tail of NLOS
delays that Hsu 2018 reports, coming from geometry, not from a drawn distribution.

Diffuse scattering (the Lambertian form of the effective-roughness model, Degli-Esposti et
al. 2007): windows, balconies, ledges and the facade's roughness reradiate a fraction S^2 of the
power that falls on it into all directions, with intensity proportional to cos(theta_s).
The satellite lights the facade across the street above the shadow line of the roof edge on its
own side, z1 = H_near - 2 (w/2) tan(el) / |sin a|, up to that facade's top z2 (heights above the
antenna; the building standing at the antenna's along-street coordinate on each side). A facade
element dA receives the power density I cos(theta_i) dA (cos theta_i = cos el |sin a|) and sends
S^2 I cos(theta_i) dA cos(theta_s) / pi per steradian to the antenna at distance r, so the
scattered power relative to the direct power is S^2 cos(theta_i) Omega / pi, Omega =
integral of cos(theta_s) dA / r^2 = the solid angle of the lit strip seen from the antenna: for
a wall at distance D = w/2, infinitely long, between heights z1 and z2, Omega =
2 (atan(z2 / D) - atan(z1 / D)) (``lit_strip_solid_angle``). The scattered field is
depolarised (half its power in the co-polar RHCP: 3 dB), and it arrives from the strip
(elevation atan(z_mid / D) across the street), where the antenna's gain is not the gain toward
the satellite: the caller's ``antenna_gain_db`` gives the difference (landnav passes the C/N0
model's elevation shape, taken as the antenna's gain: the power reaching the ground varies by
about 2 dB over elevation, the satellites' antennas being shaped to keep it flat). Its extra
path is that of the strip's mid-height point of least delay,
sqrt(D^2 + z^2) sqrt(1 - u_x^2) + D |u_y| - z u_z (the code loop locks on the composite's peak;
the delay spread over the strip is a few metres).
S = 0.4 is the default (Degli-Esposti et al. 2007 fitted S of about 0.4 to the Lambertian model
for building walls measured at 1.3 GHz; ray-tracing tools use 0.2-0.5). At 15 deg elevation
across a street as high as it is wide the path loses about 21 dB against the direct signal
and gains 10 dB of antenna gain back: a C/N0 near 24 dB-Hz, where deep shadow diffraction over
the roof loses 35 dB or more; the Berlin u-blox log's weakest NLOS GPS signals are 21-23 dB-Hz.

Choices where the sources are silent: the antenna is on the centre line; the street is
straight along the vehicle's heading with the distance driven as its along-street coordinate;
the end facades are ``building_height`` high; only the buildings along the street are modelled
(beyond a roof or a gap's side walls the sky is open); diffraction round a building's vertical
corner edges, the ground reflection and LOS multipath are left out (the last two to the
receiver's multipath error process); paths of three or more reflections are left out (they lose
45 dB and more). Continuous facades of one height (``buildings`` None) are the special case of
closed blocks with no cross streets and no height spread.

Public names
------------
PATHS, Buildings, street_buildings, knife_edge_loss_db, lit_strip_solid_angle,
scattered_path, trace_paths, canyon_reception.

References
----------
Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed.,
2013, section 10.4.2 (NLOS reception, path delay of a reflection off a building).
Degli-Esposti, Fuschini, Vitucci & Falciasecca, "Measurement and modelling of scattering from
buildings", IEEE Trans. Antennas Propag. 55(1), 143-153, 2007 (effective-roughness diffuse
scattering, Lambertian pattern, scattering parameter S of building walls).
Groves, "Shadow matching: a new GNSS positioning technique for urban canyons", J. Navigation
64(3), 2011 (building edges decide which satellites are direct; diffraction near the edges).
Wang, Groves & Ziebart, "GNSS shadow matching: improving urban positioning accuracy using a 3D
city model with optimized visibility scoring scheme", NAVIGATION 60(3), 2013 (buildings as blocks
of their own heights, the city model a satellite's visibility is decided against).
Bourdeau, Sahmoudi & Tourneret, "Tight integration of GNSS and a 3D city model for robust
positioning in urban canyons", ION GNSS 2012 (street-canyon geometry, reflected signals' delays).
Hsu, "Analysis and modeling GPS NLOS effect in highly urbanized area", GPS Solutions 22(1), 2018
(NLOS delays and C/N0 of reflected signals in Hong Kong).
ITU-R P.526-15, *Propagation by diffraction*, 2019, eq. 31 (single knife-edge loss J(nu)).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

# facades: 0 right side (y = +w/2), 1 left side, 2 far end ahead (x = ahead), 3 end behind
RIGHT, LEFT, AHEAD, BEHIND = 0, 1, 2, 3
# the paths traced: name -> facades met in order
PATHS: dict[str, tuple[int, ...]] = {
    "direct": (),
    "right": (RIGHT,), "left": (LEFT,), "ahead": (AHEAD,), "behind": (BEHIND,),
    "right_left": (RIGHT, LEFT), "left_right": (LEFT, RIGHT),
}
_NO_EDGE_NU = -0.78  # below it the knife-edge loss is zero (ITU-R P.526-15 eq. 31)


def knife_edge_loss_db(nu: np.ndarray) -> np.ndarray:
    """Single knife-edge diffraction loss, dB (ITU-R P.526-15 eq. 31):
    J(nu) = 6.9 + 20 log10(sqrt((nu - 0.1)^2 + 1) + nu - 0.1) for nu > -0.78, else 0."""
    nu = np.asarray(nu, dtype=float)
    clipped = np.maximum(nu, _NO_EDGE_NU)  # far below the edge the formula cancels to log(0)
    j = 6.9 + 20.0 * np.log10(np.sqrt((clipped - 0.1) ** 2 + 1.0) + clipped - 0.1)
    return np.where(nu > _NO_EDGE_NU, j, 0.0)


@dataclass(frozen=True)
class Buildings:
    """The buildings along both sides of a drive's canyon streets, in the distance driven.

    Side ``k`` (0 right, 1 left) has buildings ``start_m[k][i] <= s < end_m[k][i]`` (sorted, not
    overlapping; s the along-street coordinate, the distance driven) of height ``height_m[k][i]``
    above the antenna; between them are gaps and cross streets. ``street_start_m`` are the
    distances where the streets begin (each closed at both ends by an end facade of
    ``end_height_m``). Facade numbers (for the reflection losses): the right side's buildings
    first, then the left side's, then each street's end facades, ahead and behind."""

    start_m: tuple[np.ndarray, np.ndarray]
    end_m: tuple[np.ndarray, np.ndarray]
    height_m: tuple[np.ndarray, np.ndarray]
    street_start_m: np.ndarray
    end_height_m: float

    @property
    def count(self) -> int:
        """Number of facades: every building, and two end facades per street."""
        return len(self.start_m[0]) + len(self.start_m[1]) + 2 * len(self.street_start_m)


def street_buildings(rng: np.random.Generator, streets_m: np.ndarray, block_length_m: float,
                     cross_street_width_m: float, building_length_m: float,
                     building_gap_m: float, height_m: float, height_spread_m: float
                     ) -> Buildings:
    """Lay out the buildings of canyon streets, block by block, with drawn heights.

    Each street (rows of ``streets_m``: start and end in the distance driven) begins at an
    intersection: blocks of ``block_length_m`` alternate with cross streets of
    ``cross_street_width_m``, at the same places on both sides (intersections). Along a block,
    buildings of ``building_length_m`` frontage follow each other ``building_gap_m`` apart (0: the
    closed perimeter block of European city centres); the last one ends with the block. Each
    building's height above the antenna is drawn once from N(``height_m``,
    ``height_spread_m``), floored at 0, independently per building (the city model of Wang,
    Groves & Ziebart 2013 gives every building its own height). The end facades closing each
    street are ``height_m`` high. A street of no length (a zone the car stands in) gets one
    block from its start, up to the next street's start."""
    streets = np.asarray(streets_m, dtype=float).reshape(-1, 2)
    following = np.append(streets[1:, 0], np.inf)
    pitch = building_length_m + building_gap_m
    per_block = int(np.ceil(block_length_m / pitch))
    starts, ends = [], []
    for (first, end), next_first in zip(streets, following, strict=True):  # one pass per street
        last = end if end > first else min(first + block_length_m, next_first)
        block = np.arange(first, last, block_length_m + cross_street_width_m)
        b0 = (block[:, None] + pitch * np.arange(per_block)[None, :]).ravel()
        b1 = np.minimum(b0 + building_length_m, np.repeat(block + block_length_m, per_block))
        keep = (b1 > b0) & (b0 < last)
        starts.append(b0[keep])
        ends.append(np.minimum(b1[keep], last))
    start = np.concatenate(starts) if starts else np.zeros(0)
    end = np.concatenate(ends) if ends else np.zeros(0)
    heights = np.maximum(height_m + height_spread_m * rng.standard_normal((2, len(start))), 0.0)
    return Buildings((start, start.copy()), (end, end.copy()), (heights[0], heights[1]),
                     streets[:, 0], float(height_m))


# the left side's buildings are looked up beyond the right side's, shifted by this much (far
# beyond any drive), so that both sides are one sorted array and one ``np.searchsorted``
_LEFT_SHIFT_M = 1e12


def _sorted_sides(buildings: Buildings) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Both sides' starts, ends and heights as one sorted array (the left side shifted by
    ``_LEFT_SHIFT_M``: an index into it is the facade number), and the right side's count."""
    return (np.concatenate([buildings.start_m[0], buildings.start_m[1] + _LEFT_SHIFT_M]),
            np.concatenate([buildings.end_m[0], buildings.end_m[1] + _LEFT_SHIFT_M]),
            np.concatenate(buildings.height_m), len(buildings.start_m[0]))


def _street(shape: tuple[int, ...], building_height_m: np.ndarray, street_width_m: np.ndarray,
            along_m: np.ndarray, buildings: Buildings | None
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple | None]:
    """The street's arrays broadcast to ``shape``: facade height, half width, the antenna's
    along-street coordinate, and the buildings sorted for lookups (``_sorted_sides``; None for
    continuous facades)."""
    return (np.broadcast_to(np.asarray(building_height_m, dtype=float), shape),
            np.broadcast_to(0.5 * np.asarray(street_width_m, dtype=float), shape),
            np.broadcast_to(np.asarray(along_m, dtype=float), shape),
            None if buildings is None else _sorted_sides(buildings))


def _side_facade(sides: tuple | None, left: np.ndarray, s: np.ndarray, height: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The building at along-street coordinate s on the left (``left`` true) or right side:
    whether there is one, its height and its facade number (``np.searchsorted`` over the sorted
    buildings, ``_sorted_sides``; None: continuous facades of ``height``, numbered 0 right,
    1 left)."""
    if sides is None:
        return (np.ones(s.shape, dtype=bool), height,
                np.broadcast_to(left, s.shape).astype(int))
    start, end, tops, n_right = sides
    key = s + np.where(left, _LEFT_SHIFT_M, 0.0)
    i = np.searchsorted(start, key, side="right") - 1
    j = np.maximum(i, 0)
    inside = (i >= np.where(left, n_right, 0)) & (key < end[j])
    return inside, np.where(inside, tops[j], 0.0), j


def _gap_wall(sides: tuple, left: np.ndarray, s: np.ndarray, forward: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """The building side wall that bounds the gap or cross street at s, in the direction the ray
    runs along the street (``forward``: toward larger s): its along-street coordinate (+-inf if
    none on that side) and its height."""
    start, end, tops, n_right = sides
    first, last = np.where(left, n_right, 0), np.where(left, len(start), n_right)
    shift = np.where(left, _LEFT_SHIFT_M, 0.0)
    i = np.searchsorted(start, s + shift, side="right")  # the next building starts at start[i]
    k = np.clip(np.where(forward, i, i - 1), 0, len(start) - 1)
    there = np.where(forward, i < last, i - 1 >= first)
    wall = np.where(forward, start[k], end[k]) - shift
    return (np.where(there, wall, np.where(forward, np.inf, -np.inf)),
            np.where(there, tops[k], 0.0))


def _exit(p: np.ndarray, d: np.ndarray, half_width: np.ndarray, ahead: np.ndarray,
          behind: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance along the unit direction d (..., 3) from p (..., 3) to the facade line the ray
    meets first (horizontally: the box is convex), and that facade's wall number."""
    with np.errstate(divide="ignore", invalid="ignore"):
        sx = np.where(d[..., 0] > 0, (ahead - p[..., 0]) / d[..., 0],
                      np.where(d[..., 0] < 0, (-behind - p[..., 0]) / d[..., 0], np.inf))
        sy = np.where(d[..., 1] > 0, (half_width - p[..., 1]) / d[..., 1],
                      np.where(d[..., 1] < 0, (-half_width - p[..., 1]) / d[..., 1], np.inf))
    wall = np.where(sx < sy, np.where(d[..., 0] > 0, AHEAD, BEHIND),
                    np.where(d[..., 1] > 0, RIGHT, LEFT))
    return np.minimum(sx, sy), wall


def _mirror(d: np.ndarray, wall: int) -> np.ndarray:
    """Direction d after a specular reflection off facade ``wall`` (its normal component flips)."""
    out = d.copy()
    out[..., 0 if wall in (AHEAD, BEHIND) else 1] *= -1.0
    return out


def _end_number(buildings: Buildings | None, along: np.ndarray, wall: int) -> np.ndarray:
    """Facade number of the end facade ``wall`` (AHEAD or BEHIND) of the street at ``along``."""
    if buildings is None:
        return np.full(along.shape, wall)
    street = np.maximum(np.searchsorted(buildings.street_start_m, along, side="right") - 1, 0)
    return (len(buildings.start_m[0]) + len(buildings.start_m[1]) + 2 * street
            + (wall - AHEAD))


def _leave(p: np.ndarray, d: np.ndarray, half: np.ndarray, ahead: np.ndarray,
           behind: np.ndarray, along: np.ndarray, height: np.ndarray, end_height: np.ndarray,
           sides: tuple | None) -> tuple[np.ndarray, np.ndarray]:
    """Where the leg from p along d leaves the street, and its clearance there.

    It crosses the facade line of a side or an end. An end facade, or a side building at the
    crossing's along-street coordinate, is passed over its roof edge (clearance: height of the
    ray above it). Where the crossing falls in a gap or a cross street, the ray runs on between
    the side walls of the buildings bounding it (walls as deep as the block) and leaves over the
    edge of the one it runs toward (a ray square to the street leaves freely). Returns the edge
    point (its height raised to the edge where the ray passes below: the bent path's corner;
    far away for an open street) and the clearance (< 0: diffracted)."""
    s, met = _exit(p, d, half, ahead, behind)
    s = np.where(np.isfinite(s), s, 1e9)  # an open street: no edge
    edge = p + s[..., None] * d
    side = (met == RIGHT) | (met == LEFT)
    inside, top, _ = _side_facade(sides, met == LEFT, along + edge[..., 0], height)
    top = np.where(side, top, end_height)
    gap = side & ~inside & (d[..., 0] != 0)
    if gap.any():  # only where buildings are laid out: continuous facades have no gaps
        wall_s, wall_h = _gap_wall(sides, met[gap] == LEFT, along[gap] + edge[gap][:, 0],
                                   d[gap][:, 0] > 0)
        open_run = ~np.isfinite(wall_s)
        k = np.where(open_run, 1e9, (wall_s - along[gap] - edge[gap][:, 0]) / d[gap][:, 0])
        edge[gap] = edge[gap] + k[:, None] * d[gap]
        top[gap] = np.where(open_run, 0.0, wall_h)
    clearance = edge[..., 2] - top
    edge[..., 2] = np.maximum(edge[..., 2], top)  # the bent path goes over the edge
    return edge, clearance


def trace_paths(u: np.ndarray, building_height_m: np.ndarray, street_width_m: np.ndarray,
                ahead_m: np.ndarray, behind_m: np.ndarray, along_m: np.ndarray = 0.0,
                buildings: Buildings | None = None) -> dict[str, dict[str, np.ndarray]]:
    """Trace every path of ``PATHS`` for satellite directions u in street axes.

    Parameters
    ----------
    u : ndarray, shape (..., 3)
        Unit vectors toward the satellites (x along the street ahead, y right, z up), z > 0.
    building_height_m, street_width_m, ahead_m, behind_m : array_like, broadcast to u[..., 0]
        Facade height above the antenna (of continuous facades, and of the end facades where
        ``buildings`` is None), distance between the side facades, distances to the end facades
        ahead and behind (np.inf: open).
    along_m : array_like, broadcast to u[..., 0]
        The antenna's along-street coordinate (distance driven) in ``buildings``' terms.
    buildings : Buildings or None
        The buildings along the sides (``street_buildings``); None: continuous facades of
        ``building_height_m`` (the special case with no gaps), numbered as the walls.

    Returns
    -------
    dict
        Path name -> {``possible`` (bool: every reflection meets a building of its facade first,
        below its top), ``clearance_m`` (height of the last leg above the edge it leaves over;
        < 0: it passes below, diffracted), ``edge_distance_m`` (slant distance from the last
        reflection point, or the antenna, to that edge), ``extra_path_m`` (length of the path
        minus the direct range, over the roof edge where the last leg is diffracted),
        ``hit_x_m`` (along-street coordinate of the first reflection; 0 for ``direct``),
        ``facades`` (facade number of each reflection, shape (len(walls),) + u.shape[:-1])}.
    """
    u = np.asarray(u, dtype=float)
    shape = u.shape[:-1]
    height, half, along, sides = _street(shape, building_height_m, street_width_m, along_m,
                                         buildings)
    ahead = np.broadcast_to(np.asarray(ahead_m, dtype=float), shape)
    behind = np.broadcast_to(np.asarray(behind_m, dtype=float), shape)
    end_height = height if buildings is None else np.full(shape, buildings.end_height_m)
    out = {}
    for name, walls in PATHS.items():  # seven paths
        d = u
        for wall in walls:
            d = _mirror(d, wall)
        p = np.zeros(u.shape)
        possible = np.ones(shape, dtype=bool)
        legs = np.zeros(shape)
        hit_x = np.zeros(shape)
        facades = np.zeros((len(walls),) + shape, dtype=int)
        for n, wall in enumerate(walls):
            s, met = _exit(p, d, half, ahead, behind)
            possible &= np.isfinite(s)
            s = np.where(np.isfinite(s), s, 0.0)
            p = p + s[..., None] * d
            if wall in (RIGHT, LEFT):  # the image method per building: one must be there
                there, top, facades[n] = _side_facade(sides, np.bool_(wall == LEFT),
                                                      along + p[..., 0], height)
            else:
                there, top, facades[n] = True, end_height, _end_number(buildings, along, wall)
            possible &= (met == wall) & there & (p[..., 2] <= top)
            legs = legs + s
            if n == 0:
                hit_x = p[..., 0]
            d = _mirror(d, wall)
        edge, clearance = _leave(p, d, half, ahead, behind, along, height, end_height, sides)
        detour = np.linalg.norm(edge - p, axis=-1) - np.einsum("...k,...k->...", edge - p, u)
        extra = legs - np.einsum("...k,...k->...", p, u) + np.where(clearance < 0, detour, 0.0)
        out[name] = {"possible": possible, "clearance_m": clearance,
                     "edge_distance_m": np.linalg.norm(edge - p, axis=-1),
                     "extra_path_m": extra, "hit_x_m": hit_x, "facades": facades}
    return out


def lit_strip_solid_angle(distance_m: np.ndarray, low_m: np.ndarray, high_m: np.ndarray
                          ) -> np.ndarray:
    """Solid angle, sr, of an infinitely long vertical wall strip between heights ``low_m`` and
    ``high_m`` (above the eye) seen from ``distance_m`` in front of it:
    integral over x, z of D / (x^2 + z^2 + D^2)^(3/2) = 2 (atan(high / D) - atan(low / D))
    (0 where the strip has no height)."""
    d = np.asarray(distance_m, dtype=float)
    return 2.0 * np.maximum(np.arctan2(high_m, d) - np.arctan2(low_m, d), 0.0)


def scattered_path(u: np.ndarray, building_height_m: np.ndarray, street_width_m: np.ndarray,
                   scattering_coefficient: float, along_m: np.ndarray = 0.0,
                   buildings: Buildings | None = None) -> dict[str, np.ndarray]:
    """Diffuse scattering of a satellite's signal off the side facade across the street from it
    (the Lambertian effective-roughness model, module docstring; Degli-Esposti et al. 2007).

    Arguments as in ``trace_paths``. Returns ``possible`` (a lit strip exists: a building
    stands across the street at the antenna and the satellite lights part of it),
    ``loss_db`` (scattered power below the direct signal's, with the 3 dB of depolarisation;
    no antenna gain), ``arrival_elevation_rad`` (direction of the strip's middle) and
    ``extra_path_m``."""
    u = np.asarray(u, dtype=float)
    height, half, along, sides = _street(u.shape[:-1], building_height_m, street_width_m, along_m,
                                         buildings)
    toward_left = u[..., 1] < 0  # a satellite on the left lights the right facade
    _, near_top, _ = _side_facade(sides, toward_left, along, height)
    across, far_top, _ = _side_facade(sides, ~toward_left, along, height)
    # the ray over the near roof edge drops tan(el) / |sin a| = u_z / |u_y| per metre across
    with np.errstate(divide="ignore"):
        shadow = near_top - 2.0 * half * u[..., 2] / np.abs(u[..., 1])
    low = np.clip(shadow, 0.0, far_top)
    omega = lit_strip_solid_angle(half, low, far_top)
    cos_incidence = np.abs(u[..., 1])
    power = scattering_coefficient**2 * cos_incidence * omega / np.pi
    possible = across & (omega > 0) & (power > 0)
    with np.errstate(divide="ignore"):
        loss = np.where(possible, -10.0 * np.log10(np.where(possible, power, 1.0)) + 3.0,
                        np.inf)
    mid = 0.5 * (low + far_top)
    slant = np.hypot(half, mid)
    extra = slant * np.sqrt(np.maximum(1.0 - u[..., 0] ** 2, 0.0)) + half * np.abs(u[..., 1]) \
        - mid * u[..., 2]
    return {"possible": possible, "loss_db": loss, "arrival_elevation_rad": np.arctan2(mid, half),
            "extra_path_m": extra}


def canyon_reception(azimuth_rad: np.ndarray, elevation_rad: np.ndarray, heading_rad: np.ndarray,
                     building_height_m: np.ndarray, street_width_m: np.ndarray,
                     ahead_m: np.ndarray, behind_m: np.ndarray,
                     reflection_loss_db: np.ndarray, wavelength_m: float,
                     along_m: np.ndarray = 0.0, buildings: Buildings | None = None,
                     satellite: np.ndarray | None = None, scattering_coefficient: float = 0.0,
                     antenna_gain_db: Callable[[np.ndarray], np.ndarray] | None = None
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The strongest path of each satellite in a street canyon (module docstring).

    Parameters
    ----------
    azimuth_rad, elevation_rad : ndarray, shape S
        Satellite direction (azimuth from north, clockwise), rad.
    heading_rad : array_like, broadcast to S
        Direction of the street (the vehicle heading), rad.
    building_height_m, street_width_m, ahead_m, behind_m : array_like, broadcast to S
        As in ``trace_paths``.
    reflection_loss_db : ndarray, shape S + (F,), or (number of satellites, F) with ``satellite``
        C/N0 loss of a reflection off each facade, dB, by facade number (``Buildings``; for
        continuous facades F = 4: right, left, ahead, behind).
    wavelength_m : float
        Carrier wavelength (the diffraction parameter nu depends on it), m.
    along_m, buildings : as in ``trace_paths``
    satellite : ndarray of int, shape S, optional
        Row of ``reflection_loss_db`` of each sample's satellite (the loss of a building is drawn
        once per satellite, not per sample).
    scattering_coefficient : float
        S of the facades' diffuse scattering (``scattered_path``); 0: no scattered path.
    antenna_gain_db : callable, optional
        Antenna gain (dB, any reference) against elevation (rad): the scattered signal arrives
        from the lit facade, not from the satellite. None: the same gain either way.

    Returns
    -------
    los : ndarray of bool, S
        The strongest path is the direct one and clears the roof edge.
    nlos : ndarray of bool, S
        Above the horizon and not ``los``: received by diffraction, reflection or scattering
        only.
    extra_path_m : ndarray, S
        Extra path of the tracked signal (0 where ``los``), m.
    loss_db : ndarray, S
        C/N0 loss of the tracked signal, dB (the caller applies its tracking threshold).
    """
    el = np.asarray(elevation_rad, dtype=float)
    alpha = np.asarray(azimuth_rad, dtype=float) - np.asarray(heading_rad, dtype=float)
    cos_el = np.cos(el)
    u = np.stack(np.broadcast_arrays(cos_el * np.cos(alpha), cos_el * np.sin(alpha),
                                     np.sin(np.maximum(el, 1e-6))), axis=-1)
    paths = trace_paths(u, building_height_m, street_width_m, ahead_m, behind_m, along_m,
                        buildings)
    table = np.asarray(reflection_loss_db, dtype=float)
    if satellite is None:
        table = np.broadcast_to(table, u.shape[:-1] + table.shape[-1:])
    losses, extras = [], []
    for path in paths.values():
        nu = -path["clearance_m"] * np.sqrt(2.0 / (wavelength_m
                                                   * np.maximum(path["edge_distance_m"], 1e-3)))
        loss = knife_edge_loss_db(nu)
        for facade in path["facades"]:
            loss = loss + (table[satellite, facade] if satellite is not None else
                           np.take_along_axis(table, facade[..., None], axis=-1)[..., 0])
        losses.append(np.where(path["possible"], loss, np.inf))
        extras.append(path["extra_path_m"])
    if scattering_coefficient > 0:
        scattered = scattered_path(u, building_height_m, street_width_m, scattering_coefficient,
                                   along_m, buildings)
        loss = scattered["loss_db"]
        if antenna_gain_db is not None:
            loss = loss - (antenna_gain_db(scattered["arrival_elevation_rad"])
                           - antenna_gain_db(el))
        # beside a clear direct signal the scattered one is multipath, not a path of its own
        blocked = paths["direct"]["clearance_m"] < 0
        losses.append(np.where(scattered["possible"] & blocked, loss, np.inf))
        extras.append(scattered["extra_path_m"])
    losses, extras = np.stack(losses), np.stack(extras)
    best = np.argmin(losses, axis=0)
    loss_db = np.take_along_axis(losses, best[None], axis=0)[0]
    extra = np.take_along_axis(extras, best[None], axis=0)[0]
    above = el > 0
    los = above & (best == 0) & (paths["direct"]["clearance_m"] >= 0)
    nlos = above & ~los
    return los, nlos, np.where(los | ~above, 0.0, extra), loss_db
