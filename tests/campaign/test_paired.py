"""A campaign's paired comparison (``simulator.campaign.paired``): on a runs table whose
per-seed differences are known, the median difference, the counts, the missing seeds and the
sign test (against the binomial sum written out, independent of scipy) are those of the
seeds both estimators scored; the bootstrap interval holds the median and is the same on
every call; the summary carries it as JSON without NaN and the report shows it."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd

from simulator.campaign.paired import paired_comparisons
from simulator.campaign.report import _paired_lines
from simulator.campaign.summary import summarise

SEEDS = list(range(1, 11))
# b - a per seed: a is smaller on seeds 1-8, larger on 9 and 10
DIFFERENCE = np.array([0.5, 0.4, 0.9, 0.2, 0.7, 0.3, 0.6, 0.8, -0.1, -0.4])


def _runs() -> pd.DataFrame:
    b = np.linspace(2.0, 3.0, len(SEEDS))
    values = {"a": b - DIFFERENCE, "b": b}
    ends = {"a": np.full(len(SEEDS), 5.0), "b": np.full(len(SEEDS), 6.0)}
    ends["b"][2] = np.nan  # b silent at an outage's end on seed 3
    rows = []
    for label in ("a", "b"):
        for i, seed in enumerate(SEEDS):
            failed = label == "a" and seed == 10  # a failed on seed 10: no pair there
            rows.append({"run_id": i, "seed": seed, "label": label,
                         "status": "failed" if failed else "ok",
                         "horizontal.rms": np.nan if failed else values[label][i],
                         "outages.end_horizontal": np.nan if failed else ends[label][i],
                         "error": ""})
    return pd.DataFrame(rows)


def _sign_test_p(k: int, n: int) -> float:
    """Two-sided exact sign test: twice the smaller binomial tail, at most 1."""
    tail = sum(math.comb(n, i) for i in range(min(k, n - k) + 1)) / 2.0**n
    return min(1.0, 2.0 * tail)


def test_paired_statistics_are_those_of_the_common_seeds():
    rms, ends = paired_comparisons(_runs(), ["a", "b"], [{}])
    assert (rms["a"], rms["b"], rms["score"]) == ("a", "b", "horizontal.rms")
    d = -DIFFERENCE[:9]  # seed 10 failed for a
    assert rms["seeds"] == 9 and rms["missing"] == 0
    assert math.isclose(rms["median_difference"], float(np.median(d)))
    assert (rms["a_smaller"], rms["b_smaller"]) == (8, 1)
    assert math.isclose(rms["sign_test_p"], _sign_test_p(8, 9))
    low, high = rms["interval"]
    assert low <= rms["median_difference"] <= high and low >= d.min() and high <= d.max()
    assert paired_comparisons(_runs(), ["a", "b"], [{}])[0]["interval"] == [low, high]
    # seed 3: b silent at the outage end, counted as missing, not compared
    assert ends["seeds"] == 8 and ends["missing"] == 1
    assert math.isclose(ends["median_difference"], -1.0)
    assert math.isclose(ends["sign_test_p"], _sign_test_p(8, 8))


def test_summary_and_report_carry_the_comparison():
    summary = summarise(_runs(), ["a", "b"], [{}], {"scenario": "s", "sweep": {}})
    text = json.dumps(summary, allow_nan=False)  # no NaN in summary.json
    assert json.loads(text)["paired"][0]["a_smaller"] == 8
    table = "\n".join(_paired_lines(summary))
    assert "horizontal.rms" in table and "8 of 9" in table and "outages.end_horizontal" in table
