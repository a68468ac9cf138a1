"""``fgo_lc`` and ``fgo_tc``, the GTSAM fixed-lag smoothers, on the quickstart drive: the loosely
coupled one estimates the IMU's turn-on biases (against truth_sensors) and follows the truth; the
tightly coupled one follows the truth and the receiver clock; both know their own error (the
consistency bounds of docs/scores.md)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("gtsam")


@pytest.fixture(scope="module")
def solved(quickstart):
    from simulator import pipeline

    solutions = pipeline.run_estimators(quickstart, ["fgo_lc", "fgo_tc", "gnss_only", "gnss_wls"])
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


def test_follows_the_truth(solved):
    _, _, scores = solved
    assert scores["fgo_lc"]["horizontal"]["rms"] < scores["gnss_only"]["horizontal"]["rms"] + 0.3
    assert scores["fgo_lc"]["attitude"]["yaw_rms"] < 2.0


@pytest.mark.parametrize("label", ["fgo_lc", "fgo_tc"])
def test_knows_its_own_error(solved, label):
    """The consistency bounds of docs/scores.md on this seed: per axis of position, velocity
    and attitude, the mean (error / sigma)^2 after the first 60 s below the per-seed ceiling,
    10; and within the goal, 0.3-3, for the velocity and attitude axes, whose errors change
    sign many times over the drive. A position axis's error is mostly the drive-long range
    error (the fix's, or the pseudoranges'), whose value over one drive is one draw: its mean
    (error / sigma)^2 on one seed is nearly a chi-square of one degree of freedom, below 0.3
    in 42 % of seeds, so the goal is a mean over seeds (docs/fgo.md), not asserted here."""
    from simulator.scoring.consistency import normalised_errors

    dataset, solutions, _ = solved
    nse = normalised_errors(dataset.read("truth"), solutions[label][0])
    for axis, value in nse.items():
        assert 0.0 < value < 10.0, (axis, value)
        if axis not in ("n", "e", "d"):
            assert 0.3 <= value <= 3.0, (axis, value)


def test_tightly_coupled_follows_the_truth_and_the_clock(solved):
    """Horizontally the smoother is, like the snapshot least squares of the same pseudoranges
    (``gnss_wls``, the image of the simulated errors to the millimetre: test_gnss_wls), bound
    to the drive-long range errors no filter of these measurements removes, whose size over
    one drive is one draw (gnss_wls 0.5-2.8 m horizontal RMS over seeds 1-8). So its
    horizontal RMS is compared with gnss_wls's, within twice its own reported horizontal
    1-sigma (the RMS of sqrt(std_n^2 + std_e^2) after 60 s), not with a fixed figure."""
    dataset, solutions, scores = solved
    frame = solutions["fgo_tc"][0]
    spread = float(np.sqrt(np.mean((frame["std_n"] ** 2 + frame["std_e"] ** 2)[
        frame["t"].to_numpy() > 60.0])))
    assert abs(scores["fgo_tc"]["horizontal"]["rms"]
               - scores["gnss_wls"]["horizontal"]["rms"]) < 2.0 * spread
    truth = dataset.read("truth_sensors")
    late = frame["t"].to_numpy() > 60.0
    drift = frame["clock_drift"] - np.interp(frame["t"], truth["t"], truth["clock_drift"])
    bias = frame["clock_bias"] - np.interp(frame["t"], truth["t"], truth["clock_bias"])
    assert abs(np.mean(drift[late])) < 0.2      # m/s, of a drift of 80 m/s
    # the clock takes the ionosphere left after the broadcast model, common to all satellites
    assert abs(np.mean(bias[late])) < 15.0 and np.std(bias[late]) < 3.0
