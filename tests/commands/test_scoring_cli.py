"""``landnav score`` and ``landnav run`` through ``simulator.cli.main``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from simulator.cli import main
from simulator.dataset.io import open_dataset
from simulator.pipeline import NO_ESTIMATOR
from simulator.replay import run_estimator, write_solution
from simulator.scoring.metrics import score_solution
from tests.scoring_helpers import (
    QUICKSTART,
    events,
    offset_solution,
    quickstart_truth,
    write_scoring_dataset,
)
from tests.synthetic import write_synthetic
from tests.test_html_report import check_report_html

OUTAGES = ((40.0, 60.0), (120.0, 150.0))


def _strict_json(path: Path) -> dict:
    def refuse(name: str):
        raise AssertionError(f"{path} holds {name}")
    return json.loads(Path(path).read_text(), parse_constant=refuse)


def _flat(tree, prefix: str = "") -> dict:
    """Nested dicts and lists as {"a.b.0.c": leaf}, for pytest.approx."""
    items = tree.items() if isinstance(tree, dict) else enumerate(tree)
    out = {}
    for key, value in items:
        if isinstance(value, (dict, list)):
            out.update(_flat(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


@pytest.fixture(scope="module")
def truth() -> pd.DataFrame:
    return quickstart_truth()


@pytest.fixture(scope="module")
def dataset(truth, tmp_path_factory) -> Path:
    return write_scoring_dataset(tmp_path_factory.mktemp("score") / "ds", truth, OUTAGES)


@pytest.fixture()
def shifted(truth) -> pd.DataFrame:
    return offset_solution(truth.iloc[::10], dpos=(3.0, -4.0, 1.5), dvel=(0.3, -0.4, 1.2),
                           datt_deg=(1.0, -2.0, 20.0))


def test_pandas_file_is_scored_like_a_builtin(dataset, truth, shifted, tmp_path, capsys):
    foreign = shifted.set_index(pd.RangeIndex(7, 7 + len(shifted)))  # index saved as a column
    foreign["bias_gz"] = 1e-4  # a free extra column
    foreign.to_parquet(tmp_path / "other_program.parquet")
    write_solution(shifted, tmp_path / "builtin.parquet")
    assert main(["score", str(dataset), "--solution", str(tmp_path / "other_program.parquet"),
                 str(tmp_path / "builtin.parquet"), "--json", str(tmp_path / "s.json")]) == 0
    scores = _strict_json(tmp_path / "s.json")
    assert list(scores) == ["other_program", "builtin"]
    assert scores["other_program"] == scores["builtin"]
    expected = score_solution(truth, events(*OUTAGES), shifted)
    assert _flat(scores["builtin"]) == pytest.approx(_flat(expected), abs=1e-12)
    assert scores["builtin"]["horizontal"]["rms"] == pytest.approx(5.0, abs=1e-5)
    assert [o["start"] for o in scores["builtin"]["outages"]] == [40.0, 120.0]
    out = capsys.readouterr().out
    assert "other_program" in out and "5.000" in out


@pytest.mark.parametrize("damage, message", [
    (lambda f: f.drop(columns=["yaw", "vd"]), "missing column(s) vd, yaw"),
    (lambda f: f.iloc[[0, 2, 1, 3]], "t is not increasing"),
])
def test_bad_solution_file_is_one_clear_message(dataset, shifted, tmp_path, capsys, damage,
                                                message):
    bad = tmp_path / "bad.parquet"
    damage(shifted).to_parquet(bad)
    assert main(["score", str(dataset), "--solution", str(bad), "--json",
                 str(tmp_path / "s.json")]) == 2
    err = capsys.readouterr().err
    assert str(bad) in err and message.split("(")[0] in err and "Traceback" not in err
    assert not (tmp_path / "s.json").exists()


def test_unreadable_file_duplicate_labels_and_non_dataset(dataset, shifted, tmp_path, capsys):
    text = tmp_path / "notes.parquet"
    text.write_text("not parquet")
    assert main(["score", str(dataset), "--solution", str(text)]) == 2
    assert str(text) in capsys.readouterr().err
    (tmp_path / "a").mkdir()
    shifted.to_parquet(tmp_path / "a" / "sol.parquet")
    shifted.to_parquet(tmp_path / "sol.parquet")
    assert main(["score", str(dataset), "--solution", str(tmp_path / "sol.parquet"),
                 str(tmp_path / "a" / "sol.parquet")]) == 2
    assert "labelled 'sol'" in capsys.readouterr().err
    assert main(["score", str(tmp_path), "--solution", str(tmp_path / "sol.parquet")]) == 2
    assert "not a landnav dataset" in capsys.readouterr().err


def test_score_report_is_written_atomically(dataset, shifted, tmp_path, capsys):
    shifted.to_parquet(tmp_path / "shifted.parquet")
    report = tmp_path / "report"
    args = ["score", str(dataset), "--solution", str(tmp_path / "shifted.parquet"),
            "--report", str(report)]
    assert main(args) == 0
    text = (report / "report.md").read_text()
    assert "shifted" in text and "5.000" in text and "20.000" in text
    for png in ("map", "position_errors", "attitude_errors", "horizontal_cdf"):
        assert f"(plots/{png}.png)" in text and (report / "plots" / f"{png}.png").is_file()
    assert "shifted" in "".join(check_report_html(report).text)  # every plot embedded
    assert main(args) == 2  # exists: kept unless --force
    assert "--force" in capsys.readouterr().err
    assert main([*args, "--force"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir() if "tmp" in p.name) == []


def test_outside_truth_rows_are_warned_about(dataset, shifted, tmp_path, capsys):
    late = shifted.copy()
    late["t"] += 100.0
    late.to_parquet(tmp_path / "late.parquet")
    assert main(["score", str(dataset), "--solution", str(tmp_path / "late.parquet"),
                 "--json", str(tmp_path / "s.json")]) == 0
    rows = _strict_json(tmp_path / "s.json")["late"]["rows"]
    assert rows["outside_truth"] == int((late["t"] > 193.47).sum()) > 0
    assert f"{rows['outside_truth']} of {len(late)} solution rows" in capsys.readouterr().err


def test_score_runs_a_registered_estimator(tmp_path):
    ds = write_synthetic(tmp_path / "syn", streams=("gnss_fix",), gnss_sigma=0.0)
    assert main(["score", str(ds), "-e", "gnss_only", "--json", str(tmp_path / "s.json")]) == 0
    scores = _strict_json(tmp_path / "s.json")
    assert list(scores) == ["gnss_only"]
    assert scores["gnss_only"]["runtime"]["seconds"] > 0
    runtime = scores["gnss_only"]["runtime"]  # the data's span over the replay's wall time
    fix_t = open_dataset(ds).read("gnss_fix")["t"]
    assert runtime["realtime_factor"] * runtime["seconds"] == pytest.approx(
        fix_t.iloc[-1] - fix_t.iloc[0], rel=1e-3)
    frame, _ = run_estimator(open_dataset(ds), "gnss_only", show_progress=False)
    frame.to_parquet(tmp_path / "gnss_only.parquet")
    assert main(["score", str(ds), "--solution", str(tmp_path / "gnss_only.parquet"),
                 "--json", str(tmp_path / "f.json")]) == 0
    from_file = _strict_json(tmp_path / "f.json")["gnss_only"]
    scores["gnss_only"].pop("runtime")
    assert scores["gnss_only"] == from_file
    assert main(["score", str(ds), "-e", "no_such_estimator"]) == 2


def _scenario(tmp_path: Path, estimators: list) -> Path:
    data = yaml.safe_load(Path(QUICKSTART).read_text())
    data["estimators"] = estimators
    path = tmp_path / "quickstart.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_run_generates_estimates_scores_and_reports(tmp_path, capsys):
    entry = {"name": "tests.campaign_estimators:HoldStart", "label": "hold",
             "init": {"position_error": [3.0, -4.0, 0.0]}}
    out = tmp_path / "run"
    assert main(["run", str(_scenario(tmp_path, [entry])), "-o", str(out)]) == 0
    assert (out / "dataset" / "manifest.json").is_file()
    scores = _strict_json(out / "scores.json")
    assert list(scores) == ["hold"]
    # the held state is the stationary start (v = 0, roll = pitch = 0) 3 m north, 4 m west
    truth = open_dataset(out / "dataset").read("truth")
    sol = pd.read_parquet(out / "solutions" / "hold.parquet")
    at = truth.set_index(np.round(truth["t"], 6)).loc[np.round(sol["t"], 6)]
    v = at[["vn", "ve", "vd"]].to_numpy()
    # rows matched by times rounded to the microsecond: with the body's vibration (some m/s^2)
    # the truth moves by up to 1e-6 m/s within that rounding
    assert scores["hold"]["velocity"]["rms"] == pytest.approx(
        np.sqrt(np.mean(np.sum(v**2, axis=1))), rel=1e-7)
    # the held roll is the start's (the road's camber under the car), not zero
    assert scores["hold"]["attitude"]["roll_rms"] == pytest.approx(
        np.degrees(np.sqrt(np.mean((at["roll"] - truth["roll"].iloc[0]) ** 2))), rel=1e-7)
    assert scores["hold"]["horizontal"]["cep50"] > 100.0
    assert scores["hold"]["runtime"]["seconds"] > 0
    text = (out / "report.md").read_text()
    assert "hold" in text and "(plots/map.png)" in text and (out / "plots" / "map.png").is_file()
    assert "hold" in "".join(check_report_html(out).text)  # the same report, plots embedded
    assert "hold" in capsys.readouterr().out
    # the solution file it wrote scores like the run did
    assert main(["score", str(out / "dataset"), "--solution",
                 str(out / "solutions" / "hold.parquet"), "--json", str(tmp_path / "s.json")]) == 0
    again = _strict_json(tmp_path / "s.json")["hold"]
    scores["hold"].pop("runtime")
    # the estimator used no GNSS: no outage scores, in the run and from the file it wrote
    assert scores["hold"]["outages"] is None and scores["hold"]["degraded"] is None
    assert again == scores["hold"]


def test_run_without_estimators_and_default_dir(tmp_path, monkeypatch, capsys):
    scenario = _scenario(tmp_path, []).resolve()
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(scenario)]) == 0
    out = tmp_path / "runs" / "quickstart"
    assert _strict_json(out / "scores.json") == {}
    assert NO_ESTIMATOR in (out / "report.md").read_text()
    assert list((out / "solutions").iterdir()) == []
    assert "no estimator was named" in capsys.readouterr().out
    assert main(["run", str(scenario)]) == 2  # exists: kept unless --force
    assert main(["run", str(scenario), "--force", "--seed", "5"]) == 0
    assert _strict_json(out / "dataset" / "manifest.json")["seed"] == 5


def test_run_with_a_bad_estimator_leaves_nothing(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", str(_scenario(tmp_path, ["no_such_estimator"])), "-o", str(out)]) == 2
    assert "no_such_estimator" in capsys.readouterr().err
    assert not out.exists() and [p.name for p in tmp_path.iterdir()] == ["quickstart.yaml"]


def test_solution_cut_off_at_an_outage_start_has_no_end_error(dataset, shifted, tmp_path,
                                                               capsys):
    """A solution that stops talking at an outage's start is not scored by its last row: its
    end error is missing (null), its coverage of the outage and of the drive drops."""
    a, b = OUTAGES[1]
    shifted.loc[shifted["t"] < a].to_parquet(tmp_path / "silent.parquet")
    shifted.to_parquet(tmp_path / "full.parquet")
    assert main(["score", str(dataset), "--solution", str(tmp_path / "silent.parquet"),
                 str(tmp_path / "full.parquet"), "--json", str(tmp_path / "s.json")]) == 0
    scores = _strict_json(tmp_path / "s.json")
    cut = scores["silent"]["outages"][1]
    assert cut["end_horizontal"] is None and cut["end_percent"] is None
    assert cut["max_horizontal"] is None  # no row inside the outage either
    # the last row at a - 0.1 s covers 1.5 periods (0.15 s) past it: 0.05 s of the outage
    assert cut["coverage"]["fraction"] == pytest.approx(0.05 / (b - a), abs=1e-9)
    assert cut["coverage"]["longest_gap"] == pytest.approx(b - a, abs=1e-9)
    assert scores["silent"]["coverage"]["fraction"] < 1.0
    full = scores["full"]["outages"][1]
    assert full["end_horizontal"] == pytest.approx(5.0, abs=1e-5)
    assert full["coverage"]["fraction"] == pytest.approx(1.0)
    # the printed table: its worst outage end is not the one outage it spoke at
    lines = {line.split()[0]: line.split() for line in capsys.readouterr().out.splitlines()}
    assert lines["silent"][-1] == "no-row"
    assert float(lines["full"][-1]) == pytest.approx(
        max(o["end_percent"] for o in scores["full"]["outages"]), abs=1e-3)
