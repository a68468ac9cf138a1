"""The library entry points (``simulator.pipeline``): the notebook path step by step gives the
same dataset and scores as ``pipeline.run`` and as ``landnav run`` (one code path for all)."""

from __future__ import annotations

import json
from pathlib import Path

import yaml

from simulator import pipeline
from simulator.cli import main

QUICKSTART = Path(__file__).resolve().parents[1] / "scenarios" / "quickstart.yaml"


def _short_quickstart(tmp_path: Path) -> Path:
    data = yaml.safe_load(QUICKSTART.read_text())
    data["trajectory"]["segments"] = data["trajectory"]["segments"][:4]  # a minute of driving
    data["estimators"] = ["gnss_only", {"name": "dead_reckoning", "label": "dr"}]
    path = tmp_path / "short.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _without_runtime(scores: dict) -> dict:
    return {label: {k: v for k, v in s.items() if k != "runtime"} for label, s in scores.items()}


def test_step_by_step_equals_run_and_the_command(tmp_path, capsys):
    path = _short_quickstart(tmp_path)
    scenario = pipeline.load_scenario(path, seed=4)
    dataset = pipeline.generate(scenario, tmp_path / "steps")
    solutions = pipeline.run_estimators(dataset, scenario.data["estimators"])
    assert list(solutions) == ["gnss_only", "dr"]
    evaluation = pipeline.score(dataset, solutions)
    report = pipeline.write_report(tmp_path / "report", evaluation, "short")
    assert report.is_file() and "dr" in report.read_text()
    # the horizontal error of dead reckoning over a minute stays within metres
    assert 0.0 < evaluation.scores()["dr"]["horizontal"]["max"] < 20.0

    whole = pipeline.run(scenario, tmp_path / "whole")
    assert _without_runtime(whole.evaluation.scores()) == _without_runtime(evaluation.scores())
    assert main(["run", str(path), "--seed", "4", "-o", str(tmp_path / "cli")]) == 0
    from_cli = json.loads((tmp_path / "cli" / "scores.json").read_text())
    assert _without_runtime(from_cli) == json.loads(json.dumps(
        _without_runtime(evaluation.scores())))
    for stream in ("imu", "truth", "gnss_fix"):
        steps = (tmp_path / "steps" / f"{stream}.parquet").read_bytes()
        assert steps == (tmp_path / "whole" / "dataset" / f"{stream}.parquet").read_bytes()
        assert steps == (tmp_path / "cli" / "dataset" / f"{stream}.parquet").read_bytes()
    assert "dr" in capsys.readouterr().out  # the command printed the table
