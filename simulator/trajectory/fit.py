"""The smoothing fit shared by the ``sumo`` and ``recorded`` trajectory sources: from sampled 3-D
positions of a vehicle to a ``RoadProfile`` (road geometry along the distance travelled and the
distance in time) that the exact kinematics can differentiate.

The fit separates where the vehicle goes (geometry) from when it gets there (timing):

* geometry: the positions are stripped of standstill repeats and resampled every
  ``_RESAMPLE_M`` of chord length u (linearly, or with Akima's cubic when the samples are
  sparse, as in a 1 Hz log); east, north and up are fitted as penalised least-squares
  quintic B-splines (P-splines, Eilers and Marx 1996) of u with knots every ``knot_spacing``
  metres, or every ``knot_time`` seconds of travel where that is longer (de Boor, *A Practical
  Guide to Splines*, ch. XIV). The knot spacing bounds how sharp a corner can be, so a kink in
  SUMO's lane polylines (or in an OpenStreetMap way) or SUMO's non-smooth headings become a
  smooth curve, never a yaw-rate spike; the penalty damps the ringing next to a kink. With a
  ``max_curvature`` (a car's tightest turn, ``min_radius`` of a SUMO drive's ``fit``), the
  knots are spread further apart where the fitted path turns more sharply than that, by the
  ratio of its curvature to the limit over the knot spacing on either side, and the path
  fitted again, until no point of it turns tighter (at most ``_WIDEN_PASSES`` passes, the
  knots at most ``_WIDEST_KNOTS_M`` apart: a U-turn that SUMO draws within the road's width
  stays tighter, since a wider one would leave the road): a
  junction's turn that SUMO draws on a radius of 2 m, which no car can drive, becomes the
  wider turn that cuts its corner, still held to the road on both sides of it. The
  spline's own arc length sigma(u) is integrated (Gauss-Legendre), and its heading psi and grade
  angle gamma (both C4 in u) are re-interpolated as quintic splines of sigma, so that
  integrating the unit tangent along sigma reproduces the spline curve and curvature
  dpsi/dsigma is C3;
* timing: each sample's distance sigma_k is the arc length at its chord length; the piecewise
  linear distance S(t) through (t_k, sigma_k) is convolved with a triangle kernel of half-width
  ``time_window`` (two box filters). The result s(t) = (S2(t+W) - 2 S2(t) + S2(t-W)) / W^2, with
  S2 the second antiderivative of S, is a piecewise cubic with continuous acceleration, is
  non-decreasing because the kernel is non-negative, and is exactly flat wherever the vehicle
  stood still for longer than 2 W (so there is no heading change, hence no yaw rate, at rest).
  Its deviation from S is at most about a W^2 / 6 for an acceleration a.

Positions come in a local frame (``local_frame``): east and north on the tangent plane at the
first sample, and up as the geodetic height above that sample (not the plane's up, so a level
road stays level however far it runs). Headings in that plane are turned into true headings with
the meridian convergence (Groves section 2.4.2): at a point e metres east of the reference the
true azimuth of the plane's north is e tan(L0) / R_E.

References: P. H. C. Eilers and B. D. Marx, "Flexible smoothing with B-splines and penalties",
Statistical Science 11(2), 1996.

Public names
------------
FittedDrive, LocalFrame, fit_drive, fit_along, local_frame, plan_curvature, start_block,
zone_intervals.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simulator.earth import (
    ecef_to_geodetic,
    ecef_to_ned,
    geodetic_to_ecef,
    ned_to_ecef,
    radii_of_curvature,
)
from simulator.trajectory.piecewise import PiecewisePolynomial
from simulator.trajectory.segments import RoadProfile

_RESAMPLE_M = 1.0  # spacing of the resampled path used for the geometry fit, m
_DENSE_M = 0.25  # spacing of the arc-length grid the heading and grade are sampled on, m
_PENALTY = 0.1  # weight of the P-spline roughness penalty (per squared metre of residual)
_GL_X, _GL_W = np.polynomial.legendre.leggauss(4)  # arc-length quadrature per dense interval
_WIDEN_PASSES = 12  # at most this many refits spreading the knots of a too-sharp turn
# knots spread at most this far apart for a too-sharp turn, m: a turn that would need more
# (a U-turn SUMO draws within a road's width) cannot be widened and still follow the road
_WIDEST_KNOTS_M = 12.0


@dataclass
class FittedDrive:
    """A fitted drive: its road profile and where it starts.

    ``start_enu`` (m, shape (3,)) is the fitted position at t = 0 in the frame of the input
    positions; ``heading_deg`` the absolute heading there (from north, clockwise), which
    ``profile.heading`` (starting at 0) is relative to.
    """

    profile: RoadProfile
    start_enu: np.ndarray
    heading_deg: float


@dataclass
class LocalFrame:
    """Positions in the local frame of ``local_frame``: ``enu`` (n, 3), m; ``reference`` the
    (lat rad, lon rad, alt m) of its origin; ``convergence`` the true-heading change per metre
    east, rad/m."""

    enu: np.ndarray
    reference: tuple[float, float, float]
    convergence: float


def local_frame(lat_rad: np.ndarray, lon_rad: np.ndarray, alt_m: np.ndarray) -> LocalFrame:
    """Geodetic positions (n,) each to the local frame about the first one (see module doc)."""
    alt = np.asarray(alt_m, dtype=float)
    reference = (float(lat_rad[0]), float(lon_rad[0]), float(alt[0]))
    ned = ecef_to_ned(geodetic_to_ecef(lat_rad, lon_rad, np.full_like(alt, alt[0])), *reference)
    _, r_e = radii_of_curvature(reference[0])
    enu = np.stack([ned[:, 1], ned[:, 0], alt - alt[0]], axis=-1)
    return LocalFrame(enu, reference, float(np.tan(reference[0]) / (r_e + alt[0])))


def start_block(frame: LocalFrame, fitted: FittedDrive) -> dict:
    """The ``start`` (lat, lon deg, alt m, heading deg) of a fitted drive in ``frame``."""
    e, n, up = fitted.start_enu
    lat, lon, _ = (float(np.ravel(v)[0]) for v in ecef_to_geodetic(
        ned_to_ecef(np.array([[n, e, 0.0]]), *frame.reference)))
    return {"lat": float(np.degrees(lat)), "lon": float(np.degrees(lon)),
            "alt": float(frame.reference[2] + up), "heading": fitted.heading_deg}


def fit_drive(t: np.ndarray, enu: np.ndarray, knot_spacing: float = 3.0,
              time_window: float = 0.5, knot_time: float = 0.4, standstill_m: float = 1e-3,
              zones: list[tuple[float, float, str]] | None = None,
              convergence: float = 0.0, max_curvature: float = 0.0) -> FittedDrive:
    """Fit a smooth road profile to sampled positions.

    Parameters
    ----------
    t : array, shape (n,)
        Sample times, s, strictly increasing; the profile's t = 0 is ``t[0]``.
    enu : array, shape (n, 3)
        Positions in a local level frame (east, north, up), m.
    knot_spacing : float
        Smallest knot spacing of the geometry splines, m (larger = smoother path, looser fit).
    knot_time : float
        Knots are at least this many seconds of travel apart at the local speed, s.
    time_window : float
        Half-width W of the triangle kernel that smooths the distance in time, s.
    standstill_m : float
        Steps shorter than this (m) count as standing still (removes jitter at rest).
    zones : list of (t_start, t_end, name), optional
        Zone intervals in the input's time; shifted with it.
    convergence : float
        True-heading change per metre east of the frame's origin, rad/m (``LocalFrame``).
    max_curvature : float
        The largest horizontal curvature the fitted path may have, 1/m (see the module doc);
        0: no limit.

    Returns
    -------
    FittedDrive

    Raises
    ------
    ValueError
        When the samples are not increasing in time or the vehicle never moves.
    """
    from scipy.interpolate import Akima1DInterpolator, make_interp_spline  # see module doc

    t = np.asarray(t, dtype=float)
    enu = np.asarray(enu, dtype=float)
    if len(t) < 2 or np.any(np.diff(t) <= 0):
        raise ValueError("the position samples must have at least two strictly increasing times")
    step = np.linalg.norm(np.diff(enu, axis=0), axis=1)
    step[step < standstill_m] = 0.0
    chord = np.concatenate([[0.0], np.cumsum(step)])
    total = chord[-1]
    if total < 4 * knot_spacing:
        raise ValueError(f"the vehicle moves only {total:.1f} m; at least {4 * knot_spacing:g} m "
                         "are needed to fit a road")
    moving = np.concatenate([[True], step > 0])
    u_grid = np.linspace(0.0, total, int(np.ceil(total / _RESAMPLE_M)) + 1)
    if np.median(step[step > 0]) > 2 * _RESAMPLE_M:
        # sparse samples (a 1 Hz log): chords would cut every bend, so interpolate with Akima's
        # local cubic (no overshoot next to a corner)
        path = Akima1DInterpolator(chord[moving], enu[moving], axis=0)(u_grid)
    else:
        path = np.stack([np.interp(u_grid, chord[moving], enu[moving, i]) for i in range(3)], -1)
    dt = np.diff(t)
    speed = np.interp(u_grid, chord[1:][step > 0], (step / dt)[step > 0])
    curve = _drivable_fit(u_grid, path, np.maximum(knot_spacing, knot_time * speed),
                          max_curvature)

    u_dense = np.linspace(0.0, total, int(np.ceil(total / _DENSE_M)) + 1)
    sigma = _arc_length(curve, u_dense)
    d = curve(u_dense, 1)
    horizontal = np.hypot(d[:, 0], d[:, 1])
    psi = np.unwrap(np.arctan2(d[:, 0], d[:, 1])) + convergence * curve(u_dense)[:, 0]
    gamma = np.arctan2(d[:, 2], horizontal)
    heading_abs = _piecewise(make_interp_spline(sigma, psi, k=5))
    curvature = heading_abs.derivative()
    grade = _piecewise(make_interp_spline(sigma, gamma, k=5))
    bank = PiecewisePolynomial(np.zeros((1, 1)), np.array([0.0, sigma[-1]]))

    sigma_k = np.interp(chord, u_dense, sigma)
    tt = t - t[0]
    distance = _smoothed_distance(tt, sigma_k, time_window)
    shifted = [(a - t[0], b - t[0], name) for a, b, name in (zones or [])]
    profile = RoadProfile(distance_of_time=distance, curvature=curvature,
                          heading=curvature.antiderivative(), grade=grade, bank=bank,
                          duration_s=float(tt[-1]), zones=shifted)
    u0 = float(np.interp(distance(0.0), sigma, u_dense))
    return FittedDrive(profile, curve(u0), float(np.degrees(heading_abs(0.0))))


def fit_along(sigma: np.ndarray, values: np.ndarray, spacing: float) -> PiecewisePolynomial:
    """A smooth (C4) function of the distance through samples: the P-spline of the path fit.

    Parameters
    ----------
    sigma : array, shape (n,)
        Distances along the road, m, strictly increasing.
    values : array, shape (n,)
        Samples (a road bank angle, rad).
    spacing : float
        Knot spacing, m.
    """
    return _piecewise(_lsq_quintic(sigma, np.asarray(values, dtype=float),
                                   np.full(len(sigma), float(spacing))))


def zone_intervals(t: np.ndarray, zone: np.ndarray) -> list[tuple[float, float, str]]:
    """Runs of equal, non-empty zone names as (t_start, t_end, name)."""
    change = np.flatnonzero(zone[1:] != zone[:-1]) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [len(zone)]])
    return [(float(t[a]), float(t[min(b, len(t) - 1)]), str(zone[a]))
            for a, b in zip(starts, ends, strict=True) if zone[a]]


def _piecewise(spline) -> PiecewisePolynomial:
    """A B-spline as a piecewise polynomial without its zero-width end intervals."""
    from scipy.interpolate import PPoly

    pp = PPoly.from_spline(spline)
    keep = np.diff(pp.x) > 0
    return PiecewisePolynomial(pp.c[:, keep], np.concatenate([pp.x[:-1][keep], pp.x[-1:]]))


def _lsq_quintic(u: np.ndarray, points: np.ndarray, spacing: np.ndarray):
    """Penalised least-squares quintic B-spline (P-spline) of ``points`` (n, 3) over ``u``, with
    knots ``spacing`` (n,) metres apart locally and a ``_PENALTY`` on the third differences of
    the coefficients (Eilers and Marx 1996, eq. 8), which damps the ringing a plain least-squares
    fit shows next to a kink."""
    from scipy import sparse
    from scipy.interpolate import BSpline
    from scipy.sparse.linalg import spsolve

    k = 5
    count = np.concatenate([[0.0], np.cumsum(np.diff(u) / spacing[1:])])
    n_int = max(1, int(round(count[-1])))
    inner = np.interp(np.linspace(0.0, count[-1], n_int + 1), count, u)
    knots = np.concatenate([[u[0]] * k, inner, [u[-1]] * k])
    basis = BSpline.design_matrix(u, knots, k).tocsr()
    diff = sparse.eye(basis.shape[1], format="csr")
    for _ in range(3):
        diff = diff[1:] - diff[:-1]
    # the coefficients next to the clamped ends sit on coincident knots, where differences are
    # not derivatives: penalising them would bend the path's ends
    diff = diff[k:-k] if diff.shape[0] > 2 * k else diff[:0]
    normal = (basis.T @ basis + _PENALTY * (diff.T @ diff)).tocsc()
    return BSpline(knots, spsolve(normal, basis.T @ points), k, axis=0)


def _drivable_fit(u: np.ndarray, points: np.ndarray, spacing: np.ndarray,
                  max_curvature: float):
    """``_lsq_quintic`` with the knots spread apart, pass by pass, where the curve turns more
    sharply than ``max_curvature`` (1/m; 0: the plain fit; see the module doc)."""
    from scipy.ndimage import maximum_filter1d

    curve = _lsq_quintic(u, points, spacing)
    widest = np.maximum(spacing, _WIDEST_KNOTS_M)
    for _ in range(_WIDEN_PASSES if max_curvature > 0 else 0):
        excess = np.abs(plan_curvature(curve, u)) / max_curvature
        if excess.max() <= 1.0:
            break
        reach = 2 * int(np.ceil(spacing.max() / max(u[1] - u[0], 1e-9))) + 1
        wider = np.minimum(spacing * maximum_filter1d(np.maximum(excess, 1.0), reach), widest)
        if np.array_equal(wider, spacing):
            break
        spacing = wider
        curve = _lsq_quintic(u, points, spacing)
    return curve


def plan_curvature(curve, u: np.ndarray) -> np.ndarray:
    """The horizontal curvature (1/m, + turning right, clockwise seen from above: east x, north
    y) of a 3-D spline curve (east, north, up) of a parameter u at u: (y' x'' - x' y'') / (x'^2
    + y'^2)^(3/2)."""
    d1, d2 = curve(u, 1), curve(u, 2)
    cross = d1[:, 1] * d2[:, 0] - d1[:, 0] * d2[:, 1]
    return cross / np.hypot(d1[:, 0], d1[:, 1]) ** 3


def _arc_length(curve, u: np.ndarray) -> np.ndarray:
    """Arc length of a 3-D spline curve at ``u`` (cumulative from u[0]), Gauss-Legendre."""
    a, b = u[:-1], u[1:]
    nodes = 0.5 * (a + b)[:, None] + 0.5 * (b - a)[:, None] * _GL_X[None, :]
    speed = np.linalg.norm(curve(nodes.ravel(), 1), axis=1).reshape(nodes.shape)
    pieces = 0.5 * (b - a) * (speed @ _GL_W)
    return np.concatenate([[0.0], np.cumsum(pieces)])


def _smoothed_distance(t: np.ndarray, s: np.ndarray, w: float) -> PiecewisePolynomial:
    """Triangle-kernel smoothing (half-width w) of the piecewise linear s(t), as a C2 PPoly.

    S is extended linearly beyond both ends with its first and last slopes.
    """
    from scipy.interpolate import PPoly

    slope0 = (s[1] - s[0]) / (t[1] - t[0])
    slope1 = (s[-1] - s[-2]) / (t[-1] - t[-2])
    tx = np.concatenate([[t[0] - 2 * w], t, [t[-1] + 2 * w]])
    sx = np.concatenate([[s[0] - 2 * w * slope0], s, [s[-1] + 2 * w * slope1]])
    linear = PPoly(np.stack([np.diff(sx) / np.diff(tx), sx[:-1]]), tx)
    s2 = linear.antiderivative(2)

    def smoothed(x: np.ndarray, nu: int) -> np.ndarray:
        return (s2(x + w, nu) - 2 * s2(x, nu) + s2(x - w, nu)) / w**2

    breaks = np.unique(np.round(np.concatenate([t, t - w, t + w]), 9))
    breaks = breaks[(breaks >= t[0]) & (breaks <= t[-1])]
    mid = 0.5 * (breaks[:-1] + breaks[1:])
    a = [smoothed(mid, nu) / f for nu, f in zip(range(4), (1, 1, 2, 6), strict=True)]
    for coeff in a[1:]:  # exactly flat where the vehicle stands (no creeping at 1e-13 m/s)
        coeff[np.abs(coeff) < 1e-9] = 0.0
    # and there S itself is the smoothed value: this avoids the rounding of the second
    # differences of S2 (about 1e-7 m after a few kilometres), so a stop has one exact distance
    flat = (a[1] == 0.0) & (a[2] == 0.0) & (a[3] == 0.0)
    a[0][flat] = np.interp(mid[flat], t, s)
    d = mid - breaks[:-1]  # re-expand the Taylor polynomial at mid about the left break
    coeffs = np.stack([
        a[3],
        a[2] - 3 * a[3] * d,
        a[1] - 2 * a[2] * d + 3 * a[3] * d**2,
        a[0] - a[1] * d + a[2] * d**2 - a[3] * d**3,
    ])
    return PiecewisePolynomial(coeffs, breaks)
