"""The street-canyon sky against hand-solvable geometry: a satellite along the street is in line
of sight, one across the street below the facades' angle is blocked or reflected, a reflection's
extra path is the image-antenna distance (one and two side facades, the end facade), diffraction
over a roof edge follows the knife-edge loss of ITU-R P.526, diffuse scattering off the lit
facade across the street is the Lambertian integral over it (patch by patch, by quadrature)."""

from __future__ import annotations

import numpy as np
import pytest

from simulator.environment.sky import (
    Buildings,
    canyon_reception,
    knife_edge_loss_db,
    lit_strip_solid_angle,
    scattered_path,
    street_buildings,
    trace_paths,
)

LAMBDA_M = 0.1903  # GPS L1 wavelength
H, W = 20.0, 20.0  # facades 20 m above the antenna, 20 m apart
NO_LOSS = np.zeros(4)


def _u(az_deg: float, el_deg: float) -> np.ndarray:
    """Unit vector toward a satellite in street axes (x along the street, y right, z up)."""
    az, el = np.radians(az_deg), np.radians(el_deg)
    return np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])


def _receive(az_deg, el_deg, ahead=np.inf, behind=np.inf, loss=None, heading_deg=0.0,
             height=H):
    loss = np.full(4, 15.0) if loss is None else loss
    return canyon_reception(np.radians(az_deg), np.radians(el_deg), np.radians(heading_deg),
                            height, W, ahead, behind, np.asarray(loss, dtype=float), LAMBDA_M)


@pytest.mark.parametrize("heading", [0.0, 73.0, 250.0])
@pytest.mark.parametrize("el", [5.0, 30.0, 89.0])
def test_satellite_along_the_street_is_line_of_sight(heading, el):
    for along in (0.0, 180.0):  # ahead or behind, the street open at both ends
        los, nlos, extra, loss = _receive(heading + along, el, heading_deg=heading)
        assert los and not nlos and extra == 0.0 and loss == pytest.approx(0.0, abs=1e-9)


def test_satellite_across_the_street_below_the_facade_is_reflected_with_image_path():
    # across (90 deg): direct needs tan(el) >= H / (W / 2) = 2 (63.4 deg); the reflection off
    # the far facade needs tan(el) >= H / (3 W / 2) = 2 / 3 (33.7 deg)
    for el in (40.0, 50.0, 60.0):
        los, nlos, extra, loss = _receive(90.0, el)
        assert not los and nlos
        assert loss == pytest.approx(15.0, abs=1e-9)  # one facade's loss, no edge in the way
        # image method: the antenna mirrored in the facade W / 2 away, seen along u
        assert extra == pytest.approx(2 * (W / 2) * np.cos(np.radians(el)), rel=1e-12)
    # 30 deg off the street's normal the condition is H |sin a|; the image path scales the same
    los, nlos, extra, _ = _receive(60.0, 40.0)
    assert nlos and extra == pytest.approx(W * np.cos(np.radians(40.0)) * np.sin(np.radians(60)))
    # above 63.4 deg it is direct again
    assert _receive(90.0, 70.0)[0]


def test_satellite_across_the_street_below_both_angles_is_lost():
    # below 33.7 deg across, the reflection too goes under the satellite-side roof: the
    # strongest path left is diffracted deep into the shadow, tens of dB down
    los, nlos, _, loss = _receive(90.0, 20.0)
    assert not los and nlos and loss > 30.0


def test_ray_just_below_a_roof_edge_is_diffracted_with_a_few_db():
    # tan(el) (W / 2) = H - 0.05 m: the ray passes 5 cm under the edge, 10.2 m away
    el = np.degrees(np.arctan((H - 0.05) / (W / 2)))
    los, nlos, extra, loss = _receive(90.0, el)
    assert not los and nlos
    assert 6.0 < loss < 7.5  # J(0) = 6.0 dB at grazing, slightly more just below
    assert 0 < extra < 0.01  # the detour over the edge is millimetres


def test_knife_edge_loss_against_itu_r_p526():
    """J(nu): 0 dB below nu = -0.78 (continuous there), 6.0 dB at grazing incidence
    (ITU-R P.526-15 Fig. 9), and 13 + 20 log10(nu) for large nu (its approximation)."""
    assert knife_edge_loss_db(-0.78) == pytest.approx(0.0, abs=0.01)
    assert knife_edge_loss_db(-5.0) == 0.0
    assert knife_edge_loss_db(0.0) == pytest.approx(6.0, abs=0.05)
    assert knife_edge_loss_db(10.0) == pytest.approx(13.0 + 20.0, abs=0.2)


