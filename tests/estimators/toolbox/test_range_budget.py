"""``toolbox.range_budget``: the split of a pseudorange's reported variance adds up to it, and
the ionosphere field the split implies (its shared quantities' coefficients and each
satellite's remainder) is, where the position takes it, the field the receiver's own model
describes (``simulator.datasheet.iono_field_covariance``: the squared-exponential over the
chords between the pierce points, computed without the zenith pierce point's value and
gradient)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from estimators.toolbox.range_budget import RangeBudget, range_budget
from simulator.datasheet import iono_field_covariance

BUDGET = RangeBudget(iono_common=0.5, iono_field=0.3, sis=0.5, tropo_zenith=0.05,
                     inflation=14.0)


def _sky(seed: int, m: int = 8) -> SimpleNamespace:
    """An epoch of m satellites above 15 deg, midday broadcast delays, the reported 1-sigma of
    every part of the budget and 0.3 m of smoothed code noise."""
    rng = np.random.default_rng(seed)
    el = rng.uniform(np.radians(15.0), np.radians(85.0), m)
    az = rng.uniform(0.0, 2.0 * np.pi, m)
    delay = 4.0 / np.sin(el + 0.2)
    reported = np.sqrt(BUDGET.sis**2 + ((BUDGET.iono_common**2 + BUDGET.iono_field**2)
                                        * delay**2) + (BUDGET.tropo_zenith / np.sin(el)) ** 2
                       + 0.3**2)
    return SimpleNamespace(sv=np.arange(m), iono=delay, elevation=el, azimuth=az,
                           pseudorange_std=reported)


def test_the_parts_add_up_to_the_reported_variance():
    ep = _sky(1)
    shared, own, white = BUDGET.sigmas(ep)
    total = np.sum(shared**2, axis=0) + own**2 + (white / BUDGET.inflation) ** 2
    np.testing.assert_allclose(total, ep.pseudorange_std**2, rtol=1e-12)
    np.testing.assert_allclose(white / BUDGET.inflation, 0.3, rtol=1e-12)
    # the common part's coefficient is |iono_scale - 1| of each broadcast delay
    np.testing.assert_allclose(shared[0], BUDGET.iono_common * ep.iono, rtol=1e-12)


def test_the_field_in_the_position_is_the_receivers_model():
    """Over 100 random skies, the least-squares position's variance (north, east, down; the
    clock estimated too) from the field as the budget splits it against the chord-based
    covariance: the same variance per satellite, and the median ratio of the position's
    variances within 15 % on every axis (measured 1.02, 1.03 and 0.90 over 200 skies; the
    split keeps the field's value and gradient at one point, so a single sky with pierce
    points far apart is off by more: 5-95 % of skies 0.97-1.24 horizontally, 0.69-1.08 in
    height)."""
    ratios = []
    for seed in range(1, 101):
        ep = _sky(seed)
        shared, own, _ = BUDGET.sigmas(ep)
        tropo2 = (BUDGET.tropo_zenith / np.sin(ep.elevation)) ** 2
        split = shared[1:].T @ shared[1:] + np.diag(own**2 - BUDGET.sis**2 - tropo2)
        model = iono_field_covariance(BUDGET.iono_field, ep.iono, ep.azimuth, ep.elevation)
        np.testing.assert_allclose(np.diag(split), np.diag(model), rtol=1e-9)
        los = np.column_stack([np.cos(ep.elevation) * np.cos(ep.azimuth),
                               np.cos(ep.elevation) * np.sin(ep.azimuth),
                               -np.sin(ep.elevation), np.ones(len(ep.sv))])
        solve = np.linalg.solve(los.T @ los, los.T)
        ratios.append(np.diag(solve @ split @ solve.T)[:3]
                      / np.diag(solve @ model @ solve.T)[:3])
    median = np.median(ratios, axis=0)
    assert np.all(np.abs(median - 1.0) < 0.15), median


def test_a_silent_datasheet_leaves_the_reported_variance_white():
    budget = range_budget({})
    assert not budget.shared_in_use().any()
    assert budget.inflation == 1.0
