"""The report of a dataset with raw GNSS: every plot the issue asks for is written, the
degraded and outage windows are tabled, and the NEES bounds are the chi-square quantiles."""

from __future__ import annotations

import re

import pytest
from scipy.stats import chi2

from simulator.replay import run_estimator
from simulator.scoring import plots
from simulator.scoring.consistency import chi2_band
from simulator.scoring.evaluate import score_solutions
from simulator.scoring.report import write_report
from tests.scoring_helpers import offset_solution


@pytest.fixture(scope="module")
def evaluation(quickstart):
    truth = quickstart.read("truth")
    with_std = offset_solution(truth.iloc[::10], dpos=(1.0, 0.0, 0.0))
    with_std[["std_n", "std_e", "std_d"]] = 1.0
    gnss, info = run_estimator(quickstart, "gnss_only", show_progress=False)
    return score_solutions(quickstart, {"with_std": (with_std, None), "gnss_only": (gnss, info)})


def test_report_of_a_raw_gnss_dataset_has_every_plot(evaluation, tmp_path):
    text = write_report(tmp_path, evaluation, "quickstart").read_text()
    pngs = sorted(p.stem for p in (tmp_path / "plots").glob("*.png"))
    assert pngs == ["altitude", "attitude_errors", "gnss_sky", "horizontal_cdf", "map",
                    "map_windows", "nees", "position_errors"]
    assert sorted(re.findall(r"\]\(plots/(\w+)\.png\)", text)) == pngs
    assert "## Degraded GNSS windows" in text and "coverage (fraction of the drive)" in text
    # the tunnel outage row: gnss_only stops extrapolating 2 s after its last fix, so it has
    # no row at the outage's end; its coverage of the outage is printed beside it
    row = next(line for line in text.splitlines() if line.startswith("| 1 | 73.000"))
    assert row.count("|") == 4 + 2 * 4 + 1
    gnss_cells = [c.strip() for c in row.split("|")[9:13]]
    tunnel = evaluation.results["gnss_only"].scores["outages"][0]
    assert gnss_cells[:3] == ["no row", f"{tunnel['coverage']['fraction']:.3f}", "no row"]


def test_nees_bounds_are_the_chi_square_95_percent_quantiles():
    for dim in (1, 2, 3):
        assert chi2_band(dim) == pytest.approx([chi2.ppf(0.025, dim), chi2.ppf(0.975, dim)])
    assert chi2_band(3) == pytest.approx([0.2158, 9.348], abs=1e-3)  # published table


def test_lines_break_where_rows_are_missing():
    import numpy as np
    from matplotlib.figure import Figure

    t, y = plots.time_series(Figure(), np.array([0.0, 0.1, 0.2, 5.0, 5.1]), np.arange(5.0))
    assert np.isnan(t[3]) and np.isnan(y[3]) and len(t) == 6
