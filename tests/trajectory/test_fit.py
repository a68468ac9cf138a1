"""The smoothing fit from sampled positions to a road profile, against analytic drives: a circle
of known radius on a known grade, standstills, and a kinked polyline."""

from __future__ import annotations

import numpy as np
import pytest

import simulator.scenario  # noqa: F401  (loads the schema before the trajectory package)
from simulator import earth
from simulator.trajectory.fit import fit_drive, local_frame
from simulator.trajectory.kinematics import Kinematics, Origin


def _circle_drive(radius=50.0, grade=0.03, dt=0.1):
    """20 s standing, then 1 m/s^2 up to 10 m/s, on a left-hand circle climbing at ``grade``."""
    t = np.arange(0.0, 120.0, dt)
    v = np.clip(t - 20.0, 0.0, 10.0)
    s = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * dt)])  # exact for this v
    horizontal = s / np.sqrt(1 + grade**2)
    enu = np.stack([radius * np.sin(horizontal / radius),
                    radius * (1 - np.cos(horizontal / radius)), grade * horizontal], axis=-1)
    return t, s, enu


def test_circle_curvature_grade_and_timing():
    t, s, enu = _circle_drive()
    fitted = fit_drive(t, enu)
    p = fitted.profile
    sigma = np.linspace(20.0, s[-1] - 40.0, 200)  # away from the free ends of the spline
    # a left (anticlockwise) circle of 50 m in the plane: kappa = -cos(gamma)/R along the road
    np.testing.assert_allclose(p.curvature(sigma), -np.cos(np.arctan(0.03)) / 50.0, rtol=1e-2)
    assert np.mean(p.curvature(sigma)) == pytest.approx(-np.cos(np.arctan(0.03)) / 50.0,
                                                        rel=1e-3)
    np.testing.assert_allclose(np.tan(p.grade(sigma)), 0.03, atol=2e-4)
    assert fitted.heading_deg == pytest.approx(90.0, abs=0.05)
    tt = np.linspace(0.0, t[-1], 2000)
    # the triangle kernel (half-width 0.5 s) moves s(t) by at most a W^2/6 = 0.04 m at 1 m/s^2
    assert np.max(np.abs(p.distance_of_time(tt) - np.interp(tt, t, s))) < 0.05


def test_distance_is_monotone_c2_and_flat_at_rest():
    t, _, enu = _circle_drive()
    p = fit_drive(t, enu).profile
    d = p.distance_of_time
    tt = np.linspace(0.0, t[-1], 20001)
    assert np.min(d(tt, 1)) >= -1e-12
    inner = d.x[1:-1]
    for nu in (0, 1, 2):  # value, speed and acceleration continuous at every break
        left, right = d(inner - 1e-9, nu), d(inner + 1e-9, nu)
        assert np.max(np.abs(left - right)) < 1e-6
    still = tt < 19.4  # standing (until 20 s) minus the kernel half-width
    assert np.all(d(tt[still], 1) == 0.0)
    assert np.ptp(d(tt[still])) == 0.0


def test_standstill_has_no_yaw_rate_beyond_earth_rate():
    t, _, enu = _circle_drive()
    fitted = fit_drive(t, enu)
    truth = Kinematics(fitted.profile, Origin(45.0, 7.0, 200.0, fitted.heading_deg), 100.0, 0.0)
    k = truth.inertial(np.linspace(0.0, 19.0, 50))
    c_bn = earth.euler_to_dcm(k["roll"], k["pitch"], k["yaw"])
    expected = np.einsum("nji,nj->ni", c_bn, earth.earth_rate_ned(k["lat"]))
    np.testing.assert_allclose(k["w_body"], expected, atol=1e-15)


