"""Consistency scores (NEES per block, per-axis normalised errors, NIS, ANEES) against solutions
whose errors and sigmas are known by construction, a Monte Carlo of a synthetic consistent
estimator, and chi-square quantiles computed without scipy (Wilson and Hilferty 1931)."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from scipy.stats import binom

from simulator.scoring.consistency import (
    CONSISTENCY_SKIP_S,
    anees,
    chi2_band,
    normalised_errors,
)
from simulator.scoring.metrics import score_solution
from tests.scoring_helpers import events, offset_solution, quickstart_truth

ATOL_M = 1e-5  # second-order error of the curvilinear offsets used to build the solutions
Z975 = 1.959963984540054  # standard normal 97.5 % quantile


@pytest.fixture(scope="module")
def truth() -> pd.DataFrame:
    return quickstart_truth()


def _wilson_hilferty(p_z: float, dof: int) -> float:
    """Chi-square quantile by the Wilson-Hilferty cube-root normal approximation."""
    a = 2.0 / (9.0 * dof)
    return dof * (1.0 - a + p_z * math.sqrt(a)) ** 3


def test_chi2_band_matches_tables_and_the_normal_approximation():
    # one epoch, 3 dof: the printed table values 0.216 and 9.348 (Bar-Shalom et al. 2001)
    assert chi2_band(3) == pytest.approx((0.2158, 9.348), abs=5e-4)
    # 50 runs of a 3-dof NEES: chi-square with 150 dof, over 50
    low, high = chi2_band(3, 50)
    assert low == pytest.approx(_wilson_hilferty(-Z975, 150) / 50, rel=2e-3)
    assert high == pytest.approx(_wilson_hilferty(Z975, 150) / 50, rel=2e-3)
    assert low < 3.0 < high


def test_known_errors_and_sigmas_give_their_normalised_squares(truth):
    sol = offset_solution(truth.iloc[::10], dpos=(3.0, -4.0, 1.5), dvel=(0.2, 0.0, -0.1),
                          datt_deg=(0.5, -1.0, 20.0))
    t = sol["t"].to_numpy()
    # before the skip the errors are 100 times larger: they must not count
    early = t < t[0] + CONSISTENCY_SKIP_S
    sol = offset_solution(truth.iloc[::10], dpos=(np.where(early, 300.0, 3.0), -4.0, 1.5),
                          dvel=(0.2, 0.0, -0.1), datt_deg=(0.5, -1.0, 20.0))
    sol["std_n"], sol["std_e"], sol["std_d"] = 1.5, 2.0, 0.5
    sol["std_vn"], sol["std_ve"], sol["std_vd"] = 0.1, 0.5, 0.1
    sol["std_roll"], sol["std_pitch"], sol["std_yaw"] = np.radians([0.25, 1.0, 10.0])
    assert np.ptp(truth["yaw"]) > np.radians(300)  # the yaw error is wrapped across +-180 deg
    expected = {"n": 4.0, "e": 4.0, "d": 9.0, "vn": 4.0, "ve": 0.0, "vd": 1.0,
                "roll": 4.0, "pitch": 1.0, "yaw": 4.0}
    assert normalised_errors(truth, sol) == pytest.approx(expected, abs=1e-4)
    c = score_solution(truth, events(), sol)["consistency"]
    assert set(c) == {"position", "velocity", "attitude"}
    later = int((~early).sum())
    for block, axes, dim in (("position", "ned", 3), ("velocity", ("vn", "ve", "vd"), 3),
                             ("attitude", ("roll", "pitch", "yaw"), 3)):
        nees = sum(expected[a] for a in axes)
        assert c[block]["nees"] == pytest.approx(nees, abs=1e-3)
        assert c[block]["nees_expected"] == dim
        assert c[block]["epochs"] == later
        assert c[block]["with_sigma"] == 1.0
        low, high = chi2_band(dim)
        assert c[block]["inside_95"] == (1.0 if low <= nees <= high else 0.0)
        assert c[block]["nse"] == pytest.approx({a: expected[a] for a in axes}, abs=1e-4)
    # the skip is a parameter: without it the early north error (200 sigma) dominates
    assert normalised_errors(truth, sol, skip_s=0.0)["n"] > 100.0


def test_a_solution_that_hides_its_worst_epochs_behind_nan_or_zero_sigmas_shows_it(truth):
    """NaN or 0 as the sigma of the epochs with a 30 m error leaves them out of the NEES (a
    sigma of 0 claims no error at all, so it cannot be scored) and ``with_sigma`` says for
    which share of the drive the figures hold."""
    sol = offset_solution(truth.iloc[::10], dpos=(1.0, 0.0, 0.0))
    sol["std_n"], sol["std_e"], sol["std_d"] = 1.0, 1.0, 1.0
    later = (sol["t"] >= sol["t"].iloc[0] + 60.0).to_numpy()
    worst = later & (np.cumsum(later) % 2 == 0)  # every other scored epoch
    sol.loc[worst, "lat"] += 30.0 / 6.4e6 * 180.0 / np.pi  # 30 m north
    sol.loc[worst, "std_n"] = np.nan
    sol.loc[worst & (np.cumsum(worst) % 2 == 0), "std_n"] = 0.0
    c = score_solution(truth, events(), sol)["consistency"]["position"]
    assert c["nse"]["n"] == pytest.approx(1.0, abs=1e-3)  # the hidden epochs are not in it
    assert c["with_sigma"] == pytest.approx(1.0 - worst.sum() / later.sum())
    assert 0.45 < c["with_sigma"] < 0.55
    json.dumps(c, allow_nan=False)


def test_a_2d_solution_is_judged_on_horizontal_position_and_yaw(truth):
    sol = offset_solution(truth.iloc[::10], dpos=(1.0, 2.0, 0.0), datt_deg=(0.0, 0.0, -3.0))
    sol["alt"] = sol["roll"] = sol["pitch"] = np.nan
    sol["std_n"], sol["std_e"], sol["std_d"] = 1.0, 1.0, np.nan
    sol["std_yaw"] = np.radians(1.0)
    c = score_solution(truth, events(), sol)["consistency"]
    assert c["position"] is None and c["velocity"] is None and c["attitude"] is None
    assert c["horizontal"]["nees"] == pytest.approx(5.0, abs=1e-4)
    assert c["horizontal"]["nees_expected"] == 2.0
    assert c["horizontal"]["nse"] == pytest.approx({"n": 1.0, "e": 4.0}, abs=1e-4)
    low, high = chi2_band(2)
    assert c["horizontal"]["inside_95"] == (1.0 if low <= 5.0 <= high else 0.0)
    assert c["yaw"]["nees"] == pytest.approx(9.0, abs=1e-6)
    assert c["yaw"]["nees_expected"] == 1.0 and c["yaw"]["inside_95"] == 0.0  # 9 > 5.02
    json.dumps(c, allow_nan=False)


def test_a_planar_filter_keeps_its_horizontal_velocity_and_pitch(truth):
    # Cho's DRM2 filters: n, e, vn, ve, pitch and yaw with sigmas, no height, vd or roll
    sol = offset_solution(truth.iloc[::10], dpos=(1.0, 2.0, 0.0), dvel=(0.3, -0.1, 0.0),
                          datt_deg=(0.0, 2.0, -3.0))
    sol["alt"] = sol["vd"] = sol["roll"] = np.nan
    sol["std_n"], sol["std_e"] = 1.0, 1.0
    sol["std_vn"], sol["std_ve"] = 0.1, 0.1
    sol["std_pitch"], sol["std_yaw"] = np.radians(1.0), np.radians(1.0)
    c = score_solution(truth, events(), sol)["consistency"]
    assert c["velocity"] is None and c["attitude"] is None
    assert c["horizontal_velocity"]["nees_expected"] == 2.0
    assert c["horizontal_velocity"]["nse"] == pytest.approx({"vn": 9.0, "ve": 1.0}, abs=1e-3)
    assert c["pitch"]["nse"] == pytest.approx({"pitch": 4.0}, abs=1e-6)
    assert c["yaw"]["nse"] == pytest.approx({"yaw": 9.0}, abs=1e-6)
    assert "roll" not in c and "d" not in c  # no sigma, no block


def test_no_sigma_columns_no_consistency(truth):
    s = score_solution(truth, events(), truth.iloc[::10])
    assert "consistency" not in s and "nis" not in s


def _consistent_run(truth: pd.DataFrame, rng: np.random.Generator, scale: float = 1.0
                    ) -> pd.DataFrame:
    """A synthetic estimator whose errors are N(0, sigma_k) with sigmas that vary in time,
    reporting ``scale`` times its true sigma."""
    rows = truth.iloc[::20].reset_index(drop=True)
    k = len(rows)
    sigma_pos = np.stack([0.5 + 0.4 * np.sin(rows["t"] / 17.0 + i) for i in range(3)], axis=1)
    sigma_att = np.radians(0.2 + 0.1 * rng.random((k, 3)))
    e_pos = rng.standard_normal((k, 3)) * sigma_pos
    e_att = np.degrees(rng.standard_normal((k, 3)) * sigma_att)
    sol = offset_solution(rows, dpos=tuple(e_pos.T), datt_deg=tuple(e_att.T))
    for i, name in enumerate(("std_n", "std_e", "std_d")):
        sol[name] = scale * sigma_pos[:, i]
    for i, name in enumerate(("std_roll", "std_pitch", "std_yaw")):
        sol[name] = scale * sigma_att[:, i]
    return sol


def test_monte_carlo_of_a_consistent_estimator_lands_inside_the_chi2_bounds(truth):
    rng = np.random.default_rng(24)
    runs = 12
    per_run = {"position": [], "attitude": []}
    for _ in range(runs):
        c = score_solution(truth, events(), _consistent_run(truth, rng))["consistency"]
        for block in per_run:
            k = c[block]["epochs"]
            # one run: the time average of k independent chi-square(3) draws is chi2(3k)/k;
            # a 99.9 % band, so that a consistent run fails it once in a thousand seeds
            low, high = (_wilson_hilferty(s * 3.2905, 3 * k) / k for s in (-1, 1))
            assert low < c[block]["nees"] < high
            # the share inside the one-epoch 95 % band is binomial(k, 0.95)
            inside = c[block]["inside_95"] * k
            assert binom.ppf(0.0005, k, 0.95) <= inside <= binom.ppf(0.9995, k, 0.95)
            for v in c[block]["nse"].values():
                assert (_wilson_hilferty(-3.2905, k) / k < v < _wilson_hilferty(3.2905, k) / k)
            per_run[block].append(c[block]["nees"])
    for block, values in per_run.items():
        a = anees(np.array(values), 3)
        assert a["runs"] == runs and a["missing"] == 0
        assert a["lower"] < a["anees"] < a["upper"], block
        assert (a["lower"], a["upper"]) == pytest.approx(chi2_band(3, runs))
    # the same estimator claiming half its sigma: NEES four times, ANEES far above its band
    over = score_solution(truth, events(), _consistent_run(truth, rng, 0.5))["consistency"]
    a = anees(np.array([over["position"]["nees"]]), 3)
    assert a["anees"] > a["upper"]


def test_anees_counts_runs_without_a_value():
    a = anees(np.array([2.0, np.nan, 4.0]), 3)
    assert a["anees"] == 3.0 and a["runs"] == 2 and a["missing"] == 1
    assert anees(np.array([np.nan]), 2) == {"anees": None, "expected": 2.0, "lower": None,
                                            "upper": None, "runs": 0, "missing": 1}


def test_nis_from_the_solution_columns(truth):
    rng = np.random.default_rng(5)
    sol = offset_solution(truth.iloc[::10])
    sol["std_n"] = sol["std_e"] = sol["std_d"] = 1.0
    update = (np.arange(len(sol)) % 10) == 0  # one GNSS update a second
    dof = np.where(np.arange(len(sol)) % 20 == 0, 4.0, 6.0)
    draws = rng.chisquare(dof)
    sol["nis_gnss"] = np.where(update, draws, np.nan)
    sol["nis_gnss_dof"] = np.where(update, dof, np.nan)
    nis = score_solution(truth, events(), sol)["nis"]
    later = update & (sol["t"].to_numpy() >= sol["t"].iloc[0] + CONSISTENCY_SKIP_S)
    n = int(later.sum())
    assert nis["updates"] == n
    assert nis["expected"] == pytest.approx(5.0, abs=0.1)  # half the updates 4 dof, half 6
    # the mean of n chi-square draws of mean dof 5 and variance 2 dof: 3.3 sigma either side
    assert nis["mean"] == pytest.approx(nis["expected"], abs=3.3 * math.sqrt(10.0 / n))