def test_far_end_reflection_extra_path_is_the_image_distance():
    # a satellite straight ahead at 20 deg: the 40 m facade across the street 50 m ahead hides
    # it (50 tan 20 = 18.2 m, 22 m under the edge: over 30 dB of diffraction loss); its signal
    # arrives reflected off the facade 60 m behind (met 21.8 m up, leaving 61.8 m up)
    el = 20.0
    los, nlos, extra, loss = _receive(0.0, el, ahead=50.0, behind=60.0, height=40.0)
    assert not los and nlos and loss == pytest.approx(15.0, abs=1e-9)
    assert extra == pytest.approx(2 * 60.0 * np.cos(np.radians(el)), rel=1e-12)
    # the end facade's long delay is a property of the geometry: 2 d cos(el) grows with d
    assert _receive(0.0, 3.0, ahead=50.0, behind=600.0, height=40.0)[2] == pytest.approx(
        2 * 600.0 * np.cos(np.radians(3.0)), rel=1e-12)


def test_double_reflection_extra_path_is_the_twice_mirrored_image():
    # a satellite on the right, 40 m facades: its signal passes over the right roof, meets the
    # left facade 25.6 m up, the right one 8.5 m up, and reaches the antenna. Traced from the
    # antenna: right facade, then left, then out over the right roof. The antenna mirrored in
    # the right facade (y = W) and that image in the left one (y = -2 W): extra 2 W cos(el) sin(a)
    u = _u(80.0, 40.0)
    path = trace_paths(u, 40.0, W, np.inf, np.inf)["right_left"]
    assert path["possible"] and path["clearance_m"] >= 0
    assert path["extra_path_m"] == pytest.approx(2 * W * u[1], rel=1e-12)
    # a facade missed first is no reflection: a satellite on the left cannot come that way
    assert not trace_paths(_u(-80.0, 40.0), 40.0, W, np.inf, np.inf)["right_left"]["possible"]
    # nor one met above its top: at 60 deg the left facade would be met 52.8 m up
    assert not trace_paths(_u(80.0, 60.0), 40.0, W, np.inf, np.inf)["right_left"]["possible"]


def test_the_strongest_path_is_tracked():
    # a satellite on the right (blocked, as above) with the far (left) facade a perfect mirror
    # and the others absorbing: the left facade's reflection is chosen; made absorbing too,
    # the satellite is received only by diffraction, far weaker
    loss = np.array([60.0, 0.0, 60.0, 60.0])
    los, nlos, extra, got = _receive(90.0, 45.0, loss=loss)
    assert nlos and got == 0.0 and extra == pytest.approx(W * np.cos(np.radians(45.0)))
    _, nlos, extra, got = _receive(90.0, 45.0, loss=np.full(4, 60.0))
    assert nlos and 20.0 < got < 60.0
    # over the right roof edge E = (0, W / 2, H): the bent path's extra |E| - E . u
    edge, u = np.array([0.0, W / 2, H]), _u(90.0, 45.0)
    assert extra == pytest.approx(np.linalg.norm(edge) - edge @ u, rel=1e-12)


# -- buildings with gaps, cross streets and their own heights ---------------------------------

def _buildings(right: list[tuple[float, float, float]], left: list[tuple[float, float, float]],
               end_height: float = H) -> Buildings:
    """Buildings from (start, end, height) rows per side, one street from s = -1000 m."""
    r, lft = np.array(right, dtype=float), np.array(left, dtype=float)
    return Buildings((r[:, 0], lft[:, 0]), (r[:, 1], lft[:, 1]), (r[:, 2], lft[:, 2]),
                     np.array([-1000.0]), end_height)


# both sides: a block [0, 100), a cross street [100, 120), a block [120, 220), 20 m high
BLOCKS = [(0.0, 100.0, H), (120.0, 220.0, H)]


