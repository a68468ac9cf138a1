"""``landnav campaign`` through ``simulator.cli.main``: local processes, a Dask cluster on
loopback, sweeps, failures, resuming, and bad input."""

from __future__ import annotations

import dataclasses
import json
import socket
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest
import yaml

from simulator.campaign.plan import plan_campaign
from simulator.campaign.worker import execute_run, flatten_scores
from simulator.cli import main

HOLD = {"name": "tests.campaign_estimators:HoldStart", "label": "hold"}
SHIFTED = {"name": "tests.campaign_estimators:HoldStart", "label": "shifted",
           "init": {"position_error": [3.0, -4.0, 0.0]}}
FAILS = {"name": "tests.campaign_estimators:Fails", "label": "fails"}


def _scenario(tmp_path: Path, estimators: list, name: str = "tiny.yaml") -> Path:
    """A four-second drive (stop, accelerate, straight) with an ideal 50 Hz IMU."""
    data = {
        "name": "tiny", "seed": 3,
        "start": {"utc": "2024-05-01T03:00:00Z", "lat": 37.5, "lon": 127.0, "alt": 40.0,
                  "heading": 30.0},
        "trajectory": {"kind": "segments", "segments": [
            {"stop": {"duration": 1}}, {"accelerate": {"to_speed": 5.0, "accel": 1.5}},
            {"straight": {"duration": 2}}]},
        "sensors": {"imu": {"preset": "ideal", "rate": 50}},
        "estimators": estimators,
    }
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def _runs(out: Path) -> pd.DataFrame:
    return pd.read_parquet(out / "runs.parquet")


def _summary(out: Path) -> dict:
    def refuse(name: str):
        raise AssertionError(f"summary.json holds {name}")
    return json.loads((out / "summary.json").read_text(), parse_constant=refuse)


def _group(summary: dict, label: str, **sweep) -> dict:
    (group,) = [g for g in summary["groups"] if g["label"] == label and g["sweep"] == sweep]
    return group


def _closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def local(tmp_path_factory) -> tuple[Path, Path]:
    """A campaign in local processes: 3 runs from seed 10 x 2 estimators, datasets kept."""
    tmp = tmp_path_factory.mktemp("local")
    scenario = _scenario(tmp, [HOLD, SHIFTED])
    out = tmp / "campaign"
    assert main(["campaign", str(scenario), "--runs", "3", "--seed", "10", "--workers", "2",
                 "--keep-datasets", "-o", str(out)]) == 0
    return scenario, out


def test_local_campaign_rows_seeds_and_summary(local):
    _, out = local
    runs = _runs(out)
    assert list(runs.columns[:4]) == ["run_id", "seed", "label", "status"]
    assert runs.columns[-1] == "error"
    assert runs["run_id"].tolist() == [0, 0, 1, 1, 2, 2]
    assert runs["seed"].tolist() == [10, 10, 11, 11, 12, 12]
    assert runs["label"].tolist() == ["hold", "shifted"] * 3
    assert (runs["status"] == "ok").all() and (runs["error"] == "").all()
    # the kept datasets were generated with those seeds
    for part in sorted((out / "datasets").iterdir()):
        manifest = json.loads((part / "manifest.json").read_text())
        assert manifest["seed"] == 10 + int(part.name.split("-")[-1])
    summary = _summary(out)
    assert summary["runs"] == 3 and summary["base_seed"] == 10 and summary["sweep"] == {}
    for label in ("hold", "shifted"):
        group = _group(summary, label)
        assert (group["runs"], group["ok"], group["failed"]) == (3, 3, 0)
        values = runs.loc[runs["label"] == label, "runtime.seconds"].to_numpy()
        stats = group["scores"]["runtime.seconds"]
        assert stats["mean"] == pytest.approx(values.mean())
        assert stats["median"] == pytest.approx(np.median(values))
        assert min(values) <= stats["p95"] <= max(values) and stats["count"] == 3
    units = {f.name: f.metadata[b"unit"].decode()
             for f in pq.read_schema(out / "runs.parquet")}
    assert (units["horizontal.rms"], units["attitude.yaw_rms"], units["velocity.rms"],
            units["runtime.seconds"], units["coverage.longest_gap"]
            ) == ("m", "deg", "m/s", "s", "s")
    report = (out / "report.md").read_text()
    assert "| hold |" in report and "| shifted |" in report and "No run failed." in report
    assert (out / "plots" / "horizontal_rms.png").stat().st_size > 1000


