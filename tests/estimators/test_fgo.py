"""``fgo_lc``, the GTSAM fixed-lag smoother, on the quickstart drive: it estimates the IMU's
turn-on biases (against truth_sensors), follows the truth, and claims position sigmas of the
size of its errors."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("gtsam")


@pytest.fixture(scope="module")
def solved(quickstart):
    from simulator import pipeline

    solutions = pipeline.run_estimators(quickstart, ["fgo_lc", "gnss_only"])
    return quickstart, solutions, pipeline.score(quickstart, solutions).scores()


def test_estimates_the_turn_on_biases(solved):
    dataset, solutions, _ = solved
    frame = solutions["fgo_lc"][0]
    truth = dataset.read("truth_sensors")
    late = frame["t"].to_numpy() > 100.0
    for axis in "xyz":
        true = np.interp(frame["t"], truth["t"], truth[f"gyro_bias_{axis}"])[late]
        assert np.sqrt(np.mean((frame[f"gyro_bias_{axis}"].to_numpy()[late] - true) ** 2)) \
            < np.radians(0.1)  # of turn-on biases up to 1.3 deg/s
        true = np.interp(frame["t"], truth["t"], truth[f"accel_bias_{axis}"])[late]
        assert np.sqrt(np.mean((frame[f"accel_bias_{axis}"].to_numpy()[late] - true) ** 2)) \
            < 0.05  # m/s^2, of turn-on biases up to 1.2 m/s^2


def test_follows_the_truth_with_honest_position_sigmas(solved):
    dataset, solutions, scores = solved
    assert scores["fgo_lc"]["horizontal"]["rms"] < scores["gnss_only"]["horizontal"]["rms"] + 0.3
    assert scores["fgo_lc"]["attitude"]["yaw_rms"] < 2.0
    frame = solutions["fgo_lc"][0]
    truth = dataset.read("truth")
    late = frame["t"].to_numpy() > 60.0
    north = np.radians(frame["lat"] - np.interp(frame["t"], truth["t"], truth["lat"])) * 6.371e6
    down = -(frame["alt"] - np.interp(frame["t"], truth["t"], truth["alt"]))
    for error, sigma in ((north, frame["std_n"]), (down, frame["std_d"])):
        nse = float(np.mean((error.to_numpy()[late] / sigma.to_numpy()[late]) ** 2))
        assert 0.3 < nse < 3.0
