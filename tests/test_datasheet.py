"""The one receiver error budget (``simulator.datasheet``) against what it is read from: the
ionosphere fractions against the receiver simulation's own reported pseudorange variance, the
budget of the ``automotive`` preset against its terms worked by hand, the consumers (the
filters' fix model, the exported UERE) against the budget, and the filters' split of a fix's
reported accuracy (``FixSplit``) against its terms worked by hand."""

from __future__ import annotations

import math

import numpy as np

from estimators.toolbox.datasheet import (
    MIN_DRIVE_LONG_SIGMA_M,
    NLOS_WHITE_SHARE,
    FixSplit,
    fix_error_model,
)
from simulator.datasheet import (
    KLOBUCHAR_NIGHT_SLANT_M,
    fix_uere_m,
    iono_residual_fractions,
    range_error_budget,
)
from simulator.gnss.errors import pseudorange_sigma
from simulator.sensors.gnss import PRESETS

AUTOMOTIVE = PRESETS["automotive"]


def test_iono_fractions_are_the_simulation_reported_ionosphere_variance():
    """With every other term zero, the simulated receiver reports sigma = sqrt(common^2 +
    field^2) x the broadcast delay (simulator.gnss.errors.pseudorange_sigma)."""
    common, field = iono_residual_fractions(AUTOMOTIVE)
    assert (common, field) == (0.5, 1.5 * 0.2)
    cfg = {**AUTOMOTIVE, "tropo_residual": 0.0, "sis_error": 0.0, "carrier_smoothing": 0.0,
           "dll_bandwidth": 1.0, "multipath_distance": 10.0, "multipath_correlation_time": 1.0}
    zeros = np.zeros((2, 3))
    terms = {"code_sigma": zeros, "multipath_sigma": zeros, "rate_sigma": zeros + 0.05}
    iono = np.array([[4.0, 6.0, 9.0], [3.0, 5.0, 8.0]])
    sigma, _ = pseudorange_sigma(cfg, terms, iono, np.ones((2, 3)), 1.0, np.ones(3))
    np.testing.assert_allclose(sigma, math.hypot(common, field) * iono, rtol=1e-12)


def test_automotive_budget_worked_by_hand():
    b = range_error_budget(AUTOMOTIVE)
    assert b.sis == 0.5
    # the Klobuchar night floor, 5 ns x c = 1.4990 m, at the 30 deg obliquity 1.77
    assert math.isclose(KLOBUCHAR_NIGHT_SLANT_M, 2.6532, rel_tol=1e-4)
    assert math.isclose(b.ionosphere, 0.8 * 2.6532, rel_tol=1e-4)
    assert math.isclose(b.troposphere, 0.05 * 2.0)
    # code noise 1 m after a 100-epoch Hatch filter, 1 / sqrt(199), and 0.3 m multipath
    assert math.isclose(b.smoothed, math.hypot(1.0 / math.sqrt(199.0), 0.3))
    assert math.isclose(b.correlated_m(), math.sqrt(0.25 + (0.8 * 2.6532) ** 2 + 0.01),
                        rel_tol=1e-4)
    assert math.isclose(b.correlated_m(ionosphere=False), math.sqrt(0.26))


def test_consumers_read_the_one_budget():
    b = range_error_budget(AUTOMOTIVE)
    model = fix_error_model({"gnss": AUTOMOTIVE})
    assert model.correlated_range == b.correlated_m()
    # the smoothed error's white equivalent at 1 Hz: sigma sqrt(2 T / dt), T = 100 s
    assert math.isclose(model.white_range, b.smoothed * math.sqrt(200.0))
    assert fix_uere_m(AUTOMOTIVE) == math.hypot(b.correlated_m(), b.smoothed)


def test_an_ideal_receiver_has_no_error_and_the_filters_keep_a_floor():
    ideal = PRESETS["ideal"]
    assert fix_uere_m(ideal) == 0.0
    assert iono_residual_fractions({}) == (0.0, 0.0)
    model = fix_error_model({"gnss": ideal})
    assert model.correlated_range == 0.1 and model.white_range == 0.1