def test_campaign_scores_equal_those_of_landnav_run(local, tmp_path):
    scenario, out = local
    runs = _runs(out)
    assert main(["run", str(scenario), "--seed", "11", "-o", str(tmp_path / "r")]) == 0
    scores = json.loads((tmp_path / "r" / "scores.json").read_text())
    for label in ("hold", "shifted"):
        row = runs[(runs["seed"] == 11) & (runs["label"] == label)].iloc[0]
        expected = scores[label]
        for group in ("horizontal", "vertical", "velocity", "attitude"):
            for key, value in expected[group].items():
                assert row[f"{group}.{key}"] == pytest.approx(value, rel=1e-12, abs=1e-12)
        # neither estimator uses GNSS: no outage scores, full coverage
        assert expected["outages"] is None and "outages.count" not in row
        assert row["coverage.fraction"] == expected["coverage"]["fraction"] == 1.0
        assert row["runtime.seconds"] > 0
    assert runs.loc[runs["label"] == "shifted", "horizontal.rms"].iloc[0] != pytest.approx(
        runs.loc[runs["label"] == "hold", "horizontal.rms"].iloc[0])


def test_gnss_outage_scores_are_means_over_the_runs_outages(tmp_path):
    scenario = _scenario(tmp_path, ["gnss_only"])
    data = yaml.safe_load(scenario.read_text())
    data["trajectory"]["segments"][2] = {"straight": {"duration": 30}}
    data["sensors"]["gnss"] = {"preset": "automotive", "rate": 1, "outputs": ["fix"]}
    data["faults"] = [{"kind": "gnss_outage", "start": 8, "duration": 6},
                      {"kind": "gnss_outage", "start": 20, "duration": 8}]
    scenario.write_text(yaml.safe_dump(data))
    out = tmp_path / "gnss"
    assert main(["campaign", str(scenario), "--runs", "2", "--workers", "1", "-o",
                 str(out)]) == 0
    runs = _runs(out)
    assert (runs["status"] == "ok").all()
    # the seed draws the GNSS noise: the two runs differ
    assert runs["horizontal.rms"].iloc[0] != pytest.approx(runs["horizontal.rms"].iloc[1])
    assert main(["run", str(scenario), "--seed", "4", "-o", str(tmp_path / "r")]) == 0
    expected = json.loads((tmp_path / "r" / "scores.json").read_text())["gnss_only"]
    row = runs[runs["seed"] == 4].iloc[0]
    assert row["horizontal.rms"] == pytest.approx(expected["horizontal"]["rms"], rel=1e-12)
    outages = expected["outages"]
    assert row["outages.count"] == len(outages) == 2
    # gnss_only stops 2 s after the last fix: silent at both outages' ends, so the run's end
    # error is missing (NaN), never the mean of rows inside the outages
    assert row["outages.missing"] == sum(o["end_horizontal"] is None for o in outages) == 2
    for key in ("max_horizontal", "end_horizontal", "end_percent", "duration", "distance"):
        values = [np.nan if o[key] is None else o[key] for o in outages]
        assert row[f"outages.{key}"] == pytest.approx(np.mean(values), rel=1e-12, nan_ok=True)
    assert np.isnan(row["outages.end_horizontal"])
    # the summary counts both runs as missing the end error, and the report says so
    end = _group(_summary(out), "gnss_only")["scores"]["outages.end_horizontal"]
    assert end == {"mean": None, "median": None, "p95": None, "count": 0, "missing": 2}
    assert "- / - / - (2 missing)" in (out / "report.md").read_text()
    assert (out / "plots" / "outage_end.png").is_file()


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(host="127.0.0.1", n_workers=2, threads_per_worker=1,
                                  processes=True, dashboard_address=None) as c:
        yield c


