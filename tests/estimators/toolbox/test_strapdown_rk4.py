"""The total-state RK4 navigation kernel (Chan et al. eqs. 1-3) against the exact kinematics of a
simulated drive: integrating the true body rates and specific forces must follow the true
trajectory, as the increment mechanisation ``run_strapdown`` does."""

from __future__ import annotations

import numpy as np

from estimators.toolbox.strapdown import nav_derivative, rk4_step, run_strapdown
from simulator.earth import euler_to_quat, quat_to_euler, radii_of_curvature, wrap_angle
from tests.gnss_helpers import drive

DRIVE = [{"stop": {"duration": 2}}, {"accelerate": {"to_speed": 15, "accel": 2.0}},
         {"turn": {"angle": 120, "radius": 40}}, {"slope": {"grade": 0.06, "length": 200}},
         {"turn": {"angle": -90, "radius": 60}}, {"straight": {"length": 200}}]


def test_rk4_follows_the_exact_kinematics():
    truth = drive(DRIVE)
    t = np.arange(0.0, truth.duration_s, 0.01)
    k = truth.inertial(t)
    x = np.concatenate([[k["lat"][0], k["lon"][0], k["alt"][0]], k["v_ned"][0],
                        euler_to_quat(k["roll"][0], k["pitch"][0], k["yaw"][0])])
    work = np.empty((5, 10))
    w, f = k["w_body"], k["f_body"]
    for j in range(len(t) - 1):
        rk4_step(x, w[j], 0.5 * (w[j] + w[j + 1]), w[j + 1], f[j], 0.5 * (f[j] + f[j + 1]),
                 f[j + 1], t[j + 1] - t[j], work)
    rn, re = radii_of_curvature(k["lat"][-1])
    d_north = (x[0] - k["lat"][-1]) * rn
    d_east = (x[1] - k["lon"][-1]) * re * np.cos(k["lat"][-1])
    assert np.hypot(d_north, d_east) < 0.5
    assert abs(x[2] - k["alt"][-1]) < 0.5
    assert np.abs(x[3:6] - k["v_ned"][-1]).max() < 0.02
    att = np.array(quat_to_euler(x[6:10]))
    true_att = np.array([k["roll"][-1], k["pitch"][-1], k["yaw"][-1]])
    assert np.abs(wrap_angle(att - true_att)).max() < 1e-3
    # as close as the increment mechanisation of the toolbox
    dth = 0.5 * (w[1:] + w[:-1]) * 0.01
    dv = 0.5 * (f[1:] + f[:-1]) * 0.01
    _, v_sd, pos_sd = run_strapdown(euler_to_quat(k["roll"][0], k["pitch"][0], k["yaw"][0]),
                                    k["v_ned"][0],
                                    np.array([k["lat"][0], k["lon"][0], k["alt"][0]]), dth, dv,
                                    0.01)
    assert np.abs(x[3:6] - v_sd[-1]).max() < 0.05
    assert abs(x[0] - pos_sd[-1, 0]) * rn < 0.5


def test_derivative_at_rest_is_gravity_and_earth_rate():
    """A body at rest, level and facing north: v' = 0 (the accelerometer reads -g up and the
    Coriolis term vanishes), and the gyro reading w_ie^b gives q' = 0."""
    lat = np.radians(45.0)
    from simulator.earth import OMEGA_E_RAD_S, normal_gravity

    g = float(normal_gravity(lat, 100.0))
    x = np.array([lat, 0.3, 100.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    w = OMEGA_E_RAD_S * np.array([np.cos(lat), 0.0, -np.sin(lat)])
    out = np.empty(10)
    nav_derivative(x, w, np.array([0.0, 0.0, -g]), out)
    np.testing.assert_allclose(out, 0.0, atol=1e-12)
