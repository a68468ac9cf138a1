"""The built-in filters of Park et al. 2019 with their default ``tuning: datasheet`` know their
own error (docs/scores.md, "Consistency of the built-in filters"): on the quickstart drive,
seeds 1 and 2, per axis of position, velocity and attitude after the first 60 s, the mean of
(error / sigma)^2 stays under 10 on every axis and seed, and its mean over the axes and the two
seeds lies between 0.3 and 3 (1 for a consistent filter); ten seeds under ``--runslow``; the
snapshot ``gnss_wls`` (its position and velocity sigmas) too. Two seeds, since the fix's error
is constant over a drive: one seed's horizontal axis is a chi-square draw of one degree of freedom
(0.01 happens). Measured (mean over the axes, seeds 1 / 2): ins_odo_ekf 0.37 / 0.37, dr3d_ekf
0.27 / 0.48 (the car-body model of its datasheet tuning),
dr2d_odo_ekf 0.25 / 1.25. With ``tuning: paper`` on seed 1: ins_odo_ekf down 11.2,
dr3d_ekf roll 1700 and down 3200 (the white-noise tilt, barometer and fix of the paper's
model)."""

from __future__ import annotations

import numpy as np
import pytest

from simulator.pipeline import estimate, generate, load_scenario
from simulator.reproduce.paper import scenario_path
from simulator.scoring.align import solution_errors

AXES = {"north": ("err_n", "std_n"), "east": ("err_e", "std_e"), "down": ("err_d", "std_d"),
        "v_north": ("err_vn", "std_vn"), "v_east": ("err_ve", "std_ve"),
        "v_down": ("err_vd", "std_vd"), "roll": ("err_roll", "std_roll"),
        "pitch": ("err_pitch", "std_pitch"), "yaw": ("err_yaw", "std_yaw")}
SKIP_S = 60.0
SEEDS = (1, 2)
SEEDS_SLOW = tuple(range(1, 11))


def normalised_squares(dataset, solution) -> dict[str, float]:
    """Per axis the solution has a sigma for, the mean of (error / sigma)^2 over the rows
    after the first 60 s."""
    truth_sensors = dataset.read("truth_sensors") if dataset.has("truth_sensors") else None
    e = solution_errors(dataset.read("truth"), solution, truth_sensors).errors
    e = e[e["t"] >= e["t"].iloc[0] + SKIP_S]
    out = {}
    for axis, (err, std) in AXES.items():
        if std in e:
            x = (e[err] / e[std]).to_numpy(float)
            out[axis] = float(np.mean(x[np.isfinite(x)] ** 2))
    return out


@pytest.fixture(scope="module")
def quickstarts(quickstart, tmp_path_factory):
    """Seed 1 is the session's quickstart dataset (tests/conftest.py), seed 2 generated here."""
    folder = tmp_path_factory.mktemp("qs")
    return [quickstart, *(generate(load_scenario(scenario_path("quickstart.yaml"), seed=seed),
                                   folder / f"qs{seed}") for seed in SEEDS[1:])]


def _assert_consistent(name: str, datasets: list, seeds: tuple[int, ...]) -> None:
    per_seed = [normalised_squares(ds, estimate(ds, name)[0]) for ds in datasets]
    for seed, nse in zip(seeds, per_seed, strict=True):
        print(f"{name} seed {seed} (error/sigma)^2: "
              + ", ".join(f"{k} {v:.2f}" for k, v in nse.items()))
    values = np.array([list(nse.values()) for nse in per_seed])
    assert values.max() < 10.0, per_seed
    assert 0.3 < values.mean() < 3.0, per_seed


@pytest.mark.parametrize("name", ["ins_odo_ekf", "dr3d_ekf", "dr2d_odo_ekf", "gnss_wls"])
def test_datasheet_tuning_is_consistent_on_the_quickstart(quickstarts, name):
    _assert_consistent(name, quickstarts, SEEDS)


@pytest.fixture(scope="module")
def quickstarts_ten(tmp_path_factory):
    folder = tmp_path_factory.mktemp("qs10")
    return [generate(load_scenario(scenario_path("quickstart.yaml"), seed=seed),
                     folder / f"qs{seed}") for seed in SEEDS_SLOW]


@pytest.mark.slow
@pytest.mark.parametrize("name", ["ins_odo_ekf", "dr3d_ekf", "dr2d_odo_ekf", "gnss_wls"])
def test_datasheet_tuning_is_consistent_on_ten_quickstart_seeds(quickstarts_ten, name):
    _assert_consistent(name, quickstarts_ten, SEEDS_SLOW)
