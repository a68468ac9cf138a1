"""The per-sample errors are computed a chunk of solution rows at a time (bounded temporaries
for a solution of millions of rows): chunks of any size give the errors of one pass, bit for
bit, and the errors share the solution's own sigma columns instead of copying them."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from simulator.scoring import align
from tests.scoring_helpers import offset_solution, quickstart_truth


@pytest.fixture(scope="module")
def solution_and_truth() -> tuple[pd.DataFrame, pd.DataFrame]:
    truth = quickstart_truth()
    rows = truth.iloc[::7]
    sol = offset_solution(rows, dpos=(np.linspace(-3, 3, len(rows)), 2.0, 0.5),
                          dvel=(0.1, -0.2, 0.3), datt_deg=(1.0, -1.0, 179.0))
    sol.loc[sol.index[::5], "alt"] = np.nan  # rows without a height: horizontal error only
    sol["std_n"] = 0.5
    after = sol.tail(3).assign(t=sol["t"].iloc[-1] + np.arange(1.0, 4.0))  # after the truth:
    return pd.concat([sol, after], ignore_index=True), truth  # dropped and counted


@pytest.mark.parametrize("chunk_rows", [1, 7, 1000])
def test_chunks_give_the_errors_of_one_pass(solution_and_truth, monkeypatch, chunk_rows):
    sol, truth = solution_and_truth
    whole = align.solution_errors(truth, sol)
    assert whole.outside_truth > 0 and len(whole.errors) > 1000
    monkeypatch.setattr(align, "CHUNK_ROWS", chunk_rows)
    chunked = align.solution_errors(truth, sol)
    pd.testing.assert_frame_equal(chunked.errors, whole.errors, check_exact=True)
    assert (chunked.total_rows, chunked.outside_truth) == (whole.total_rows, whole.outside_truth)
    # the errors are the offsets put in (second order in the offsets: 1e-5 m)
    err = whole.errors
    assert np.nanmax(np.abs(err["err_e"] - 2.0)) < 1e-5
    assert np.nanmax(np.abs(err["err_d"] - 0.5)) < 1e-5
    assert err["err_d"].isna().sum() == sol["alt"].iloc[:len(err)].isna().sum()


def test_sigmas_are_shared_not_copied(solution_and_truth):
    sol, truth = solution_and_truth
    inside = sol.iloc[:-3].reset_index(drop=True)
    errors = align.solution_errors(truth, inside).errors
    assert np.shares_memory(errors["std_n"].to_numpy(), inside["std_n"].to_numpy())