def test_a_ray_through_a_cross_street_is_line_of_sight():
    # across the street at 30 deg: in front of a building its ray meets the facade 5.8 m up
    # (blocked); standing in the intersection the same ray leaves along the cross street
    for along, expected in ((50.0, False), (110.0, True)):
        path = trace_paths(_u(90.0, 30.0), H, W, np.inf, np.inf, along, _buildings(BLOCKS, BLOCKS))
        assert (path["direct"]["clearance_m"] >= 0) == expected
    # 30 deg off the normal (a = 60 deg) from s = 105: the ray crosses the facade line at
    # s = 105 + (W / 2) / tan(a), in the cross street, and runs on to the next block's corner
    # wall at s = 120, 15 / cos(a) m of horizontal distance away: clearance 30 tan(el) - H
    for el in (30.0, 40.0):
        path = trace_paths(_u(60.0, el), H, W, np.inf, np.inf, 105.0,
                           _buildings(BLOCKS, BLOCKS))["direct"]
        expected = 15.0 / np.cos(np.radians(60.0)) * np.tan(np.radians(el)) - H
        assert path["clearance_m"] == pytest.approx(expected, rel=1e-12)
    # a building lower than the ray lets it through: the building in its way decides
    low = [(0.0, 100.0, 5.0), (120.0, 220.0, H)]
    assert trace_paths(_u(90.0, 30.0), H, W, np.inf, np.inf, 50.0,
                       _buildings(low, BLOCKS))["direct"]["clearance_m"] >= 0


def test_a_reflection_point_on_a_gap_gives_no_reflection():
    # right side continuous, the left side with a gap [100, 120). A satellite at a = 60 deg,
    # 45 deg up, is hidden by the right facade (met 11.5 m up); its reflection off the left
    # facade is met at x = (W / 2) / tan(a) = 5.77 m ahead, 11.5 m up
    right = [(0.0, 220.0, H)]
    u = _u(60.0, 45.0)
    on_building = trace_paths(u, H, W, np.inf, np.inf, 80.0, _buildings(right, BLOCKS))
    on_gap = trace_paths(u, H, W, np.inf, np.inf, 100.0, _buildings(right, BLOCKS))
    assert on_building["direct"]["clearance_m"] < 0 and on_gap["direct"]["clearance_m"] < 0
    assert on_building["left"]["possible"] and not on_gap["left"]["possible"]
    assert on_building["left"]["hit_x_m"] == pytest.approx((W / 2) / np.tan(np.radians(60.0)))
    # the image method: the extra path is still the mirrored antenna's W cos(el) sin(a)
    assert on_building["left"]["extra_path_m"] == pytest.approx(W * u[1], rel=1e-12)
    # a building too low for the point (11.5 m) reflects nothing either
    low_left = [(0.0, 100.0, 10.0), (120.0, 220.0, H)]
    assert not trace_paths(u, H, W, np.inf, np.inf, 80.0,
                           _buildings(right, low_left))["left"]["possible"]


def test_the_reflecting_building_gives_its_own_loss():
    # as above, from s = 80: the reflection point is on the left side's first building
    # (facade number 1: the right side's one building is 0); its loss is the one applied
    buildings = _buildings([(0.0, 220.0, H)], BLOCKS)
    table = np.array([[60.0, 7.0, 12.0, 60.0, 60.0]])  # right, left x2, the street's two ends
    los, nlos, _, loss = canyon_reception(
        np.radians([60.0]), np.radians([45.0]), 0.0, H, W, np.inf, np.inf, table, LAMBDA_M,
        80.0, buildings, np.array([0]))
    assert nlos[0] and loss[0] == pytest.approx(7.0, abs=1e-9)
    # from s = 130 the point is on the second left building (number 2)
    *_, loss = canyon_reception(np.radians([60.0]), np.radians([45.0]), 0.0, H, W, np.inf,
                                np.inf, table, LAMBDA_M, 130.0, buildings, np.array([0]))
    assert loss[0] == pytest.approx(12.0, abs=1e-9)


def test_closed_blocks_of_one_height_are_the_continuous_facade():
    """With no cross streets, no gaps and no height spread, the laid-out street traces exactly
    as the continuous facades (the special case the analytic tests above use)."""
    buildings = street_buildings(np.random.default_rng(1), np.array([[0.0, 400.0]]), 110.0, 0.0,
                                 20.0, 0.0, 30.0, 0.0)
    gen = np.random.default_rng(2)
    az, el = gen.uniform(0, 2 * np.pi, 500), gen.uniform(0.05, 1.5, 500)
    u = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=-1)
    along = gen.uniform(0.0, 400.0, 500)
    ahead, behind = 400.0 - along, along
    laid = trace_paths(u, 30.0, W, ahead, behind, along, buildings)
    plain = trace_paths(u, 30.0, W, ahead, behind)
    for name in laid:
        for key in ("possible", "clearance_m", "extra_path_m"):
            np.testing.assert_allclose(laid[name][key], plain[name][key], rtol=1e-12, atol=1e-9)


