"""The toolbox blocks the tightly coupled filters' consistency rests on, each against something
independent of itself: the Euler-angle covariance against a Monte Carlo of the attitude
perturbation, the range-error channels against their bookkeeping contract and the closed-form
Gauss-Markov variance, the datasheet reader against a preset's own figures, the row gate
against scipy's chi-square quantile, the re-acquisition's covariance matching against a
position error of known size, the sigma-point measurement prediction against H P H^T."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import chi2

from estimators.toolbox.gating import matching_variance, rows_passing
from estimators.toolbox.kalman import update
from estimators.toolbox.nav_error import euler_covariance, perturb
from estimators.toolbox.range_bias import RangeBiasChannels
from estimators.toolbox.sensor_datasheet import BIAS_INSTABILITY_TIME_S, ImuDatasheet
from estimators.toolbox.ukf import SigmaPointFilter
from simulator.earth import euler_to_quat, quat_to_euler, wrap_angle


def test_euler_covariance_matches_a_monte_carlo_of_small_attitude_errors():
    rng = np.random.default_rng(0)
    euler = np.array([0.1, -0.2, 2.5])
    q = euler_to_quat(*euler)
    a = rng.normal(size=(3, 3))
    p_psi = (a @ a.T) * 1e-6  # rad^2: milliradian errors, where first order holds
    psi = rng.multivariate_normal(np.zeros(3), p_psi, size=4000)
    d = np.array([wrap_angle(np.array(quat_to_euler(perturb(q, np.zeros(3), np.zeros(3),
                                                            np.r_[np.zeros(6), x])[0]))
                             - euler) for x in psi])
    expected = euler_covariance(*euler, p_psi)
    # the sample covariance of 4000 draws: each entry within 5 of its standard errors
    se = np.sqrt((expected**2 + np.outer(np.diag(expected), np.diag(expected))) / 4000)
    assert np.all(np.abs(np.cov(d.T) - expected) < 5 * se)


def test_euler_covariance_of_a_level_car_heading_east_swaps_the_tilt_axes():
    """Heading east, roll is a rotation about east (psi_e), pitch about -north (psi_n)."""
    p = np.diag([1.0, 4.0, 9.0])
    out = euler_covariance(0.0, 0.0, np.pi / 2, p)
    np.testing.assert_allclose(np.diag(out), [4.0, 1.0, 9.0], atol=1e-12)


def test_range_bias_channels_keep_reuse_and_reset():
    ch = RangeBiasChannels(first=5, n=2, correlation_time_s=100.0)
    p = np.eye(7)
    idx, new = ch.assign(np.array([3.0, 7.0]), 0.0, np.array([2.0, 3.0]), p)
    assert list(idx) == [5, 6] and new.all()
    assert p[5, 5] == 4.0 and p[6, 6] == 9.0
    p[5, 0] = p[0, 5] = 0.5
    idx, new = ch.assign(np.array([7.0]), 10.0, np.array([1.0]), p)
    assert list(idx) == [6] and not new.any() and p[6, 6] == 9.0  # kept, not reset
    # satellite 3 is the one seen longest ago: a new satellite takes its channel, reset
    idx, new = ch.assign(np.array([7.0, 12.0]), 20.0, np.array([1.0, 0.5]), p)
    assert list(idx) == [6, 5] and list(new) == [False, True]
    assert p[5, 5] == 0.25 and p[5, 0] == 0.0 and p[0, 5] == 0.0
    # no free channel left: the third satellite is left out
    idx, _ = ch.assign(np.array([7.0, 12.0, 20.0]), 30.0, np.ones(3), p)
    assert list(idx) == [6, 5, -1]
    phi, q = ch.transition(10.0)
    np.testing.assert_allclose(phi, np.exp(-0.1))
    # stationary: phi^2 sigma^2 + q = sigma^2
    np.testing.assert_allclose(phi**2 * ch.sigma**2 + q, ch.sigma**2)


def test_imu_datasheet_reads_the_largest_axis_and_the_bias_walk():
    sheet = ImuDatasheet.from_datasheet({"imu": {
        "gyro": {"noise_density": [1e-4, 3e-4, 2e-4], "bias": 0.01, "bias_instability": 5e-5,
                 "random_walk": 2e-6, "scale_factor": 0.005, "misalignment": 0.001},
        "accel": {"noise_density": 2e-3, "bias": 0.1}}})
    assert sheet.gyro.noise_density == 3e-4 and sheet.accel.bias == 0.1
    assert sheet.accel.scale_factor == 0.0  # absent: zero
    np.testing.assert_allclose(sheet.gyro.bias_walk**2,
                               2e-6**2 + 5e-5**2 / BIAS_INSTABILITY_TIME_S)
    assert ImuDatasheet.from_datasheet({}) is None


def test_rows_passing_is_the_chi_square_quantile_of_one_dof():
    limit = chi2.ppf(0.999, 1)
    s = np.array([4.0, 4.0, 1.0])
    nu = np.sqrt(limit * s) * np.array([0.99, 1.01, 1.0 - 1e-9])
    assert list(rows_passing(nu, s, 0.999)) == [True, False, True]


def test_matching_variance_lets_a_filter_off_by_a_known_error_take_its_ranges_back():
    """A filter whose position is 40 m off while its covariance says 1 m (what a lock-out after
    an outage looks like): every range fails the gate; with the matched variance added to the
    position and clock states the consistent ranges pass, a 300 m NLOS range still fails, and
    one update with the passing ranges removes most of the 40 m."""
    rng = np.random.default_rng(3)
    los = rng.normal(size=(7, 3))
    los[:, 2] = np.abs(los[:, 2]) + 0.3  # satellites above the horizon (north, east, up)
    los /= np.linalg.norm(los, axis=1)[:, None]
    h = np.hstack([los, np.ones((7, 1))])  # d range / d (north, east, up, clock)
    error = np.array([40.0, -10.0, 15.0, 0.0])  # estimate minus truth, m
    r_var = np.full(7, 1.5**2)
    nu = h @ error + rng.normal(0.0, 1.5, 7)  # predicted minus measured range
    nu[6] += 300.0  # one NLOS range
    p = np.eye(4)
    s_diag = np.einsum("ij,jk,ik->i", h, p, h) + r_var
    assert not rows_passing(nu, s_diag).any()
    q = matching_variance(nu, s_diag)
    assert q == pytest.approx(np.median(nu**2 - s_diag))
    p_grown = p + 0.5 * q * np.eye(4)  # each row: unit line of sight and a 1 on the clock
    s_grown = np.einsum("ij,jk,ik->i", h, p_grown, h) + r_var
    np.testing.assert_allclose(s_grown, s_diag + q)
    passing = rows_passing(nu, s_grown)
    assert passing[:6].sum() >= 4 and not passing[6]
    x, _, _ = update(np.zeros(4), p_grown, nu[passing], h[passing], np.diag(r_var[passing]))
    assert np.linalg.norm((error - x)[:3]) < 0.25 * np.linalg.norm(error[:3])
    assert matching_variance(np.zeros(3), np.ones(3)) == 0.0  # a consistent filter: nothing


def test_predicted_measurement_of_a_linear_model_is_h_x_and_h_p_h():
    x0 = np.array([1.0, -2.0, 0.5])
    a = np.random.default_rng(1).normal(size=(3, 3))
    p0 = a @ a.T + np.eye(3)
    ukf = SigmaPointFilter(x0, p0, points="symmetric", alpha=0.5, beta=2.0)
    h = np.array([[1.0, 2.0, 0.0], [0.0, -1.0, 3.0]])
    z_hat, p_zz = ukf.predict_measurement(lambda pts: pts @ h.T)
    np.testing.assert_allclose(z_hat, h @ x0, atol=1e-12)
    np.testing.assert_allclose(p_zz, h @ p0 @ h.T, atol=1e-9)
