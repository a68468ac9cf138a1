"""The sigma-point filter driver against independent references: the linear Kalman filter it
must equal on a linear-Gaussian model (both point sets, additive and augmented noise, singular
Q and P), the exact moments of x^2 of a Gaussian, FilterPy's UnscentedKalmanFilter on a
nonlinear range-bearing problem, wrapped angles near +-180 deg, and a quaternion carried as a
rotation-vector error."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.toolbox.kalman import predict as kf_predict
from estimators.toolbox.kalman import update as kf_update
from estimators.toolbox.ukf import SigmaPointFilter, angle_hooks, psd_sqrt, quaternion_hooks
from simulator.earth import euler_to_quat, quat_multiply, quat_to_dcm

DT = 0.1
PHI = np.array([[1.0, DT, 0.5 * DT**2], [0.0, 1.0, DT], [0.0, 0.0, 1.0]])
G = np.array([[0.0], [0.0], [1.0]])  # noise drives the last state only: Q is singular
Q = G @ G.T * 0.3**2
H = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
R = np.diag([2.0**2, 0.5**2])
X0 = np.array([1.0, 2.0, -0.5])
P0 = np.diag([10.0, 4.0, 1.0])

SETS = {
    "symmetric": {"points": "symmetric", "alpha": 0.99, "beta": 2.0},
    "simplex": {"points": "simplex", "alpha": 1.0, "beta": 2.0, "w0": 0.0},
    "simplex scaled": {"points": "simplex", "alpha": 0.3, "beta": 2.0, "w0": 0.4},
}


def _linear(xs: np.ndarray, ws: np.ndarray | None) -> np.ndarray:
    out = xs @ PHI.T
    return out if ws is None else out + ws


def _measure(xs: np.ndarray) -> np.ndarray:
    return xs @ H.T


@pytest.mark.parametrize("augment", [False, True], ids=["additive Q", "augmented Q"])
@pytest.mark.parametrize("options", SETS.values(), ids=SETS.keys())
def test_equals_the_kalman_filter_on_a_linear_gaussian_model(options, augment):
    rng = np.random.default_rng(1)
    ukf = SigmaPointFilter(X0, P0, augment=augment, **options)
    x, p = X0.copy(), P0.copy()
    for k in range(30):
        ukf.predict(_linear, q=Q)
        x, p = kf_predict(x, p, PHI, Q)
        if k % 5 == 4:
            z = H @ x + rng.normal(size=2)
            ukf.update(_measure, z, R)
            x, p, _ = kf_update(x, p, z - H @ x, H, R)
        np.testing.assert_allclose(ukf.x, x, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(ukf.p, p, rtol=1e-8, atol=1e-10)


def test_several_propagations_between_draws_give_the_interval_transition():
    """Cho & Choi propagate the points at 10 Hz and form P at the 1 Hz epochs (after eq. 25):
    ten noise-free steps then eq. 26 must give Phi^10 P Phi^10^T."""
    ukf = SigmaPointFilter(X0, P0, points="simplex")
    for _ in range(10):
        ukf.propagate(_linear)
    ukf.covariance()
    phi10 = np.linalg.matrix_power(PHI, 10)
    np.testing.assert_allclose(ukf.x, phi10 @ X0, rtol=1e-12)
    np.testing.assert_allclose(ukf.p, phi10 @ P0 @ phi10.T, rtol=1e-9)


@pytest.mark.parametrize("options", SETS.values(), ids=SETS.keys())
def test_augmented_noise_spread_over_an_interval_adds_q_once(options):
    """Noise held per point over ten steps, w dt / T each step, adds exactly Q over the
    interval T for an identity transition (the only non-zero Q term is augmented)."""
    def hold(xs, ws):
        return xs + 0.1 * ws

    ukf = SigmaPointFilter(X0, P0, augment=True, **options)
    for _ in range(10):
        ukf.propagate(hold, q=Q)
    ukf.covariance()
    np.testing.assert_allclose(ukf.p, P0 + Q, rtol=1e-9, atol=1e-12)


def test_x_squared_matches_the_exact_gaussian_moments():
    """y = x^2, x ~ N(mu, s^2): E y = mu^2 + s^2, var y = 4 mu^2 s^2 + 2 s^4; the symmetric
    set with n + kappa = 3 and beta = 0 carries the fourth moment, so both are exact."""
    mu, s = 1.5, 0.7
    ukf = SigmaPointFilter([mu], [[s**2]], points="symmetric", alpha=1.0, beta=0.0, kappa=2.0)
    ukf.propagate(lambda xs, ws: xs**2)
    ukf.covariance()
    assert ukf.x[0] == pytest.approx(mu**2 + s**2, rel=1e-12)
    assert ukf.p[0, 0] == pytest.approx(4 * mu**2 * s**2 + 2 * s**4, rel=1e-12)


def test_matches_filterpy_on_a_nonlinear_range_bearing_problem():
    filterpy = pytest.importorskip("filterpy.kalman", reason="filterpy is in the bench extra")
    station = np.array([30.0, -20.0])
    q = np.diag([0.01, 0.01, 0.04, 0.04])
    r = np.diag([0.5**2, np.radians(1.0) ** 2])
    phi = np.eye(4)
    phi[0, 2] = phi[1, 3] = 1.0

    def fx_one(x, dt):
        return phi @ x

    def hx_one(x):
        d = x[:2] - station
        return np.array([np.hypot(*d), np.arctan2(d[1], d[0])])

    def hx(xs):
        d = xs[:, :2] - station
        return np.column_stack([np.hypot(d[:, 0], d[:, 1]), np.arctan2(d[:, 1], d[:, 0])])

    points = filterpy.MerweScaledSigmaPoints(4, alpha=0.5, beta=2.0, kappa=0.0)
    ref = filterpy.UnscentedKalmanFilter(4, 2, 1.0, hx_one, fx_one, points)
    ref.x = np.array([0.0, 0.0, 1.0, 0.5])
    ref.P = np.diag([25.0, 25.0, 1.0, 1.0])
    ref.Q, ref.R = q, r
    ukf = SigmaPointFilter(ref.x, ref.P, points="symmetric", alpha=0.5, beta=2.0)
    rng = np.random.default_rng(3)
    truth = np.array([1.0, -2.0, 1.2, 0.4])
    for _ in range(20):
        truth = phi @ truth
        z = hx_one(truth) + rng.normal(size=2) * np.sqrt(np.diag(r))
        ref.predict()
        ref.update(z)
        ukf.predict(lambda xs, ws: xs @ phi.T, q=q)
        ukf.update(hx, z, r)
        np.testing.assert_allclose(ukf.x, ref.x, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(ukf.p, ref.P, rtol=1e-8, atol=1e-10)


def test_singular_and_indefinite_covariances_still_give_points():
    singular = np.diag([4.0, 0.0, 1.0])
    root = psd_sqrt(singular)
    np.testing.assert_allclose(root @ root.T, singular, atol=1e-9)
    indefinite = np.array([[1.0, 1.0], [1.0, 1.0 - 1e-9]])  # lost definiteness to rounding
    root = psd_sqrt(indefinite)
    assert np.all(np.isfinite(root))
    np.testing.assert_allclose(root @ root.T, indefinite, atol=1e-8)
    # a filter started from a state known exactly in one component equals the KF
    ukf = SigmaPointFilter(X0, singular, points="simplex", augment=True)
    x, p = X0.copy(), singular.copy()
    for _ in range(5):
        ukf.predict(_linear, q=Q)
        x, p = kf_predict(x, p, PHI, Q)
    z = np.array([1.5, 1.0])
    ukf.update(_measure, z, R)
    x, p, _ = kf_update(x, p, z - H @ x, H, R)
    np.testing.assert_allclose(ukf.x, x, atol=1e-6)
    np.testing.assert_allclose(ukf.p, p, atol=1e-6)


def test_wrapped_angles_average_and_update_across_plus_minus_180_deg():
    plus, minus = angle_hooks([1])
    sigma = np.radians(5.0)
    ukf = SigmaPointFilter([0.0, np.radians(178.0)], np.diag([1.0, sigma**2]),
                           points="simplex", boxplus=plus, boxminus=minus)
    ukf.propagate(lambda xs, ws: plus(xs, np.array([0.0, np.radians(2.5)])))
    ukf.covariance()
    # the mean is -179.5 deg, not the arithmetic mean of points on both sides of the cut
    assert np.degrees(ukf.x[1]) == pytest.approx(-179.5, abs=1e-9)
    assert ukf.p[1, 1] == pytest.approx(sigma**2, rel=1e-9)

    def heading(xs):
        return xs[:, 1:2]

    def residual(zs, z):
        return minus(np.column_stack([np.zeros(len(zs)), zs[:, 0]]),
                     np.array([0.0, z[0]]))[:, 1:]

    # a heading measurement of +179.5 deg pulls the estimate across the cut, halfway
    ukf.update(heading, np.array([np.radians(179.5)]), np.array([[sigma**2]]),
               z_residual=residual)
    assert abs(np.degrees(ukf.x[1])) == pytest.approx(180.0, abs=1e-9)
    assert ukf.p[1, 1] == pytest.approx(0.5 * sigma**2, rel=1e-9)


def test_update_needs_the_covariance_of_propagated_points():
    ukf = SigmaPointFilter(X0, P0)
    ukf.propagate(_linear)
    with pytest.raises(RuntimeError, match="covariance"):
        ukf.update(_measure, np.zeros(2), R)


@pytest.mark.parametrize("points", ["symmetric", "simplex"])
def test_quaternion_attitude_carried_as_a_rotation_error(points):
    """State [q (4), b]: right-multiplying every point by a fixed rotation r turns the mean
    into q r and the body-frame rotation error e into C_r^T e, so P_rot -> C_r^T P_rot C_r
    exactly (the map is linear in the rotation vector); b is untouched."""
    plus, minus = quaternion_hooks(0)
    q0 = euler_to_quat(0.3, -0.2, 2.9)
    r = euler_to_quat(0.1, 0.4, -1.2)
    a = np.random.default_rng(2).normal(size=(4, 4)) * 0.05
    p0 = a @ a.T + np.diag([1e-3, 2e-3, 3e-3, 0.5])
    ukf = SigmaPointFilter(np.append(q0, 7.0), p0, points=points, boxplus=plus, boxminus=minus)
    assert ukf.draw().shape[1] == 5
    ukf.propagate(lambda xs, ws: np.column_stack([quat_multiply(xs[:, :4], r), xs[:, 4]]))
    ukf.covariance()
    expected_q = quat_multiply(q0, r)
    assert abs(float(ukf.x[:4] @ expected_q)) == pytest.approx(1.0, abs=1e-12)
    rot = quat_to_dcm(r)
    expected = p0.copy()
    expected[:3, :3] = rot.T @ p0[:3, :3] @ rot
    expected[:3, 3] = rot.T @ p0[:3, 3]
    expected[3, :3] = expected[:3, 3]
    np.testing.assert_allclose(ukf.p, expected, atol=1e-10)
    assert ukf.x[4] == pytest.approx(7.0)