def test_street_layout_blocks_and_heights_are_reproducible():
    args = (np.array([[100.0, 460.0]]), 110.0, 20.0, 20.0, 2.0, 22.0, 3.0)
    one = street_buildings(np.random.default_rng(5), *args)
    again = street_buildings(np.random.default_rng(5), *args)
    other = street_buildings(np.random.default_rng(6), *args)
    for side in (0, 1):
        np.testing.assert_array_equal(one.height_m[side], again.height_m[side])
        assert not np.array_equal(one.height_m[side], other.height_m[side])
        np.testing.assert_array_equal(one.start_m[side], other.start_m[side])
    # blocks of 110 m from the street's start every 130 m (20 m cross streets); buildings of
    # 20 m frontage 2 m apart (five fit in a block); the street's end cuts the last one
    starts, ends = one.start_m[0], one.end_m[0]
    np.testing.assert_allclose(starts[:6], [100.0, 122.0, 144.0, 166.0, 188.0, 230.0])
    np.testing.assert_allclose(ends[:6], [120.0, 142.0, 164.0, 186.0, 208.0, 250.0])
    np.testing.assert_allclose(starts[-1], 100.0 + 2 * 130.0 + 88.0)
    assert ends[-1] == pytest.approx(460.0) and one.count == 2 * len(starts) + 2
    # a block's end cuts its last building: 25 m frontages in a 110 m block end at 110 m
    cut = street_buildings(np.random.default_rng(5), np.array([[0.0, 300.0]]), 110.0, 20.0,
                           25.0, 0.0, 22.0, 3.0)
    np.testing.assert_allclose(cut.end_m[1][:6], [25.0, 50.0, 75.0, 100.0, 110.0, 155.0])
    # the heights: N(22, 3) per building, independently on both sides
    many = street_buildings(np.random.default_rng(7), np.array([[0.0, 2e5]]), 110.0, 20.0,
                            20.0, 0.0, 22.0, 3.0)
    heights = np.concatenate(many.height_m)
    assert abs(heights.mean() - 22.0) < 4 * 3.0 / np.sqrt(heights.size)
    assert heights.std() == pytest.approx(3.0, rel=0.05)
    assert abs(np.corrcoef(many.height_m[0], many.height_m[1])[0, 1]) < 0.05


def test_a_street_stood_in_gets_a_block_that_stops_at_the_next_street():
    # a zone the car stands in (no length) at s = 0, the next stretch of it from s = 50 m: one
    # block from 0, cut where the next street begins, and the buildings stay sorted
    buildings = street_buildings(np.random.default_rng(3), np.array([[0.0, 0.0], [50.0, 300.0]]),
                                 110.0, 20.0, 20.0, 0.0, 22.0, 3.0)
    start, end = buildings.start_m[0], buildings.end_m[0]
    np.testing.assert_allclose(start[:4], [0.0, 20.0, 40.0, 50.0])
    np.testing.assert_allclose(end[:3], [20.0, 40.0, 50.0])
    assert (np.diff(start) > 0).all() and (start[1:] >= end[:-1]).all()
    assert buildings.count == 2 * len(start) + 4


# diffuse scattering (the Lambertian effective-roughness model, Degli-Esposti et al. 2007)

S = 0.4


def _lambertian_fraction_by_quadrature(u: np.ndarray, low: float, high: float,
                                       half_width: float) -> float:
    """Scattered power over direct power at the antenna from a lit strip of the facade across
    the street (y = -half_width for a satellite on the right), summed patch by patch:
    S^2 cos(theta_i) dA cos(theta_s) / (pi r^2), by numerical quadrature over the facade."""
    from scipy.integrate import dblquad

    cos_i = abs(u[1])

    def patch(z: float, x: float) -> float:
        r2 = x * x + half_width**2 + z * z
        cos_s = half_width / np.sqrt(r2)
        return S**2 * cos_i * cos_s / (np.pi * r2)

    total = 0.0
    for a, b in ((-np.inf, -50.0), (-50.0, 50.0), (50.0, np.inf)):
        total += dblquad(patch, a, b, low, high, epsabs=1e-12, epsrel=1e-9)[0]
    return total