def test_campaign_on_a_dask_cluster(local, cluster, tmp_path):
    scenario, local_out = local
    out = tmp_path / "dask"
    assert main(["campaign", str(scenario), "--runs", "3", "--seed", "10", "--scheduler",
                 cluster.scheduler_address, "-o", str(out)]) == 0
    runs, expected = _runs(out), _runs(local_out)
    assert runs[["run_id", "seed", "label", "status"]].equals(
        expected[["run_id", "seed", "label", "status"]])
    scores = [c for c in expected.columns if c.startswith(("horizontal.", "attitude."))]
    np.testing.assert_allclose(runs[scores].to_numpy(), expected[scores].to_numpy(), rtol=1e-12)
    assert _group(_summary(out), "hold")["ok"] == 3


def test_sweeps_give_columns_and_per_value_summaries(tmp_path, capsys):
    scenario = _scenario(tmp_path, [HOLD])
    out = tmp_path / "sweep"
    assert main(["campaign", str(scenario), "--runs", "2", "--workers", "1", "--sweep",
                 "sensors.imu.rate=25,50", "-o", str(out)]) == 0
    runs = _runs(out)
    assert runs["sensors.imu.rate"].tolist() == [25, 25, 50, 50]
    assert runs["seed"].tolist() == [3, 4, 3, 4]  # the same seeds at every sweep point
    summary = _summary(out)
    assert summary["sweep"] == {"sensors.imu.rate": [25, 50]}
    for rate in (25, 50):
        group = _group(summary, "hold", **{"sensors.imu.rate": rate})
        assert group["runs"] == 2
        at = runs["sensors.imu.rate"] == rate
        assert group["scores"]["horizontal.rms"]["mean"] == pytest.approx(
            runs.loc[at, "horizontal.rms"].mean())
    # the sweep point is the scenario of landnav run --set
    assert main(["run", str(scenario), "--set", "sensors.imu.rate=25", "-o",
                 str(tmp_path / "r25")]) == 0
    expected = json.loads((tmp_path / "r25" / "scores.json").read_text())["hold"]
    assert runs["horizontal.rms"].iloc[0] == pytest.approx(expected["horizontal"]["rms"])
    assert runs["horizontal.rms"].iloc[0] != pytest.approx(runs["horizontal.rms"].iloc[2])
    assert "sensors.imu.rate" in (out / "report.md").read_text()
    # two sweeps: their cartesian product, the last varying fastest
    out2 = tmp_path / "grid"
    assert main(["campaign", str(scenario), "--runs", "1", "--workers", "1",
                 "--sweep", "sensors.imu.rate=25,50",
                 "--sweep", "trajectory.segments.2.straight.duration=1,2,3", "-o", str(out2)]) == 0
    grid = _runs(out2)
    assert grid["sensors.imu.rate"].tolist() == [25] * 3 + [50] * 3
    assert grid["trajectory.segments.2.straight.duration"].tolist() == [1, 2, 3] * 2
    assert len(_summary(out2)["groups"]) == 6
    assert "6 run(s) x 1 estimator(s): 6 result(s) ok, 0 failed" in capsys.readouterr().out


