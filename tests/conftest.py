"""Shared test fixtures: the ``../shared`` reference folder, ``--runslow``, the one drive
builder (``build_drive``: segments to truth kinematics, through the scenario and the drive as
``landnav generate`` builds them), and the papers' experiments computed once per session
(``shared_experiments``)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

if TYPE_CHECKING:
    from simulator.trajectory.kinematics import Kinematics

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--runslow", action="store_true", default=False,
                     help="also run the full-length (slow) long-drive cases")


# The modules that cost most in the default run, heaviest first (seconds of one process in
# the whole run on two idle cores, summed from its --durations). Run first, so that under
# ``-n 2 --dist loadscope --no-loadscope-reorder`` (README) each worker starts on a long module
# and the many short ones fill in at the end: a long module started last would leave the other
# worker idle while it runs (xdist's own order, by number of tests, ran the quick
# reproduction's module among the last). The other modules follow in collection order.
HEAVY_MODULES = (
    "tests/reproduce/test_reproduce_cli.py",  # 200: reproduce --quick of every paper
    "tests/test_shipped.py",  # 190: every shipped scenario through landnav run
    "tests/campaign/test_campaign.py",  # 120
    "tests/estimators/test_park2019_dr.py",  # 90
    "tests/estimators/test_karamat2015.py",  # 80
    "tests/estimators/test_chan_claims.py",  # 80
    "tests/estimators/test_rtk_ins.py",  # 55: the short drive on three systems, RTKLIB too
    "tests/reliability/test_campaign_signals.py",  # 55, most of it waiting on signals
    "tests/test_notebooks.py",  # 30
    "tests/estimators/test_park2019_ins.py",  # 25
    "tests/estimators/test_fgo.py",  # 20
    "tests/estimators/test_tan2008.py",  # 15
    "tests/faults/test_faults.py",  # 15
    "tests/test_architecture.py",  # 15
    "tests/commands/test_scoring_cli.py",  # 12
    "tests/reliability/test_dask_limits.py",  # 12
)


def heaviest_first(items: list[pytest.Item]) -> None:
    """``items`` reordered in place: the modules of ``HEAVY_MODULES`` first in its order, then
    the others as collected (a stable sort: each module's tests keep their order)."""
    rank = {module: k for k, module in enumerate(HEAVY_MODULES)}
    items.sort(key=lambda item: rank.get(item.nodeid.split("::", 1)[0], len(rank)))


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    heaviest_first(items)
    if config.getoption("--runslow"):
        return
    skip = pytest.mark.skip(reason="slow long-drive case: run with --runslow")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)


@pytest.fixture
def shared_dir() -> Path:
    """The shared reference-data folder beside the checkout (skips when absent)."""
    if not (SHARED / "refdata").is_dir():
        pytest.skip(f"reference data not available: {SHARED / 'refdata'} is absent "
                    "(a user's clone has no ../shared; CI has it)")
    return SHARED


def scenario_data(segments: list[dict], **extra) -> dict:
    """A resolved scenario for a segment drive (validated like a file)."""
    from simulator.scenario import validate_data

    data = {
        "name": "test",
        "start": {"utc": "2024-05-01T03:00:00Z", "lat": 37.5, "lon": 127.0, "alt": 40.0,
                  "heading": 30.0},
        "trajectory": {"kind": "segments", "segments": segments},
        "sensors": {"imu": {"preset": "ideal", "rate": 100}},
    }
    data.update(extra)
    return validate_data(data, "test.yaml")


def build_drive(segments: list[dict], *, rate_hz: float = 100.0, start: dict | None = None,
                utc: str = "2024-05-01T03:00:00Z", environment: dict | None = None,
                limits: dict | None = None, vehicle: str | dict = "rigid") -> Kinematics:
    """The one way tests build a drive: a segment scenario validated like a file, its drive
    built by ``simulator.drive`` (as ``landnav generate`` does), its truth kinematics returned.
    The body is ``rigid`` unless ``vehicle`` says otherwise: sensor and GNSS models are tested
    on the road's exact motion, the vehicle model in its own tests.
    No sensors, so any truth ``rate_hz`` is accepted; ``start`` (lat, lon in deg, alt in m,
    heading in deg) and ``environment`` replace the validated ones as given, so they may lie
    outside a scenario's limits (the magnetometer's check at 65 km, zones no segment has)."""
    import dataclasses

    from simulator.drive import build_drive as drive_of

    data = scenario_data(segments, sensors={}, trajectory={
        "kind": "segments", "segments": segments, "rate": rate_hz},
        start={"utc": utc, **DEFAULT_START}, vehicle=vehicle,
        **({"limits": limits} if limits is not None else {}))
    drive = drive_of(data)
    return dataclasses.replace(
        drive, start={**drive.start, **(start or {})},
        environment=drive.environment if environment is None else environment).truth


