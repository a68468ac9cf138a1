"""``landnav estimators`` and ``landnav estimate`` through ``simulator.cli.main``: the worked
plug-in example by module:Class and by entry point, and each kind of bad input (exit code 2, one
clear message, no traceback)."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

from estimators.registry import get_estimator, list_estimators
from simulator.cli import main
from simulator.dataset.io import open_dataset
from simulator.errors import InputError
from simulator.pipeline import load_scenario
from simulator.replay import read_solution, run_estimator
from tests.scoring_helpers import horizontal_error
from tests.synthetic import write_synthetic

PLUGIN = "examples.my_estimator:MyEstimator"


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    return write_synthetic(tmp_path_factory.mktemp("cli") / "ds", gnss_sigma=2.0)


def _fails(capsys, argv: list[str], message: str) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err, err
    assert "Traceback" not in err


def test_estimators_lists_name_needs_and_paper(capsys):
    assert main(["estimators"]) == 0
    lines = capsys.readouterr().out.splitlines()
    dr = next(line for line in lines if line.startswith("dead_reckoning"))
    assert "needs imu, odometer" in dr and "Groves 2013" in dr
    assert any(line.startswith("gnss_only") and "needs gnss_fix" in line for line in lines)


def test_estimate_writes_a_solution_with_config_and_init(dataset, tmp_path, capsys):
    out = tmp_path / "dr.parquet"
    assert main(["estimate", str(dataset), "-e", "dead_reckoning", "-o", str(out),
                 "--set", "earth_rate=false", "--init", "position_error=[0, 10, 0]"]) == 0
    assert "x real time" in capsys.readouterr().out
    solution = read_solution(out)
    error = horizontal_error(solution, open_dataset(dataset).read("truth"))
    assert error[0] == pytest.approx(10.0, abs=1e-3)


def test_worked_plugin_example_by_module_and_class(dataset, tmp_path):
    """The example DR/GNSS EKF beats both baselines: 0.68 m RMS against 6.7 m (gnss_only, 2 m
    noise held at 10 Hz) and 48 m (dead reckoning with the same 3 deg heading error)."""
    out = tmp_path / "my.parquet"
    assert main(["estimate", str(dataset), "-e", PLUGIN, "-o", str(out),
                 "--init", "heading_error=3", "--set", "gnss_sigma=2.0"]) == 0
    solution = read_solution(out)
    truth = open_dataset(dataset).read("truth")
    rms = np.sqrt(np.mean(horizontal_error(solution, truth) ** 2))
    assert rms < 1.0
    assert {"std_n", "std_e", "std_yaw"} <= set(solution.columns)
    assert solution["std_yaw"].iloc[-1] < np.radians(3.0)


def test_entry_point_registration(tmp_path, monkeypatch):
    """A distribution that declares the entry point (as a third-party pyproject would) is
    found by name, listed, and its failing entry reports the plug-in's own error."""
    dist = tmp_path / "my_landnav_plugin-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: my-landnav-plugin\n"
                                   "Version: 0.1\n")
    (dist / "entry_points.txt").write_text(textwrap.dedent(f"""\
        [landnav.estimators]
        my_filter = {PLUGIN}
        broken_filter = my_missing_package.filters:Filter
        """))
    monkeypatch.syspath_prepend(str(tmp_path))
    assert {"my_filter", "broken_filter"} <= set(list_estimators())
    assert get_estimator("my_filter").name == "my_estimator"
    with pytest.raises(InputError, match="No module named 'my_missing_package'"):
        get_estimator("broken_filter")


def test_unknown_estimator_lists_the_known_ones(dataset, tmp_path, capsys):
    _fails(capsys, ["estimate", str(dataset), "-e", "kalmann", "-o", str(tmp_path / "x")],
           "unknown estimator 'kalmann'; known: gnss_only, dead_reckoning")


def test_plugin_import_failure_shows_its_error(dataset, tmp_path, capsys, monkeypatch):
    (tmp_path / "bad_plugin.py").write_text("import numpy\nraise ImportError("
                                            "'bad_plugin needs libfoo 2.1')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    _fails(capsys, ["estimate", str(dataset), "-e", "bad_plugin:Filter", "-o",
                    str(tmp_path / "x")], "ImportError: bad_plugin needs libfoo 2.1")