def test_a_failing_estimator_is_recorded_and_the_others_go_on(tmp_path, capsys):
    scenario = _scenario(tmp_path, [HOLD, FAILS])
    out = tmp_path / "fails"
    assert main(["campaign", str(scenario), "--runs", "2", "--workers", "2", "-o",
                 str(out)]) == 0
    runs = _runs(out)
    hold, fails = runs[runs["label"] == "hold"], runs[runs["label"] == "fails"]
    assert (hold["status"] == "ok").all() and (hold["error"] == "").all()
    assert (fails["status"] == "failed").all() and fails["horizontal.rms"].isna().all()
    for error in fails["error"]:
        assert error.startswith("Traceback") and "RuntimeError: deliberate failure" in error
    summary = _summary(out)
    assert _group(summary, "fails")["failed"] == 2 and _group(summary, "hold")["failed"] == 0
    assert _group(summary, "fails")["scores"]["horizontal.rms"]["count"] == 0
    assert "deliberate failure" in (out / "report.md").read_text()
    printed = capsys.readouterr()  # not a terminal: no bar; progress lines if it took long
    assert all(line.startswith("runs: ") for line in printed.err.splitlines())
    assert len(printed.out.splitlines()) == 1
    assert "2 result(s) ok, 2 failed" in printed.out and str(out) in printed.out
    args = ["campaign", str(scenario), "--runs", "2", "--workers", "2", "-o", str(out)]
    assert main(args) == 0  # a failed run is done ...
    assert "(0 run(s) computed now, 2 already done)" in capsys.readouterr().out
    assert main([*args, "--retry-failed"]) == 0  # ... unless asked to retry it
    assert "(2 run(s) computed now, 0 already done)" in capsys.readouterr().out


def test_a_dying_worker_process_fails_its_run_and_a_new_pool_goes_on(tmp_path):
    crashes = {"name": "tests.campaign_estimators:Crashes", "label": "crashes"}
    out = tmp_path / "crash"
    assert main(["campaign", str(_scenario(tmp_path, [HOLD, crashes])), "--runs", "2",
                 "--workers", "1", "-o", str(out)]) == 0
    runs = _runs(out)
    assert runs["run_id"].tolist() == [0, 0, 1, 1] and (runs["status"] == "failed").all()
    assert runs["error"].str.contains("BrokenProcessPool").all()


def test_resume_computes_only_the_missing_runs(tmp_path, capsys, monkeypatch):
    log = tmp_path / "runs.log"
    counting = {"name": "tests.campaign_estimators:Counting", "label": "count",
                "config": {"log": str(log)}}
    scenario = _scenario(tmp_path, [counting])
    out = tmp_path / "resume"
    args = ["campaign", str(scenario), "--workers", "2", "-o", str(out)]
    assert main([*args, "--runs", "2"]) == 0
    assert len(log.read_text().splitlines()) == 2
    parts = sorted((out / "parts").iterdir())
    stamps = {p.name: p.stat().st_mtime_ns for p in parts}
    assert main([*args, "--runs", "4"]) == 0
    assert len(log.read_text().splitlines()) == 4
    assert {p.name: p.stat().st_mtime_ns for p in parts} == stamps
    assert _runs(out)["seed"].tolist() == [3, 4, 5, 6]
    (out / "parts" / "run-000002.parquet").unlink()
    assert main([*args, "--runs", "4"]) == 0
    assert len(log.read_text().splitlines()) == 5
    assert _runs(out)["run_id"].tolist() == [0, 1, 2, 3]
    assert "1 run(s) computed now, 3 already done" in capsys.readouterr().out
    # another campaign in the same folder is refused, and --force starts over
    assert main([*args, "--runs", "4", "--set", "sensors.imu.rate=25"]) == 2
    assert "another scenario or options" in capsys.readouterr().err
    assert main([*args, "--runs", "1", "--force", "--set", "sensors.imu.rate=25"]) == 0
    assert len(log.read_text().splitlines()) == 6
    assert _runs(out)["run_id"].tolist() == [0]
    assert len(list((out / "parts").iterdir())) == 1

    # an interrupt (Ctrl-C) after the first finished run leaves a folder that resumes
    import simulator.campaign.campaign as campaign_module

    real = campaign_module.write_part

    def interrupt_after_one(*a, **k):
        real(*a, **k)
        raise KeyboardInterrupt

    monkeypatch.setattr(campaign_module, "write_part", interrupt_after_one)
    assert main([*args, "--runs", "3", "--force"]) == 130
    assert len(list((out / "parts").glob("*.parquet"))) == 1 and not (out / "runs.parquet").exists()
    monkeypatch.setattr(campaign_module, "write_part", real)
    assert main([*args, "--runs", "3"]) == 0
    assert _runs(out)["run_id"].tolist() == [0, 1, 2]


