"""The double-difference bookkeeping (``estimators.toolbox.double_difference``) against its
definitions written out by hand, and the block-diagonal Kalman prediction against the full one."""

from __future__ import annotations

import numpy as np
from scipy.linalg import block_diag

from estimators.toolbox import double_difference as ddiff
from estimators.toolbox.kalman import predict, predict_blocks


def test_keys_group_signals_by_system_and_band():
    keys = ddiff.signal_keys([71, 71, 69, 71], [5, 5, 5, 12], [1575.42e6, 1227.6e6, 1575.42e6,
                                                                1575.42e6])
    assert len(set(keys.tolist())) == 4  # same satellite number, other system or band
    groups = ddiff.group_of(keys)
    assert groups[0] == groups[3] and groups[0] != groups[1] and groups[0] != groups[2]


def test_reference_is_the_highest_of_the_highest_priority():
    groups = np.array([1, 1, 1, 2, 2])
    elevation = np.array([0.3, 1.2, 0.8, 0.5, 0.4])
    assert ddiff.references(groups, elevation).tolist() == [1, 1, 1, 3, 3]
    priority = np.array([2, 1, 2, 0, 1])
    assert ddiff.references(groups, elevation, priority).tolist() == [2, 2, 2, 4, 4]


def test_references_match_a_search_of_each_group():
    """Random epochs (ties of elevation and priority included): each signal's reference is
    the first signal of its group with the highest priority and, of those, elevation."""
    rng = np.random.default_rng(3)
    for _ in range(200):
        m = int(rng.integers(1, 30))
        groups = rng.integers(0, 5, m) * 10_000 + 1575
        elevation = rng.choice([0.3, 0.5, 0.9, 1.2], m)
        priority = rng.integers(1, 3, m)
        expected = np.empty(m, dtype=int)
        for i in range(m):
            members = [j for j in range(m) if groups[j] == groups[i]]
            best = max(members, key=lambda j: (priority[j], elevation[j], -j))
            expected[i] = best
        assert ddiff.references(groups, elevation, priority).tolist() == expected.tolist()


def test_double_differences_and_their_covariance_match_the_hand_written_ones():
    ref = np.array([1, 1, 1, 3, 3])  # two groups: references 1 and 3
    d, rows = ddiff.difference_matrix(ref)
    assert rows.tolist() == [0, 2, 4]
    sd = np.array([10.0, 3.0, 7.0, 1.0, 4.0])
    assert np.allclose(d @ sd, [10.0 - 3.0, 7.0 - 3.0, 4.0 - 1.0])
    s = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    expected = np.array([[1 + 2, 2, 0], [2, 3 + 2, 0], [0, 0, 5 + 4]], dtype=float)
    assert np.allclose(ddiff.double_difference_covariance(d, s), expected)
    # and as the sample covariance of simulated independent single differences
    rng = np.random.default_rng(1)
    draws = rng.normal(size=(200_000, 5)) * np.sqrt(s)
    sample = np.cov((draws @ d.T).T)
    assert np.allclose(sample, expected, atol=0.05 * expected.max())


def test_block_prediction_equals_the_full_one():
    rng = np.random.default_rng(2)
    a, b = 6, 5
    n = a + b
    m = rng.normal(size=(n, n))
    p = m @ m.T
    x = rng.normal(size=n)
    phi_a = np.eye(a) + 0.1 * rng.normal(size=(a, a))
    q_a = np.diag(rng.uniform(0.1, 1.0, a))
    phi_b = rng.uniform(0.5, 1.0, b)
    q_b = rng.uniform(0.0, 0.2, b)
    phi = block_diag(phi_a, np.diag(phi_b))
    q = block_diag(q_a, np.diag(q_b))
    x_full, p_full = predict(x, p, phi, q)
    x_block, p_block = predict_blocks(x, p, phi_a, q_a, phi_b, q_b)
    assert np.allclose(x_block, x_full, rtol=1e-12, atol=1e-12)
    assert np.allclose(p_block, p_full, rtol=1e-12, atol=1e-12)