def test_kinked_polyline_gives_bounded_yaw_rate():
    """A 90 degree corner with no rounding at all (a raw polyline), driven at 5 m/s: the fit
    rounds it over the knots (3 m apart) instead of putting a spike of infinite curvature in."""
    dt, v = 0.1, 5.0
    t = np.arange(0.0, 40.0, dt)
    s = v * t
    enu = np.where(s[:, None] < 100.0, np.stack([s, 0 * s, 0 * s], -1),
                   np.stack([100.0 + 0 * s, -(s - 100.0), 0 * s], -1))
    p = fit_drive(t, enu).profile
    sig = np.linspace(0.0, s[-1], 5000)
    heading_change = p.heading(sig[-1]) - p.heading(sig[0])
    assert np.degrees(heading_change) == pytest.approx(90.0, abs=0.5)  # east, then south
    kappa = np.abs(p.curvature(sig))
    assert 1.0 / np.max(kappa) > 1.5  # smallest radius, m
    # the penalty damps the ringing next to the corner: under 0.02 rad/m 10 m away, and
    # under 0.002 rad/m 20 m away
    far = np.abs(sig - 100.0)
    assert kappa[far > 10].max() < 0.02 and kappa[far > 20].max() < 0.002


def test_local_frame_is_level_and_converges_to_true_north():
    lat0, lon0 = np.radians(48.0), np.radians(11.0)
    east = np.linspace(0.0, 5000.0, 11)
    lat = np.full_like(east, lat0)
    lon = lon0 + east / (earth.radii_of_curvature(lat0)[1] * np.cos(lat0))
    frame = local_frame(lat, lon, np.full_like(east, 500.0))
    np.testing.assert_allclose(frame.enu[:, 2], 0.0, atol=1e-9)  # a level road stays level
    # along a parallel the true heading is 90 deg; the tangent-plane heading plus the
    # convergence term must give it (the plane's direction bends towards the equator)
    d = np.diff(frame.enu, axis=0)
    plane_heading = np.arctan2(d[:, 0], d[:, 1])
    true_heading = plane_heading + frame.convergence * 0.5 * (frame.enu[1:, 0] + frame.enu[:-1, 0])
    np.testing.assert_allclose(np.degrees(true_heading), 90.0, atol=2e-4)


def test_rejects_bad_samples():
    t, _, enu = _circle_drive()
    with pytest.raises(ValueError, match="increasing"):
        fit_drive(t[::-1], enu)
    with pytest.raises(ValueError, match="moves only"):
        fit_drive(t[:100], enu[:100])


def test_a_corner_tighter_than_a_car_turns_is_widened_to_its_radius():
    """A SUMO junction's turn on a 2 m radius at 2.5 m/s (fit.min_radius): unlimited, the fit
    follows it (radius under 3 m); limited to 4.5 m, no point of the fitted path turns tighter
    (to 1 %: the fit checks the spline, the profile re-interpolates its heading), the turn
    still turns by 90 degrees, and 30 m either side of the corner the path is the road's
    straight again (curvature under 0.002 rad/m; the wider knots spread the turn's tail
    further than the plain fit's 20 m next to a kink: 0.01 rad/m at 20 m)."""
    dt, v, r = 0.1, 2.5, 2.0
    t = np.arange(0.0, 50.0, dt)
    s = v * t
    arc = 0.5 * np.pi * r
    a = np.clip((s - 50.0) / r, 0.0, 0.5 * np.pi)
    enu = np.stack([np.where(s < 50.0, s, 50.0 + r * np.sin(a)),
                    np.where(s < 50.0 + arc, -r * (1 - np.cos(a)), -r - (s - 50.0 - arc)),
                    0 * s], -1)  # east, then a right turn to the south
    sig = np.linspace(0.0, s[-1] - 1.0, 20000)
    plain = fit_drive(t, enu).profile
    assert 1.0 / np.abs(plain.curvature(sig)).max() < 3.0
    p = fit_drive(t, enu, max_curvature=1 / 4.5).profile
    sig = np.linspace(0.0, float(p.distance_of_time(t[-1])), 20000)
    kappa = np.abs(p.curvature(sig))
    assert 1.0 / kappa.max() > 4.5 * 0.99
    assert np.degrees(p.heading(sig[-1]) - p.heading(sig[0])) == pytest.approx(90.0, abs=0.5)
    corner = 50.0 + 0.5 * arc
    assert kappa[(np.abs(sig - corner) > 30) & (sig > 1.0)].max() < 0.002