def test_a_run_whose_dataset_fails_fails_every_estimator(tmp_path):
    plan = plan_campaign(_scenario(tmp_path, [HOLD, SHIFTED]), [], 7, [])
    (task,) = plan.tasks(1)
    # past validation, without the drive it built: the generator's own build fails in the run
    task = dataclasses.replace(task, scenario=dataclasses.replace(task.scenario, drive=None))
    task.scenario.data["trajectory"]["kind"] = "teleport"
    rows = execute_run(task)
    assert [(r["run_id"], r["seed"], r["label"], r["status"]) for r in rows] == [
        (0, 7, "hold", "failed"), (0, 7, "shifted", "failed")]
    assert all("KeyError: 'teleport'" in r["error"] for r in rows)
    assert not any(k.startswith("horizontal.") for r in rows for k in r)


def test_flatten_scores_means_over_outages_and_counts_the_silent_ones():
    scores = {
        "horizontal": {"rms": 1.0, "mean": None}, "attitude": {"yaw_rms": 0.5},
        "outages": [
            {"start": 10.0, "duration": 20.0, "distance": 0.0, "max_horizontal": 2.0,
             "end_horizontal": 1.0, "end_percent": None,
             "coverage": {"fraction": 1.0, "longest_gap": 0.1}},
            {"start": 50.0, "duration": 40.0, "distance": 100.0, "max_horizontal": 6.0,
             "end_horizontal": 3.0, "end_percent": 3.0,
             "coverage": {"fraction": 0.5, "longest_gap": 20.1}},
            {"start": 99.0, "duration": 30.0, "distance": 200.0, "max_horizontal": 7.0,
             "end_horizontal": None, "end_percent": None,
             "coverage": {"fraction": 0.0, "longest_gap": 30.0}}],
        "nees": {"position": 2.5, "expected": 3.0}, "rows": {"total": 10},
        "consistency": {"position": {"nees": 2.5, "nees_expected": 3.0, "inside_95": 0.9,
                                     "epochs": 100, "nse": {"n": 1.0, "e": 0.5, "d": 1.0}},
                        "velocity": None},
    }
    flat = flatten_scores(scores)
    assert flat["horizontal.rms"] == 1.0 and np.isnan(flat["horizontal.mean"])
    assert flat["outages.count"] == 3 and flat["outages.duration"] == 30.0
    assert flat["outages.max_horizontal"] == 5.0
    # the silent third outage makes the run's mean end error missing, never 2.0 without it
    assert np.isnan(flat["outages.end_horizontal"]) and flat["outages.missing"] == 1
    assert np.isnan(flat["outages.end_percent"])  # the stationary first one is left out
    assert flat["outages.coverage.fraction"] == 0.5
    assert flat["outages.coverage.longest_gap"] == pytest.approx(50.2 / 3)
    assert flat["nees.position"] == 2.5 and flat["consistency.position.nees"] == 2.5
    assert flat["consistency.position.nse.e"] == 0.5
    assert not any(k.startswith("consistency.velocity") for k in flat)  # no such block
    assert not {"nees.expected", "outages.start", "rows.total", "consistency.position.epochs",
                "consistency.position.nees_expected"} & set(flat)
    scores["outages"][2].update(end_horizontal=9.0, end_percent=4.5)
    flat = flatten_scores(scores)
    assert flat["outages.end_horizontal"] == pytest.approx(13.0 / 3)
    assert flat["outages.missing"] == 0
    assert flat["outages.end_percent"] == pytest.approx(3.75)  # over the two that moved


