"""Campaign summaries count what is missing and judge consistency over the runs: a silent
solution's outage end errors are counted as missing (never dropped) in ``summary.json`` and the
report, and the ANEES of each block is given with its chi-square band (checked against the
Wilson-Hilferty approximation, independent of scipy)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from simulator.campaign import report
from simulator.campaign.summary import summarise
from tests.scoring_helpers import saved_figures

Z975 = 1.959963984540054  # standard normal 97.5 % quantile


def _chi2_quantile(z: float, dof: int) -> float:
    """Wilson-Hilferty: chi-square quantile from the normal quantile z."""
    a = 2.0 / (9.0 * dof)
    return dof * (1.0 - a + z * math.sqrt(a)) ** 3


def _runs() -> pd.DataFrame:
    n = 5
    honest = {"outages.end_horizontal": [4.0, 5.0, 6.0, 5.5, 4.5],
              "outages.coverage.fraction": [1.0] * n,
              "consistency.position.nees": [2.8, 3.3, 3.1, 2.7, 3.2],
              "consistency.horizontal.nees": [np.nan] * n}
    # speaks at one outage end only (a lucky 0.1 m), silent in the other four runs
    silent = {"outages.end_horizontal": [0.1, np.nan, np.nan, np.nan, np.nan],
              "outages.coverage.fraction": [0.9, 0.01, 0.01, 0.02, 0.01],
              "consistency.position.nees": [np.nan] * n,
              "consistency.horizontal.nees": [40.0, 55.0, 38.0, np.nan, 61.0]}
    rows = []
    for label, scores in (("honest", honest), ("silent", silent)):
        for i in range(n):
            rows.append({"run_id": i, "seed": 1 + i, "label": label, "status": "ok",
                         "horizontal.rms": 1.0 + i, **{k: v[i] for k, v in scores.items()},
                         "error": ""})
    return pd.DataFrame(rows)


@pytest.fixture()
def summary() -> dict:
    return summarise(_runs(), ["honest", "silent"], [{}],
                     {"scenario": "s", "labels": ["honest", "silent"], "runs": 5,
                      "base_seed": 1, "sweep": {}})


def test_missing_values_are_counted_per_score(summary):
    honest, silent = summary["groups"]
    end = silent["scores"]["outages.end_horizontal"]
    assert end["count"] == 1 and end["missing"] == 4 and end["mean"] == 0.1
    assert honest["scores"]["outages.end_horizontal"]["missing"] == 0
    assert honest["scores"]["horizontal.rms"] == pytest.approx(
        {"mean": 3.0, "median": 3.0, "p95": 4.8, "count": 5, "missing": 0})


def test_anees_per_block_with_its_chi_square_band(summary):
    honest, silent = summary["groups"]
    assert set(honest["anees"]) == {"position"} and set(silent["anees"]) == {"horizontal"}
    a = honest["anees"]["position"]
    assert a["anees"] == pytest.approx(3.02) and a["expected"] == 3.0
    assert a["runs"] == 5 and a["missing"] == 0
    # 5 runs of a 3-dof NEES: chi-square with 15 dof over 5
    assert a["lower"] == pytest.approx(_chi2_quantile(-Z975, 15) / 5, rel=0.01)
    assert a["upper"] == pytest.approx(_chi2_quantile(Z975, 15) / 5, rel=0.01)
    h = silent["anees"]["horizontal"]
    assert h["runs"] == 4 and h["missing"] == 1 and h["expected"] == 2.0
    assert h["upper"] == pytest.approx(_chi2_quantile(Z975, 8) / 4, rel=0.02)
    assert h["anees"] > h["upper"]


def test_report_shows_missing_runs_and_coverage_beside_the_box(summary, tmp_path):
    with saved_figures() as figures:
        path = report.write_campaign_report(tmp_path, _runs(), summary)
    text = path.read_text()
    assert "0.100 / 0.100 / 0.100 (4 missing)" in text
    assert "## Consistency over the runs (ANEES)" in text
    assert "| silent | horizontal | 48.500 | 2.000 |" in text and "overconfident" in text
    assert "| honest | position | 3.020 | 3.000 |" in text and "| inside |" in text
    outage_box = figures["outage_end"]
    ticks = [t.get_text() for t in outage_box.axes[0].get_xticklabels()]
    assert ticks == ["honest\n0/5 missing\ncoverage 1.00", "silent\n4/5 missing\ncoverage 0.19"]


def test_a_solution_not_scored_on_a_group_is_not_missing_it():
    runs = _runs()
    dr = runs[runs["label"] == "honest"].assign(label="dr")
    dr[["outages.end_horizontal", "outages.coverage.fraction",
        "consistency.position.nees"]] = np.nan  # no GNSS, no sigmas
    runs = pd.concat([runs, dr], ignore_index=True)
    summary = summarise(runs, ["honest", "silent", "dr"], [{}], {"sweep": {}})
    dr_group = summary["groups"][2]
    assert dr_group["scores"]["outages.end_horizontal"] == {
        "mean": None, "median": None, "p95": None, "count": 0, "missing": 0}
    assert dr_group["anees"] == {}
    # the 2-D solution is not missing a position NEES: it has none to give
    assert summary["groups"][1]["scores"]["consistency.position.nees"]["missing"] == 0
    assert report._box_note(dr_group, dr, "outages.end_horizontal") == "not scored"
