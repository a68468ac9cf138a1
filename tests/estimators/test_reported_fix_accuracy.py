"""``ins_lkf`` and Cho's DRM2 filters (default ``tuning: datasheet``) in a street canyon take
the fix's own reported accuracy (``gnss_fix`` ``std_*``, the receiver's least squares with its
reflected signals) as the fix's noise, and so no longer claim a confidence they do not have
there: per axis after the first 60 s, the mean of (error / sigma)^2 (1 for a consistent filter,
from the truth, which the filters never see) stays under 3 over the seeds and under 10 on each.
No lower bound: on the short drive DRM2's position is too cautious (north and east 0.01-0.11 on
seeds 1-2: the DR coasts through the canyon under its chosen process noise, docs/scores.md).

The drive is the unseen canyon of ``benchmarks/consistency/canyon.yaml`` cut short in the
canyon (CI: 35 s of open street, then 700 m between 35 m facades), the whole drive under
``--runslow``. There the reflected fixes sink by 20-50 m with a VDOP of 1.5-2.9 and their
Doppler is off by 0.2-0.6 m/s. Before, with the noise from the DOPs: ``ins_lkf`` followed the
height down under a 3.5 m sigma (down (error / sigma)^2 9.6 and 13.5 on the whole drive's seeds
1 and 2, ``urban_canyon``'s vertical velocity 18); DRM2 took the reflected Doppler at
0.04 m/s per HDOP (EKF north velocity 3.0 and 2.2, SPKF 3.7 and 2.6; ``urban_canyon`` seed
2's north position 24 and 27). On the short drive before (seeds 1 / 2): ``ins_lkf`` down
12.6 / 8.5, DRM2 EKF north velocity 5.8 on seed 1, SPKF 7.8.
"""

from __future__ import annotations

import numpy as np
import pytest

from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import open_dataset
from simulator.pipeline import estimate
from simulator.scenario import load_scenario
from simulator.scoring.consistency import normalised_errors
from tests.conftest import REPO

CANYON = REPO / "benchmarks" / "consistency" / "canyon.yaml"
SHORT = ("[{stop: {duration: 15}}, {accelerate: {to_speed: 10.0, accel: 1.5}}, "
         "{straight: {length: 100}}, {turn: {angle: -90, radius: 20}}, "
         "{straight: {length: 500, zone: midtown}}, "
         "{turn: {angle: 90, radius: 15, zone: midtown}}, "
         "{straight: {length: 200, zone: midtown}}]")
GOAL_MEAN, SEED_CEILING = 3.0, 10.0


def _canyon(folder, seed: int, short: bool):
    overrides = ["sensors.gnss.outputs=[fix]", "estimators=[]"]
    if short:
        overrides.append(f"trajectory.segments={SHORT}")
    sc = load_scenario(CANYON, overrides, seed=seed)
    return open_dataset(generate_dataset(sc, folder / f"canyon{seed}", show_progress=False))


@pytest.fixture(scope="module")
def short_canyons(tmp_path_factory):
    folder = tmp_path_factory.mktemp("canyon")
    return [_canyon(folder, seed, True) for seed in (1, 2)]


@pytest.fixture(scope="module")
def full_canyons(tmp_path_factory):
    folder = tmp_path_factory.mktemp("canyon_full")
    return [_canyon(folder, seed, False) for seed in (1, 2, 3)]


def _assert_axes_consistent(name: str, datasets: list, axes: tuple[str, ...]) -> None:
    per_seed = []
    for ds in datasets:
        nse = normalised_errors(ds.read("truth"), estimate(ds, name)[0])
        per_seed.append([nse[a] for a in axes])
        print(name, ", ".join(f"{a} {nse[a]:.2f}" for a in axes))
    values = np.array(per_seed)
    assert np.isfinite(values).all(), per_seed
    assert values.max() < SEED_CEILING, per_seed
    assert (values.mean(axis=0) < GOAL_MEAN).all(), per_seed


INS_AXES = ("n", "e", "d", "vn", "ve", "vd", "roll", "pitch", "yaw")
DRM2_AXES = ("n", "e", "vn", "ve", "pitch", "yaw")


def test_ins_lkf_knows_its_height_in_a_canyon(short_canyons):
    _assert_axes_consistent("ins_lkf", short_canyons, INS_AXES)


@pytest.mark.parametrize("name", ["dr2d_drm2_ekf", "dr2d_drm2_spkf"])
def test_drm2_knows_its_velocity_in_a_canyon(short_canyons, name):
    _assert_axes_consistent(name, short_canyons, DRM2_AXES)


@pytest.mark.slow
@pytest.mark.parametrize("name, axes", [("ins_lkf", INS_AXES), ("dr2d_drm2_ekf", DRM2_AXES),
                                        ("dr2d_drm2_spkf", DRM2_AXES)])
def test_consistent_on_the_whole_canyon(full_canyons, name, axes):
    _assert_axes_consistent(name, full_canyons, axes)