def test_flatten_scores_of_a_list_of_numbers_counts_the_missing_ones():
    flat = flatten_scores({"rtk": {"fix_rate": 0.9, "refix_times": [1.0, None, 3.0]}})
    assert flat["rtk.fix_rate"] == 0.9 and np.isnan(flat["rtk.refix_times"])
    assert flat["rtk.refix_times.count"] == 3 and flat["rtk.refix_times.missing"] == 1
    flat = flatten_scores({"rtk": {"refix_times": [1.0, 3.0]}})
    assert flat["rtk.refix_times"] == 2.0 and flat["rtk.refix_times.missing"] == 0


@pytest.mark.parametrize("extra, message", [
    (["--sweep", "sensors.imu.rat=1,2"], "sensors.imu.rat: unknown key"),
    (["--sweep", "sensors.imu.rate=50,-1"], "--sweep: sensors.imu.rate: -1 must be greater"),
    (["--set", "trajectory.segments.2={turn: {angle: 90, radius: 30}}",
      "--sweep", "trajectory.segments.2.turn.radius=30,1"],
     "--sweep: trajectory.segments.2.turn: the turn asks for 25.00 m/s^2"),
    (["--sweep", "estimators.0.label=a,b"], "may not change the estimators"),
    (["--sweep", "sensors.imu.rate"], "expected KEY.PATH=V1,V2"),
    (["--sweep", "sensors.imu.rate=50,,60"], "empty value"),
    (["--sweep", "seed=1,2"], "the seeds are not swept"),
    (["--sweep", "sensors.imu.rate=25,50", "--set", "sensors.imu.rate=25"], "give each key once"),
    (["--runs", "0"], "--runs: must be between 1 and 1,000,000, got 0"),
    (["--runs", "1000000000000"], "--runs: must be between 1 and 1,000,000"),
    (["--scheduler", "not a url"], "--scheduler: not a url: not a scheduler address"),
    (["--workers", "0"], "--workers: must be at least 1"),
])
def test_bad_input_exits_2_with_one_message(tmp_path, capsys, extra, message):
    out = tmp_path / "out"
    argv = ["campaign", str(_scenario(tmp_path, [HOLD])), "-o", str(out), "--runs", "2", *extra]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not out.exists()


def test_a_folder_that_is_not_a_campaign_is_never_replaced(tmp_path, capsys):
    out = tmp_path / "precious"
    out.mkdir()
    (out / "thesis.tex").write_text("years of work")
    argv = ["campaign", str(_scenario(tmp_path, [HOLD])), "--runs", "1", "-o", str(out)]
    assert main(argv) == 2 and main([*argv, "--force"]) == 2
    assert "not a landnav campaign folder" in capsys.readouterr().err
    assert [p.name for p in out.iterdir()] == ["thesis.tex"]


def test_a_folder_another_campaign_is_writing_is_refused(tmp_path, capsys):
    """While one campaign holds its folder, a second one into it exits 2 naming the holder and
    writes nothing; once the first ends, the folder is free (the lock dies with its holder)."""
    import os

    from simulator.campaign.store import campaign_lock

    out = tmp_path / "busy"
    argv = ["campaign", str(_scenario(tmp_path, [HOLD])), "--runs", "1", "--workers", "1",
            "-o", str(out)]
    with campaign_lock(out):
        assert main(argv) == 2 and main([*argv, "--force"]) == 2
        err = capsys.readouterr().err
        assert f"another landnav campaign (process {os.getpid()})" in err
        assert "Traceback" not in err and not out.exists()
    assert main(argv) == 0
    assert _runs(out)["status"].tolist() == ["ok"]


def test_a_scheduler_that_does_not_answer_exits_2(tmp_path, capsys):
    out = tmp_path / "out"
    address = f"tcp://127.0.0.1:{_closed_port()}"
    assert main(["campaign", str(_scenario(tmp_path, [HOLD])), "--runs", "1", "--scheduler",
                 address, "--scheduler-timeout", "0.5", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert address in err and "nothing answers there" in err and "Traceback" not in err
    assert not out.exists()
