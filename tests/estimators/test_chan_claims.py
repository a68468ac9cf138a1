"""The claims of Chan et al. ("Robust Navigation System for a Land Vehicle", seeds/001; issue 15)
on the shipped scenarios, over ten seeds, paired per seed:

* Table 1: the non-holonomic constraint cuts tc_ukf's mean 3-D error over 60 s windows with 0
  satellites by >= 40 %, with 1, 2, 3 satellites by >= 25 % each, and with 4 by less than with 0
  (paper: 54.4, 53.2, 52.6, 52.4, 22.6 %);
* Figure 2: from 100 m initial error on each axis both filters are below 10 m within 10 s, the
  UKF no later than the EKF + 1 s;
* Figure 1: on a nominal drive the UKF's RMS 3-D error is 0.8 to 1.05 times the EKF's.

The default partial-outage case is the shipped drive cut with ``--set`` to its first five 60 s
windows (one per satellite count; see ``short_partial_overrides``); the full drive, with each
count on a straight and in a curve in every seed, runs with ``--runslow``. (Halving the windows
to 30 s instead does not keep the claim's meaning: the errors then stay at the 1-3 m of the
pseudorange solution and the constraint has nothing to cut.) The figures are printed
(``pytest -s``) and collected in docs/reproduction_chan.md.
"""

from __future__ import annotations

import collections
import json
from collections.abc import Callable

import numpy as np
import pytest
import yaml

from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import open_dataset
from simulator.scenario import load_scenario
from tests.conftest import REPO
from tests.estimators.chan_helpers import run, window_means

SEEDS = range(1, 11)
SCENARIOS = REPO / "scenarios"
INIT = {"position_error": [100.0, 100.0, 100.0]}


def short_partial_overrides(seed: int) -> list[str]:
    """The partial-outage drive cut after its warm-up and first two and a half laps (straight,
    two loops, straight, two loops, straight) with its first five 60 s windows; the satellite counts
    0, 1, 2, 3, 4 in window order for even seeds, shifted by one window for odd seeds, so that
    over the ten seeds each count but 4 falls on straight and on curved road."""
    data = yaml.safe_load((SCENARIOS / "chan_partial_outages.yaml").read_text())
    segments = data["trajectory"]["segments"]
    faults = data["faults"][:5]
    shift = seed % 2
    for k, fault in enumerate(faults):
        fault["count"] = (k + shift) % 5
    return [f"trajectory.segments={json.dumps(segments[:12] + segments[-2:])}",
            f"faults={json.dumps(faults)}"]


def _datasets(tmp_path_factory, scenario: str, overrides: Callable[[int], list[str]] | None):
    root = tmp_path_factory.mktemp(scenario)
    out = []
    for seed in SEEDS:
        sc = load_scenario(SCENARIOS / f"{scenario}.yaml", overrides(seed) if overrides else [],
                           seed=seed)
        out.append(open_dataset(generate_dataset(sc, root / str(seed), show_progress=False)))
    return out


def window_errors(datasets) -> dict[int, np.ndarray]:
    """Per satellite count, rows (one per seed) of tc_ukf's mean 3-D error over that count's
    windows with and without the NHC, shape (n_seeds, 2)."""
    pairs = collections.defaultdict(list)
    for ds in datasets:
        with_nhc = window_means(ds, *run(ds, "tc_ukf"))
        without = window_means(ds, *run(ds, "tc_ukf", nhc=False))
        by = collections.defaultdict(lambda: ([], []))
        for (count, a), (_, b) in zip(with_nhc, without, strict=True):
            by[count][0].append(a)
            by[count][1].append(b)
        for count, (a, b) in by.items():
            pairs[count].append((np.mean(a), np.mean(b)))
    return {c: np.array(v) for c, v in pairs.items()}


def table1(errors: dict[int, np.ndarray]) -> dict[int, dict[str, float]]:
    """The NHC's cut (%) of the mean error over all windows of each count (Table 1's "average
    reduction"), and the median and range of the per-seed cuts."""
    out = {}
    for c, e in sorted(errors.items()):
        per_seed = 100.0 * (1.0 - e[:, 0] / e[:, 1])
        out[c] = {"cut": float(100.0 * (1.0 - e[:, 0].mean() / e[:, 1].mean())),
                  "median": float(np.median(per_seed)), "min": float(per_seed.min()),
                  "max": float(per_seed.max()), "nhc_m": float(e[:, 0].mean()),
                  "no_nhc_m": float(e[:, 1].mean())}
    return out