def test_not_a_dataset(tmp_path, capsys):
    _fails(capsys, ["estimate", str(tmp_path), "-e", "gnss_only", "-o", str(tmp_path / "x")],
           "not a landnav dataset")


def test_missing_stream(tmp_path, capsys):
    path = write_synthetic(tmp_path / "imu_only", streams=("imu",))
    _fails(capsys, ["estimate", str(path), "-e", "dead_reckoning", "-o", str(tmp_path / "x")],
           "needs the 'odometer' stream")
    assert not (tmp_path / "x").exists()


def test_bad_config_and_init(dataset, tmp_path, capsys):
    _fails(capsys, ["estimate", str(dataset), "-e", "dead_reckoning", "-o",
                    str(tmp_path / "x"), "--set", "nhc=true"],
           "unknown config key(s) nhc for estimator dead_reckoning; known: earth_rate")
    _fails(capsys, ["estimate", str(dataset), "-e", "dead_reckoning", "-o",
                    str(tmp_path / "x"), "--init", "heading_error=north"],
           "estimator.init.heading_error")


def test_scenario_validation_checks_estimator_names(tmp_path):
    """The scenario checks names from the registry's name table (with their line); the
    pipeline's loader then checks each entry against its class (import, config), a
    ``module:Class`` entry only when asked to import plug-ins."""
    scenario = tmp_path / "s.yaml"
    scenario.write_text(textwrap.dedent("""\
        start: {lat: 37.5, lon: 127.0, heading: 0}
        trajectory: {kind: segments, segments: [{stop: {duration: 5}}]}
        estimators:
          - dead_reckoning
          - kalmann
          - {name: gnss_only, label: g, config: {max_extrapolation: fast}}
          - {name: "no_such_module:Filter", label: x}
        """))
    with pytest.raises(InputError) as info:
        load_scenario(scenario)
    text = str(info.value)
    assert "s.yaml:5: estimators.1: unknown estimator 'kalmann'" in text
    assert "dead_reckoning" not in text.split("known:")[0]
    assert "estimators.2" not in text and "estimators.3" not in text  # names that exist
    scenario.write_text(scenario.read_text().replace("  - kalmann\n", ""))
    with pytest.raises(InputError) as info:
        load_scenario(scenario, import_plugins=True)  # a module:Class is imported only so
    text = str(info.value)
    assert "estimators.1.config: config key 'max_extrapolation'" in text
    assert ("estimators.2.name: estimator 'no_such_module:Filter': cannot import module "
            "'no_such_module': ModuleNotFoundError") in text


def test_incomplete_plugin_class_is_refused(dataset, tmp_path, capsys):
    _fails(capsys, ["estimate", str(dataset), "-e", "tests.recording:Mute", "-o",
                    str(tmp_path / "x")], "has no solution(t) method")
    _fails(capsys, ["estimate", str(dataset), "-e", "tests.recording:np", "-o",
                    str(tmp_path / "x")], "is not an estimators.base.Estimator subclass")


def test_generated_dataset_round_trip(tmp_path, capsys):
    """generate -> estimate on a shipped scenario: the estimator gets the IMU the generator
    wrote, and the solution file reads back."""
    from tests.conftest import REPO
    from tests.recording import Recorder
    data = tmp_path / "quick"
    assert main(["generate", str(REPO / "scenarios" / "quickstart.yaml"), "-o", str(data)]) == 0
    out = tmp_path / "rec.parquet"
    assert main(["estimate", str(data), "-e", "tests.recording:Recorder", "-o", str(out)]) == 0
    # the CLI replays a plug-in in a child process: the recorder is inspected from a replay here
    run_estimator(open_dataset(data), "tests.recording:Recorder", show_progress=False)
    imu = open_dataset(data).read("imu").to_numpy(dtype=float)
    seen = np.array([row for stream, _, row in Recorder.last.seen if stream == "imu"])
    np.testing.assert_array_equal(seen, imu)
    # every stream an estimator may see, never the truth, truth_gnss, gnss_nav or events
    assert set(Recorder.last.columns) == {"imu", "odometer", "baro", "gnss_fix", "gnss_raw"}
    assert len(read_solution(out)) == len(Recorder.last.asked)
