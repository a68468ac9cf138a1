"""The compiled blocks of estimators.toolbox.strapdown for filters' inner loops against the
vectorised reference maths of simulator.earth."""

from __future__ import annotations

import numpy as np

from estimators.toolbox.strapdown import attitude_step, frame_rates, radii
from simulator.earth import (
    earth_rate_ned,
    euler_to_quat,
    quat_multiply,
    quat_to_dcm,
    radii_of_curvature,
    rotvec_to_quat,
    transport_rate_ned,
)


def test_attitude_step_is_the_quaternion_product():
    q = euler_to_quat(0.1, -0.2, 2.5)
    rot_nav = np.array([1e-3, -2e-3, 5e-4])
    rot_body = np.array([0.02, -0.01, 0.3])
    expected = quat_multiply(quat_multiply(rotvec_to_quat(-rot_nav), q), rotvec_to_quat(rot_body))
    q_new, c_new = attitude_step(q, rot_nav, rot_body)
    np.testing.assert_allclose(q_new, expected, atol=1e-15)
    np.testing.assert_allclose(c_new, quat_to_dcm(expected), atol=1e-15)
    assert abs(np.linalg.norm(q_new) - 1.0) < 1e-15


def test_frame_rates_and_radii_match_the_earth_module():
    lat, h, v = 0.65, 120.0, np.array([12.0, -7.0, 0.5])
    w_ie, w_en = frame_rates(lat, h, v)
    np.testing.assert_allclose(w_ie, earth_rate_ned(lat)[0], rtol=1e-14, atol=1e-20)
    np.testing.assert_allclose(w_en, transport_rate_ned(lat, h, v)[0], rtol=1e-14)
    np.testing.assert_allclose(radii(lat), [float(r) for r in radii_of_curvature(lat)],
                               rtol=1e-14)
