"""The rtk scores on hand-made epochs whose answers are counted by hand."""

from __future__ import annotations

import numpy as np

from simulator.scoring.rtk import rtk_scores


def test_counts_rates_and_times():
    t = np.arange(20.0)
    status = np.array([0, 1, 1, 2, 2, 2, 2, 2, 0, 0, 0, 1, 1, 1, 2, 2, 2, 2, 1, 2], float)
    error = np.full(20, 0.02)
    error[5] = 0.5                       # one wrong fix
    scores = rtk_scores(t, error, status, [(8.0, 11.0)])
    assert scores["epochs"] == 20 and scores["fixed_epochs"] == 10
    assert scores["fix_rate"] == 0.5
    assert scores["wrong_fix_rate"] == 0.1
    assert np.isclose(scores["fixed_rms"], np.sqrt((9 * 0.02**2 + 0.5**2) / 10))
    assert scores["time_to_first_fix"] == 3.0
    assert scores["refix_times"] == [3.0]  # GNSS back at 11 s, fixed again at 14 s


def test_no_fix_and_a_refix_that_never_comes():
    t = np.arange(10.0)
    status = np.array([1, 1, 1, 1, np.nan, 1, 1, 1, 1, 1])
    scores = rtk_scores(t, np.zeros(10), status, [(2.0, 4.0), (6.0, 7.0)])
    assert scores["epochs"] == 9 and scores["fix_rate"] == 0.0
    assert scores["fixed_rms"] is None and scores["time_to_first_fix"] is None
    assert scores["refix_times"] == [None, None]