CI_SEEDS = range(1, 4)


def seed_sets(full: range) -> list:
    """A multi-seed claim's seed sets as test parameters: seeds 1-3 in the default run (the
    same property on fewer seeds; a criterion "in 8 of 10 seeds" asks for
    ``needed_count(0.8, 3)`` = 3 of 3), and ``full`` under ``--runslow``."""
    return ci_and_slow(f"{len(CI_SEEDS)}seeds", (CI_SEEDS,), (full,), f"{len(full)}seeds")


def ci_and_slow(name: str, ci: tuple, slow: tuple, slow_name: str) -> list:
    """A long case as two test parameters: its short CI variant ``ci`` in the default run (id
    ``name``) and the long one, ``slow``, with --runslow (id ``slow_name``)."""
    return [pytest.param(*ci, id=name),
            pytest.param(*slow, id=slow_name, marks=pytest.mark.slow)]


DEFAULT_START = {"lat": 37.5, "lon": 127.0, "alt": 40.0, "heading": 30.0}


def ten_minute_drive() -> list[dict]:
    """A ten-minute drive with turns, slopes, a helix, a speed bump and a lane change."""
    return [
        {"stop": {"duration": 20}},
        {"accelerate": {"to_speed": 12.0, "accel": 1.5}},
        {"straight": {"length": 300}},
        {"turn": {"angle": 90, "radius": 25}},
        {"slope": {"grade": 0.08, "length": 200}},
        {"speed_bump": {"height": 0.08, "length": 3.0}},
        {"lane_change": {"offset": 3.5, "length": 60}},
        {"turn": {"angle": -120, "radius": 40, "bank": 3.0}},
        {"straight": {"length": 1000}},
        {"turn": {"angle": 45, "radius": 60, "speed": 10.0}},
        {"straight": {"length": 1000}},
        {"accelerate": {"to_speed": 4.0, "accel": 1.0}},
        {"helix": {"turns": 3, "radius": 11, "rise": -9.0, "direction": "right"}},
        {"straight": {"length": 200, "speed": 8.0}},
        {"slope": {"grade": -0.1, "length": 150}},
        {"turn": {"angle": -45, "radius": 60}},
        {"straight": {"length": 1400}},
        {"accelerate": {"to_speed": 0.0, "accel": 2.0}},
        {"stop": {"duration": 20}},
    ]


@pytest.fixture(scope="session")
def quickstart(tmp_path_factory):
    """The shipped quickstart scenario's dataset (seed 1), generated once per session."""
    from simulator.dataset.generate import generate_dataset
    from simulator.dataset.io import open_dataset
    from simulator.scenario import load_scenario

    out = tmp_path_factory.mktemp("quickstart") / "dataset"
    return open_dataset(generate_dataset(load_scenario(REPO / "scenarios" / "quickstart.yaml"),
                                         out, show_progress=False))


@pytest.fixture(scope="session")
def shared_experiments(tmp_path_factory):
    """The reproduction's ``measure_seed`` computing each (experiment, seed) once in the session,
    and its ``estimate`` each (dataset, estimator entry) once (tests/experiment_cache.py), for
    the claim tests and the quick reproduction alike. Its folder is shared by pytest-xdist's
    workers (the parent of each worker's base folder)."""
    from simulator.reproduce import runner
    from tests.experiment_cache import cached_estimate, cached_measure_seed

    base = tmp_path_factory.getbasetemp()
    folder = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "experiments"
    folder.mkdir(exist_ok=True)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(runner, "measure_seed", cached_measure_seed(folder, runner.measure_seed))
        patch.setattr(runner, "estimate", cached_estimate(folder, runner.estimate))
        yield folder