@pytest.mark.parametrize("az, el", [(90.0, 15.0), (90.0, 25.0), (60.0, 12.0), (-120.0, 20.0)])
def test_scattered_power_is_the_lambertian_integral_over_the_lit_strip(az, el):
    """The closed form (the strip's solid angle) against the patch-by-patch integral, and the
    strip's lower edge against the ray that grazes the roof edge on the satellite's side."""
    u = _u(az, el)
    out = scattered_path(u[None], H, W, S)
    assert out["possible"][0]
    # the shadow line: the ray toward the satellite leaves the near roof edge (height H at the
    # near facade line) and reaches the far facade line (2 (W/2) across) this much lower
    horizontal = np.hypot(u[0], u[1])
    run = W / (abs(u[1]) / horizontal)  # horizontal distance from facade line to facade line
    low = H - run * u[2] / horizontal
    fraction = _lambertian_fraction_by_quadrature(u, max(low, 0.0), H, W / 2)
    assert out["loss_db"][0] == pytest.approx(-10 * np.log10(fraction) + 3.0, abs=1e-6)
    assert lit_strip_solid_angle(W / 2, max(low, 0.0), H) > 0
    # the arrival direction: the strip's middle, straight across
    assert out["arrival_elevation_rad"][0] == pytest.approx(
        np.arctan2(0.5 * (max(low, 0.0) + H), W / 2))


def test_scattered_extra_path_is_the_least_delay_point_of_the_strip():
    u = _u(60.0, 18.0)
    out = scattered_path(u[None], H, W, S)
    low = H - W * np.tan(np.radians(18.0)) / np.sin(np.radians(60.0))
    mid = 0.5 * (low + H)
    x = np.linspace(-200.0, 200.0, 400001)
    point = np.stack([x, np.full_like(x, -W / 2), np.full_like(x, mid)], axis=1)  # left facade
    extra = np.linalg.norm(point, axis=1) - point @ u
    assert out["extra_path_m"][0] == pytest.approx(extra.min(), abs=1e-4)
    assert extra.min() > 0


def test_no_scattering_from_a_facade_the_satellite_cannot_light_or_that_is_not_there():
    # along the street: no light on the side facades; high across: the shadow line falls below
    # the antenna and the whole facade is lit (still a strip); a cross street across the
    # antenna: no facade
    assert not scattered_path(_u(0.0, 20.0)[None], H, W, S)["possible"][0]
    assert scattered_path(_u(90.0, 80.0)[None], H, W, S)["possible"][0]
    street = _buildings([(0.0, 100.0, H)], [(0.0, 40.0, H), (60.0, 100.0, H)])
    assert not scattered_path(_u(90.0, 15.0)[None], H, W, S, 50.0, street)["possible"][0]
    assert scattered_path(_u(90.0, 15.0)[None], H, W, S, 30.0, street)["possible"][0]


def test_scattering_keeps_a_low_satellite_across_the_street_and_never_replaces_line_of_sight():
    def receive(az, el, s):
        gain = lambda e: 46.5 - 28.5 * np.exp(-np.degrees(e) / 17.0)  # noqa: E731 (cn0 model)
        return canyon_reception(np.radians([az]), np.radians([el]), 0.0, H, W, np.inf, np.inf,
                                np.full(4, 15.0), LAMBDA_M, scattering_coefficient=s,
                                antenna_gain_db=gain)

    los, nlos, extra, loss = receive(90.0, 15.0, 0.0)
    assert nlos[0] and loss[0] > 30.0  # deep behind the roof: only heavy diffraction
    los, nlos, extra_s, loss_s = receive(90.0, 15.0, S)
    assert nlos[0] and loss_s[0] < 15.0 and extra_s[0] > 0
    # its C/N0 near the Berlin log's weakest NLOS GPS signals (21-23 dB-Hz)
    cn0 = 46.5 - 28.5 * np.exp(-15.0 / 17.0) - loss_s[0]
    assert 18.0 < cn0 < 28.0
    los, nlos, extra, loss = receive(0.0, 15.0, S)  # along the street: line of sight
    assert los[0] and loss[0] == 0.0 and extra[0] == 0.0
