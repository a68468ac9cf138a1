"""The receiver's least-squares fix where the equations cannot determine a position: an epoch
whose normal equations are singular although it has four satellites (the urban canyon's
four-NLOS epochs can drive the iteration far from the Earth, where every satellite lies in one
direction) is reported without a fix, and the other epochs are solved as before."""

from __future__ import annotations

import numpy as np

from simulator.earth import geodetic_to_ecef
from simulator.gnss.constants import C_M_S
from simulator.gnss.fix import solve_position
from simulator.gnss.receiver import rotate_to_reception_frame


def test_a_singular_epoch_gets_no_fix_and_the_others_are_solved():
    antenna = geodetic_to_ecef(np.radians(52.5), np.radians(13.4), 75.0)
    # four satellites at 20 000 km in well-spread directions, then the same four stacked
    # in one place (a rank-one geometry: the position is undetermined)
    dirs = np.array([[1.0, 0.0, 0.3], [0.0, 1.0, 0.4], [-0.7, -0.7, 0.5], [0.1, -0.2, 1.0]])
    up = antenna / np.linalg.norm(antenna)
    east = np.cross([0.0, 0.0, 1.0], up)
    east /= np.linalg.norm(east)
    north = np.cross(up, east)
    los = dirs @ np.stack([east, north, up])
    los /= np.linalg.norm(los, axis=1, keepdims=True)
    good = antenna + 2.0e7 * los
    sats = np.stack([good, np.repeat(good[:1], 4, axis=0)])
    clock_m = 1234.5
    # the ranges with the Earth's rotation during the flight (the solver's model, Groves 8.36)
    tau = np.linalg.norm(sats - antenna, axis=-1) / C_M_S
    for _ in range(3):
        tau = np.linalg.norm(rotate_to_reception_frame(sats, tau) - antenna, axis=-1) / C_M_S
    pr = C_M_S * tau + clock_m
    mask = np.ones((2, 4), dtype=bool)
    pos, clock, ok = solve_position(pr, sats, np.ones((2, 4)), mask)
    assert ok.tolist() == [True, False]
    assert np.isnan(pos[1]).all() and np.isnan(clock[1])
    assert np.linalg.norm(pos[0] - antenna) < 1e-3 and abs(clock[0] - clock_m) < 1e-3
