"""Every shipped scenario validates and runs end to end (``landnav run``: generation, the
scenario's estimators, scores, report); the code base stays ruff-clean.

Long drives run shortened here with ``--set`` (table below; each scenario's comment says so too)
and whole in ``benchmarks/bench_shipped.py``. The two Chan drives run shortened as
``landnav reproduce --quick`` runs them (whole: 65 s and 23 s of CPU in this test). The drives
whose papers' claims are tested in tests/estimators/ run shorter still in the default run
(``SHORTER_IN_CI``) and as in ``SHORTENED`` with --runslow.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from simulator.cli import main
from simulator.dataset.io import open_dataset
from simulator.pipeline import load_scenario
from simulator.reproduce import park2019, tan2008
from simulator.reproduce.chan import short_complete_overrides as chan_short_complete
from simulator.reproduce.chan import short_partial_overrides as chan_short_partial
from simulator.reproduce.karamat2015 import protocol_overrides as karamat_overrides
from tests.conftest import ci_and_slow

REPO = Path(__file__).resolve().parents[1]
SCENARIOS = sorted((REPO / "scenarios").glob("*.yaml"))

# scenario -> the --set overrides that shorten it for CI (the whole drive in the comment)
SHORTENED: dict[str, list[str]] = {
    "highway_long": ["trajectory.segments.3.repeat.times=1"],  # one lap of six (1 h -> 12.5 min)
    "sumo_city_canyon": ["trajectory.max_duration=150"],  # 150 s after the initial stop (6 min)
    # the first five 60 s windows, one per satellite count (65 s of CPU whole)
    "chan_partial_outages": chan_short_partial(1),
    # the first outage and the loop after it (23 s of CPU whole)
    "chan_complete_outages": chan_short_complete(),
    # two loops of sixteen with the four windows that end in them (2 h 20 min -> 17.5 min)
    "karamat2015_partial_outages": karamat_overrides(2),
    # the whole hour with the real navigation file runs in tests/gnss/test_carrier_twin.py
    # (it needs ../shared); here 300 s on the nominal constellation
    "geonet_baseline_twin": ["trajectory.segments.0.stop.duration=300",
                             "sensors.gnss.constellation=nominal-gps"],
    # the straights 10 x shorter, both tunnels kept (20 min -> 4 min); the 20 minutes run in
    # tests/estimators/test_rtk_ins.py --runslow
    "rtk_open_road": [f"trajectory.segments.{i}.straight.length={n}"
                      for i, n in ((2, 300), (4, 200), (6, 250), (8, 300), (10, 200),
                                   (12, 220))],
    # the 20-minute RTK drives with every straight 300 m (about 4 min; the whole drives run
    # through RTKLIB in tests/gnss/test_rtk_drive.py with --runslow)
    "rtk_open_sky": [f"trajectory.segments.{i}.straight.length=300" for i in (2, 4, 6, 8, 10)],
    "rtk_canyon_tunnel": [f"trajectory.segments.{i}.straight.length=300"
                          for i in (2, 4, 5, 7, 8, 9, 11, 13)],
}



def rtk_open_road_first_tunnel() -> list[str]:
    """``--set`` overrides cutting rtk_open_road to its first tunnel: the start, 300 m, the
    turn, 200 m, the tunnel, 250 m after it, the stop (about 3 min of the 20)."""
    data = yaml.safe_load((REPO / "scenarios" / "rtk_open_road.yaml").read_text())
    segments = data["trajectory"]["segments"]
    kept = segments[:7] + segments[-2:]
    for k, length in ((2, 300), (4, 200), (6, 250)):
        kept[k] = {"straight": {**kept[k]["straight"], "length": length}}
    return [f"trajectory.segments={json.dumps(kept)}"]


# shorter still in the default run, where the papers' claim tests run these drives (with
# --runslow as in SHORTENED): reproduce --quick's cuts, Karamat's first loop, Chan's first
# straight and first double loop with their windows; rtk_open_road, whose RTK claims are tested
# in tests/estimators/test_rtk_ins.py, to its first tunnel (the tunnel zone still passed)
SHORTER_IN_CI: dict[str, list[str]] = {
    "tan2008_outage": list(tan2008.OUTAGE.quick_overrides),
    "park2019_underground_garage": list(park2019.SHORT),
    "karamat2015_partial_outages": karamat_overrides(1),
    "chan_partial_outages": chan_short_partial(1, windows=2),
    "rtk_open_road": rtk_open_road_first_tunnel(),
}

# the runs whose report draws its plots (a 3-D INS/GNSS report with sigma bands, a 2-D filter's,
# an RTK drive's, a garage's windows); the others run with --no-plots (drawing is about a third
# of a short run) and check that their report says so and draws nothing
PLOTTED = {"quickstart", "cho2006_situation1", "rtk_open_sky", "parking_garage"}

# zones a (shortened) run must pass through: the library scenarios are what their comments say
EXPECTED_ZONES: dict[str, set[str]] = {
    "highway_long": {"underpass", "tunnel"},
    "sumo_city_canyon": {"downtown"},
    "rtk_open_road": {"tunnel"},
    "rtk_canyon_tunnel": {"downtown", "tunnel"},
}


def test_shortened_scenarios_exist():
    assert set(SHORTENED) | set(SHORTER_IN_CI) <= {p.stem for p in SCENARIOS}
    assert len(SCENARIOS) >= 15  # issue 16: at least 15 scenarios ship


RUNS = [case for path in SCENARIOS for case in (
    ci_and_slow(path.stem, (path, SHORTER_IN_CI[path.stem]),
                (path, SHORTENED.get(path.stem, [])), f"{path.stem}-longer")
    if path.stem in SHORTER_IN_CI
    else [pytest.param(path, SHORTENED.get(path.stem, []), id=path.stem)])]


@pytest.mark.parametrize(("path", "overrides"), RUNS)
def test_shipped_scenario_runs(path, overrides, tmp_path):
    """Validation, ``landnav run``, every estimator's solution and scores, the report (its
    plots on the runs of ``PLOTTED``), the zones the drive must pass; on the cut of
    ``SHORTER_IN_CI`` where a scenario has one (the same checks; its ``SHORTENED`` cut, id
    ``-longer``, with --runslow)."""
    sets = [arg for override in overrides for arg in ("--set", override)]
    # validated as run: a cut may replace what needs ../shared (geonet_baseline_twin's
    # navigation file), which a user's clone does not have
    assert main(["validate", str(path), *sets]) == 0
    out = tmp_path / "run"
    plotted = path.stem in PLOTTED
    assert main(["run", str(path), "-o", str(out), *sets,
                 *([] if plotted else ["--no-plots"])]) == 0
    ds = open_dataset(out / "dataset")
    truth = ds.read("truth")
    assert truth.t.iloc[-1] == pytest.approx(ds.manifest["duration"], abs=0.02)
    assert EXPECTED_ZONES.get(path.stem, set()) <= set(truth.zone)
    labels = [e if isinstance(e, str) else e["label"] or e["name"]
              for e in ds.manifest["scenario"]["estimators"]]
    scores = json.loads((out / "scores.json").read_text())
    assert sorted(scores) == sorted(labels)
    for label in labels:
        solution = pd.read_parquet(out / "solutions" / f"{label}.parquet")
        assert len(solution) > 0 and np.isfinite(solution["lat"]).any()
        assert np.isfinite(scores[label]["horizontal"]["rms"])
    report = (out / "report.md").read_text()
    assert all(label in report for label in labels)
    if plotted:
        assert not labels or any((out / "plots").glob("*.png"))
    else:
        assert "not drawn" in report and not (out / "plots").exists()
    assert (out / "report.html").is_file()


def test_highway_long_is_an_hour_of_motorway():
    """Whole (validation builds the road profile; nothing is generated): about an hour, 25-33 m/s
    while moving (ramps aside), an overpass in each of the six laps and one tunnel of about 30 s."""
    drive = load_scenario(REPO / "scenarios" / "highway_long.yaml").drive
    assert 3300.0 < drive.duration_s < 3900.0
    t = np.arange(0.0, drive.duration_s, 1.0)
    speed = np.diff(drive.profile.distance_of_time(t))
    moving = speed[speed > 1.0]
    assert moving.max() <= 33.0 + 1e-6
    assert np.mean((moving >= 25.0 - 1e-6) & (moving <= 33.0 + 1e-6)) > 0.95
    zones = [(t0, t1, name) for t0, t1, name in drive.profile.zones]
    assert [name for *_, name in zones].count("underpass") == 6
    tunnels = [t1 - t0 for t0, t1, name in zones if name == "tunnel"]
    assert len(tunnels) == 1 and 25.0 < tunnels[0] < 35.0


def test_ruff_clean():
    ruff = shutil.which("ruff")
    if ruff is None:
        pytest.skip("ruff is not installed (pip install -e '.[test]')")
    result = subprocess.run([ruff, "check", str(REPO)], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout


def test_help_teaches(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert "landnav generate" in out and "validate" in out
    result = subprocess.run([sys.executable, "-m", "simulator.cli", "generate", "--help"],
                            capture_output=True, text=True, cwd=REPO)
    assert "--force" in result.stdout and "--set" in result.stdout


def test_every_scenario_the_readme_docs_and_help_name_exists(capsys):
    """A user copies commands from the README, the docs and ``--help``: every
    ``scenarios/NAME.yaml`` they name must ship (a help example once named a file that did
    not)."""
    import re

    from simulator.commands import SUMMARIES

    texts = [(REPO / "README.md").read_text()]
    texts += [page.read_text() for page in sorted((REPO / "docs").glob("*.md"))]
    for argv in (["--help"], *([command, "--help"] for command in SUMMARIES)):
        with pytest.raises(SystemExit):
            main(argv)
        texts.append(capsys.readouterr().out)
    named = {m for text in texts for m in re.findall(r"scenarios/([\w.-]+\.yaml)", text)}
    assert len(named) >= 10
    missing = sorted(name for name in named if not (REPO / "scenarios" / name).is_file())
    assert not missing, missing


def test_every_file_the_readme_and_docs_point_to_exists():
    """Paths of the repository's own files named in the README, BENCHMARKS.md and the docs
    (``simulator/...py``, ``tests/...py``, ``docs/...``) exist; ``PAPER`` stands for a paper's
    name in docs/reproduction.md."""
    import re

    pattern = (r"\b(?:simulator|estimators|tests|benchmarks|docs|notebooks)/[\w/.-]+"
               r"\.(?:py|md|yaml|png|ipynb|npz)")
    pages = [REPO / "README.md", REPO / "BENCHMARKS.md", *sorted((REPO / "docs").glob("*.md"))]
    named = {m for page in pages for m in re.findall(pattern, page.read_text())}
    assert len(named) >= 50
    missing = sorted(p for p in named if "PAPER" not in p and not (REPO / p).exists())
    assert not missing, missing