def _report(rows: dict[int, dict[str, float]], errors: dict[int, np.ndarray]) -> None:
    for c, r in rows.items():
        print(f"{c} satellites: mean error {r['nhc_m']:.2f} m with NHC, {r['no_nhc_m']:.2f} m "
              f"without: cut {r['cut']:.1f} % (per seed median {r['median']:.1f}, "
              f"[{r['min']:.1f}, {r['max']:.1f}])")
    assert sorted(rows) == [0, 1, 2, 3, 4]
    assert all(len(e) == len(SEEDS) for e in errors.values())


@pytest.fixture(scope="module")
def short_table(tmp_path_factory):
    errors = window_errors(_datasets(tmp_path_factory, "chan_partial_outages",
                                     short_partial_overrides))
    rows = table1(errors)
    _report(rows, errors)
    return rows


@pytest.fixture(scope="module")
def full_table(tmp_path_factory):
    errors = window_errors(_datasets(tmp_path_factory, "chan_partial_outages", None))
    rows = table1(errors)
    _report(rows, errors)
    return rows


def _not_shown(measured: str) -> pytest.MarkDecorator:
    return pytest.mark.xfail(strict=True, reason=f"claim not reproduced: {measured} "
                                                 "(docs/reproduction_chan.md)")


# (satellites, least cut %) of issue 15; the paper's Table 1: 54.4, 53.2, 52.6, 52.4 %
SHORT_CLAIMS = [pytest.param(0, 40.0, marks=_not_shown("11.9 % with 0 satellites on the "
                                                       "shortened drive")),
                (1, 25.0), (2, 25.0), (3, 25.0)]
FULL_CLAIMS = [(0, 40.0), (1, 25.0), (2, 25.0),
               pytest.param(3, 25.0, marks=_not_shown("17.8 % with 3 satellites"))]


@pytest.mark.parametrize(("satellites", "least_cut"), SHORT_CLAIMS)
def test_nhc_cut_as_table_1(short_table, satellites, least_cut):
    assert short_table[satellites]["cut"] >= least_cut


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
@_not_shown("29.7 % on the automotive body, whose side slip in the 40 m loops breaks the "
            "constraint (58.9 % on a rigid body)")
def test_nhc_cut_in_complete_outages(tmp_path_factory):
    """Table 1's first row on the complete-outage drive (three 60 s outages per seed, straight
    and in loops): the NHC cuts the mean 3-D error over the outages by at least 40 %."""
    rows = table1(window_errors(_datasets(tmp_path_factory, "chan_complete_outages", None)))
    print(f"complete outages: {rows[0]['nhc_m']:.2f} vs {rows[0]['no_nhc_m']:.2f} m, cut "
          f"{rows[0]['cut']:.1f} % (per seed median {rows[0]['median']:.1f}, "
          f"[{rows[0]['min']:.1f}, {rows[0]['max']:.1f}])")
    assert sorted(rows) == [0]
    assert rows[0]["cut"] >= 40.0


def settle_time(solution, error: np.ndarray, bound_m: float = 10.0) -> float:
    """Seconds from the first solution until the 3-D error stays below ``bound_m``."""
    t = solution["t"].to_numpy()
    above = np.flatnonzero(error >= bound_m)
    if len(above) == 0:
        return 0.0
    if above[-1] + 1 >= len(t):
        return np.inf
    return float(t[above[-1] + 1] - t[0])


def test_initial_error_and_nominal_accuracy(tmp_path_factory):
    """Figures 1 and 2 on the chan_initial_error drive: settling from 100 m per axis, and the
    UKF/EKF RMS ratio on the same drive without the initial error."""
    settle = {"tc_ukf": [], "tc_ekf": []}
    start_error = []
    ratios = []
    for ds in _datasets(tmp_path_factory, "chan_initial_error", None):
        rms = {}
        for name in settle:
            solution, error = run(ds, name, initial_position_std=100.0, init=INIT)
            settle[name].append(settle_time(solution, error))
            _, nominal = run(ds, name)
            rms[name] = float(np.sqrt(np.mean(nominal**2)))
        start_error.append(np.linalg.norm(INIT["position_error"]))
        ratios.append(rms["tc_ukf"] / rms["tc_ekf"])
    print("settling below 10 m (s): UKF", settle["tc_ukf"], "EKF", settle["tc_ekf"])
    print(f"nominal RMS ratio UKF/EKF: median {np.median(ratios):.3f}, "
          f"[{min(ratios):.3f}, {max(ratios):.3f}]")
    ukf, ekf = np.array(settle["tc_ukf"]), np.array(settle["tc_ekf"])
    assert (ukf <= 10.0).all() and (ekf <= 10.0).all()
    assert (ukf <= ekf + 1.0).all()
    assert 0.8 <= np.median(ratios) <= 1.05
