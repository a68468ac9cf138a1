"""The claims of Chan et al. ("Robust Navigation System for a Land Vehicle", seeds/001; issue 15)
on the shipped scenarios, over ten seeds, paired per seed:

* Table 1: the non-holonomic constraint cuts tc_ukf's mean 3-D error over 60 s windows with 0
  satellites by >= 40 %, with 1, 2, 3 satellites by >= 25 % each, and with 4 by less than with 0
  (paper: 54.4, 53.2, 52.6, 52.4, 22.6 %);
* Figure 2: from 100 m initial error on each axis both filters are below 10 m within 10 s, the
  UKF no later than the EKF + 1 s;
* Figure 1: on a nominal drive the UKF's RMS 3-D error is 0.8 to 1.05 times the EKF's.

The figures are computed by ``simulator/reproduce/chan.py`` (what ``landnav reproduce chan``
judges). The default partial-outage case is the shipped drive cut with ``--set`` to its first
five 60 s windows (one per satellite count; ``chan.short_partial_overrides``) over seeds 1-3
(both window orders); ``--runslow`` adds the same drive over the ten seeds and the full drive,
with each count on a straight and in a curve in every seed. Figures 1 and 2 run on seeds 1-3,
and on the ten with ``--runslow``. The figures are printed (``pytest -s``) and collected in
docs/reproduction_chan.md.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from simulator.reproduce import chan
from simulator.reproduce.runner import run_experiment
from tests.conftest import seed_sets

pytestmark = pytest.mark.usefixtures("shared_experiments")  # each (experiment, seed) once

SEEDS = range(1, 11)
SEED_SETS = seed_sets(SEEDS)  # seeds 1-3 (both window orders of the shortened drive); 1-10


def _short_figures(work, seeds) -> pd.DataFrame:
    """The shortened partial-outage drive, the window orders alternating over the seeds:
    odd seeds in the order of ``reproduce --quick`` (``chan.PARTIAL_OUTAGES.quick_overrides``,
    that of even arguments of ``short_partial_overrides``), so that seed 1 is computed once
    for these tests and the quick reproduction (tests/experiment_cache.py)."""
    return pd.concat([run_experiment(chan.PARTIAL_OUTAGES, [seed], work,
                                     extra_overrides=chan.short_partial_overrides(seed + 1))
                      for seed in seeds])


def _report(rows: dict[int, dict[str, float]], seeds=SEEDS) -> None:
    for c, r in rows.items():
        print(f"{c} satellites: mean error {r['nhc_m']:.2f} m with NHC, {r['no_nhc_m']:.2f} m "
              f"without: cut {r['cut']:.1f} % (per seed median {r['median']:.1f}, "
              f"[{r['min']:.1f}, {r['max']:.1f}])")
    assert sorted(rows) == [0, 1, 2, 3, 4]
    assert all(r["seeds"] == len(seeds) for r in rows.values())


def _cut_interval(figures: pd.DataFrame, count: int) -> tuple[float, float]:
    """The 95 % confidence interval (%) of Table 1's cut 100 (1 - mean(a) / mean(b)) over the
    seeds (a, b: each seed's mean 3-D error with and without the NHC): the ratio of means'
    standard error by the delta method, sqrt(var(a - r b) / n) / mean(b) with r the ratio
    (Cochran 1977, *Sampling Techniques*, eq. 6.13), times Student's t with n - 1 degrees of
    freedom (for three seeds 4.30)."""
    from scipy.stats import t as student_t

    a = figures[f"{chan.NHC}.sats{count}.mean_3d_m"].to_numpy(float)
    b = figures[f"{chan.NO_NHC}.sats{count}.mean_3d_m"].to_numpy(float)
    ratio = a.mean() / b.mean()
    spread = np.std(a - ratio * b, ddof=1) / np.sqrt(len(a)) / b.mean()
    half = student_t.ppf(0.975, len(a) - 1) * spread
    return 100.0 * (1.0 - ratio - half), 100.0 * (1.0 - ratio + half)


@pytest.fixture(scope="module", params=SEED_SETS)
def short_table(request, tmp_path_factory):
    """Table 1 on the shortened drive over seeds 1-3 (and the ten seeds with --runslow), with
    each cut's 95 % interval over the seeds (``low``, ``high``)."""
    figures = _short_figures(tmp_path_factory.mktemp("chan_short"), request.param)
    rows = chan.table1(figures)
    _report(rows, request.param)
    for count, row in rows.items():
        row["low"], row["high"] = _cut_interval(figures, count)
        print(f"{count} satellites: cut 95 % interval {row['low']:.1f} to {row['high']:.1f} %")
    return rows


@pytest.fixture(scope="module")
def full_table(tmp_path_factory):
    rows = chan.table1(run_experiment(chan.PARTIAL_OUTAGES, SEEDS,
                                      tmp_path_factory.mktemp("chan_full")))
    _report(rows)
    return rows


def _not_shown(measured: str) -> pytest.MarkDecorator:
    return pytest.mark.xfail(strict=True, reason=f"claim not reproduced: {measured} "
                                                 "(docs/reproduction_chan.md)")


# (satellites, least cut %) of issue 15; the paper's Table 1: 54.4, 53.2, 52.6, 52.4 %
SHORT_CLAIMS = [(0, 40.0), (1, 25.0), (2, 25.0), (3, 25.0)]
FULL_CLAIMS = [(0, 40.0), (1, 25.0), (2, 25.0),
               pytest.param(3, 25.0, marks=_not_shown("19.4 % with 3 satellites"))]


@pytest.mark.parametrize(("satellites", "least_cut"), SHORT_CLAIMS)
def test_nhc_cut_as_table_1(short_table, satellites, least_cut):
    """The NHC cuts the mean error (the cut over the seeds above zero), and the seeds do not
    contradict the least cut: it lies below the top of their 95 % interval
    (``_cut_interval``). Each seed's cut is one draw of the satellites kept and of the drive's
    errors, spread by tens of per cent (seeds 1-3: 7.6-76.1 % with 2 satellites, -7.8-35.5 %
    with 3, 25.4-56.4 % with none), so three seeds cannot show the printed cut; a fixed bound
    on their mean held on one set of draws and not on the next (2 satellites 18.0 then
    20.7 %, 3 satellites 22.0 then 22.9 %). Whether the cut is shown is judged over twenty
    seeds by the reproduction (docs/reproduction_chan.md)."""
    row = short_table[satellites]
    assert row["cut"] > 0.0
    assert row["high"] >= least_cut


def test_nhc_cut_with_4_satellites_is_the_smallest(short_table):
    assert short_table[4]["cut"] < short_table[0]["cut"]


@pytest.mark.slow
@pytest.mark.parametrize(("satellites", "least_cut"), FULL_CLAIMS)
def test_nhc_cut_as_table_1_full_drive(full_table, satellites, least_cut):
    assert full_table[satellites]["cut"] >= least_cut


@pytest.mark.slow
def test_nhc_cut_with_4_satellites_is_the_smallest_full_drive(full_table):
    assert full_table[4]["cut"] < full_table[0]["cut"]


@pytest.mark.slow
def test_nhc_cut_in_complete_outages(tmp_path_factory):
    """Table 1's first row on the complete-outage drive (three 60 s outages per seed, straight
    and in loops): the NHC cuts the mean 3-D error over the outages by at least 40 % (measured
    54.8 % with the constraint at the rear axle, 5.70 vs 12.62 m; 29.7 % with it at the IMU)."""
    rows = chan.table1(run_experiment(chan.COMPLETE_OUTAGES, SEEDS,
                                      tmp_path_factory.mktemp("chan_complete")))
    print(f"complete outages: {rows[0]['nhc_m']:.2f} vs {rows[0]['no_nhc_m']:.2f} m, cut "
          f"{rows[0]['cut']:.1f} % (per seed median {rows[0]['median']:.1f}, "
          f"[{rows[0]['min']:.1f}, {rows[0]['max']:.1f}])")
    assert sorted(rows) == [0]
    assert rows[0]["cut"] >= 40.0


@pytest.mark.parametrize("seeds", SEED_SETS)
def test_initial_error_and_nominal_accuracy(tmp_path_factory, seeds):
    """Figures 1 and 2 on the chan_initial_error drive: settling from 100 m per axis, and the
    UKF/EKF RMS ratio on the same drive without the initial error."""
    table = run_experiment(chan.INITIAL_ERROR, seeds, tmp_path_factory.mktemp("chan_initial"))
    ukf = table["tc_ukf_init.settle_s"].to_numpy()
    ekf = table["tc_ekf_init.settle_s"].to_numpy()
    ratios = (table["tc_ukf.rms_3d_m"] / table["tc_ekf.rms_3d_m"]).to_numpy()
    print("settling below 10 m (s): UKF", ukf, "EKF", ekf)
    print(f"nominal RMS ratio UKF/EKF: median {np.median(ratios):.3f}, "
          f"[{min(ratios):.3f}, {max(ratios):.3f}]")
    assert (ukf <= 10.0).all() and (ekf <= 10.0).all()
    assert (ukf <= ekf + 1.0).all()
    assert 0.8 <= np.median(ratios) <= 1.05