def test_fix_split_takes_the_smallest_report_as_the_drive_long_part():
    """Per horizontal axis and unit DOP (HDOP / sqrt(2)): the drive-long part is the smallest
    report so far less the smoothed part, at most the budget's correlated range; down (VDOP)
    it is the budget's; its 1-sigma is taken at the first fix's DOPs. What a report holds
    beyond the part and the smoothed noise at its own DOPs is the reflected excess, split
    into the states' gain and the white share; an axis without a report keeps its part and
    has no excess."""
    model = fix_error_model({"gnss": AUTOMOTIVE})
    c, s = model.correlated_range, model.smoothed_range
    split = FixSplit(model)
    hdop, vdop = math.sqrt(2.0), 2.0  # unit DOP per horizontal axis, 2 down
    axes = np.array([1.0, 1.0, 2.0])
    white = model.white_sigma(hdop, vdop) ** 2

    def check(report, dops, part):
        gain, nlos, noise = split.split(report, *dops)
        scale = np.array([dops[0] / math.sqrt(2.0)] * 2 + [dops[1]])
        np.testing.assert_allclose(gain, part * axes)  # the first fix's DOPs
        excess2 = np.where(np.isfinite(report), np.maximum(
            np.nan_to_num(report) ** 2 - (part**2 + s**2) * scale**2, 0.0), 0.0)
        np.testing.assert_allclose(nlos**2, (1 - NLOS_WHITE_SHARE) * excess2, atol=1e-12)
        np.testing.assert_allclose(noise, model.white_sigma(*dops) ** 2
                                   + NLOS_WHITE_SHARE * excess2)
        return excess2

    # a first fix above the budget (the carrier smoothing not yet converged): the budget's
    # part, the rest excess
    excess2 = check(np.array([4.0, 4.0, 9.0]), (hdop, vdop), np.full(3, c))
    np.testing.assert_allclose(excess2, np.array([16.0, 16.0, 81.0]) - (c**2 + s**2) * axes**2)
    # a clean open-sky report below the budget: north and east its part beyond the smoothed
    # noise, no excess; down the budget's part, its report within it
    clean = np.array([1.5, 1.2, 3.0])
    part = np.r_[np.sqrt(clean[:2] ** 2 - s**2), c]
    excess2 = check(clean, (hdop, vdop), part)
    np.testing.assert_allclose(excess2, 0.0, atol=1e-12)
    assert np.allclose(split.split(clean, hdop, vdop)[2], white)
    # a report that rises again (a faded signal) is excess over the part, which stays; the
    # down axis unreported keeps its part; at twice the DOPs the excess is over twice the
    # part's 1-sigma, the states' size stays
    excess2 = check(np.array([4.0, 3.0, np.nan]), (2.0 * hdop, 2.0 * vdop), part)
    assert (excess2[:2] > 0).all() and excess2[2] == 0.0


def test_the_reported_drive_long_sigma_splits_the_report_without_loss():
    """A fix's reported 1-sigma per axis is split into the drive-long part, the budget's
    smoothed part and the excess beyond the budget (reflections), in quadrature: below the
    budget the drive-long part is the report less the smoothed part, above it the budget's
    correlated part and the rest the excess; the budget's where the fix reports nothing, and
    at least the floor where it reports less than its smoothed part."""
    model = fix_error_model({"gnss": AUTOMOTIVE})
    hdop, vdop = 1.2, 2.0
    axes = np.array([hdop / math.sqrt(2.0), hdop / math.sqrt(2.0), vdop])
    budget = model.correlated_range * axes
    smoothed = model.smoothed_range * axes
    reported = np.array([0.6 * budget[0], 3.0 * budget[1], math.nan])
    drive_long = model.reported_drive_long_sigma(reported, hdop, vdop)
    assert math.isclose(drive_long[0], math.sqrt(reported[0] ** 2 - smoothed[0] ** 2))
    assert drive_long[1] == budget[1] and drive_long[2] == budget[2]
    excess = model.excess_sigma(reported, hdop, vdop)
    np.testing.assert_allclose((drive_long**2 + smoothed**2 + excess**2)[:2],
                               reported[:2] ** 2, rtol=1e-12)
    tiny = model.reported_drive_long_sigma(np.array([0.01, 0.01, 0.01]), hdop, vdop)
    np.testing.assert_array_equal(tiny, MIN_DRIVE_LONG_SIGMA_M)
