"""The markdown report: every plot written and referenced, every label's numbers present."""

from __future__ import annotations

import re

import numpy as np
import pytest

from simulator.dataset.io import open_dataset
from simulator.scoring.evaluate import score_solutions
from simulator.scoring.report import format_number, text_table, write_report
from tests.scoring_helpers import offset_solution, quickstart_truth, write_scoring_dataset

OUTAGES = ((40.0, 60.0), (120.0, 150.0))


@pytest.fixture(scope="module")
def evaluation(tmp_path_factory):
    truth = quickstart_truth()
    ds = open_dataset(write_scoring_dataset(tmp_path_factory.mktemp("d") / "ds", truth, OUTAGES))
    sub = truth.iloc[::10]
    shifted = offset_solution(sub, dpos=(1.0, 2.0, 0.5), datt_deg=(0.1, 0.2, 3.0))
    shifted["std_n"], shifted["std_e"], shifted["std_d"] = 1.0, 1.0, 1.0
    drifting = offset_solution(sub, dpos=(0.0, 0.02 * sub["t"].to_numpy(), 0.0))
    return score_solutions(ds, {"shifted": (shifted, {"runtime_s": 0.5, "realtime_factor": 387.0}),
                                "drifting": (drifting, None)})


def _numbers(scores: dict) -> list[float]:
    out = [v for group in ("horizontal", "vertical", "velocity", "attitude")
           for v in scores[group].values()]
    out += [o[k] for o in scores["outages"] for k in ("max_horizontal", "end_horizontal",
                                                      "end_percent")]
    return [v for v in out if v is not None]


def test_report_has_every_plot_and_every_number(evaluation, tmp_path):
    path = write_report(tmp_path, evaluation, "quickstart")
    text = path.read_text()
    pngs = sorted(p.name for p in (tmp_path / "plots").glob("*.png"))
    assert pngs == ["altitude.png", "attitude_errors.png", "horizontal_cdf.png", "map.png",
                    "map_windows.png", "nees.png", "position_errors.png"]
    assert sorted(re.findall(r"\]\(plots/([\w.]+)\)", text)) == pngs
    for png in pngs:
        assert (tmp_path / "plots" / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    for label, r in evaluation.results.items():
        assert label in text
        for value in _numbers(r.scores):
            assert format_number(value) in text
    shifted = evaluation.results["shifted"].scores
    assert format_number(shifted["nees"]["position"]) in text
    position = shifted["consistency"]["position"]
    row = next(line for line in text.splitlines() if line.startswith("| shifted | position |"))
    assert format_number(position["nees"]) in row and format_number(position["inside_95"]) in row
    assert format_number(shifted["runtime"]["realtime_factor"]) in text
    # the per-outage table: one row per outage, the drifting solution's end error 0.02 t
    rows = [line for line in text.splitlines() if re.match(r"\| [12] \|", line)]
    assert len(rows) == 2
    assert format_number(0.02 * 149.9) in rows[1]


def test_report_without_solutions_says_why(tmp_path):
    truth = quickstart_truth().iloc[::50]
    ds = open_dataset(write_scoring_dataset(tmp_path / "ds", truth, ()))
    ev = score_solutions(ds, {})
    path = write_report(tmp_path / "ds", ev, "quickstart", note="No estimator was named.")
    text = path.read_text()
    assert "No estimator was named." in text and "## Metrics" not in text
    assert (tmp_path / "ds" / "plots" / "map.png").is_file()


def test_text_table_lists_each_label(evaluation):
    table = text_table(evaluation.scores())
    lines = table.splitlines()
    assert len(lines) == 3 and lines[0].split()[0] == "label"
    drifting = evaluation.results["drifting"].scores
    worst = max(o["end_percent"] for o in drifting["outages"])
    assert lines[2].split()[0] == "drifting"
    assert lines[2].split()[-1] == format_number(worst)
    assert np.isclose(float(lines[1].split()[1]), evaluation.results["shifted"].scores[
        "horizontal"]["rms"], atol=1e-3)
