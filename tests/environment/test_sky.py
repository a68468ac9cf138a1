"""The street-canyon sky against hand-solvable geometry: a satellite along the street is in line
of sight, one across the street below the facades' angle is blocked or reflected, a reflection's
extra path is the image-antenna distance (one and two side facades, the end facade), diffraction
over a roof edge follows the knife-edge loss of ITU-R P.526."""

from __future__ import annotations

import numpy as np
import pytest

from simulator.environment.sky import canyon_reception, knife_edge_loss_db, trace_paths

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
