"""The tightly coupled filters with their default (datasheet) tuning know their own error: per
axis of position, velocity and attitude, the mean of (error / sigma)^2 after the first 60 s of
a shipped drive stays below 10 (a consistent filter gives 1; one seed's mean of a constant
error is a chi-square(1) draw, so a single drive may sit well below 1 on an axis), and the
mean over the axes is not that of a filter ten times too cautious (above 0.3). The errors come
from the truth, which the filters never see. Figures over seeds: docs/reproduction_chan.md and
docs/reproduction_karamat2015.md, section "Consistency"."""

from __future__ import annotations

import numpy as np
import pytest

from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import open_dataset
from simulator.replay import run_estimator
from simulator.scenario import load_scenario
from simulator.scoring.align import solution_errors
from tests.conftest import REPO, ci_and_slow

AXES = (("err_n", "std_n"), ("err_e", "std_e"), ("err_d", "std_d"),
        ("err_vn", "std_vn"), ("err_ve", "std_ve"), ("err_vd", "std_vd"),
        ("err_roll", "std_roll"), ("err_pitch", "std_pitch"), ("err_yaw", "std_yaw"))
SETTLE_S = 60.0  # the first minute is left out (convergence from the initial uncertainty)


def _nse(dataset, entry) -> dict[str, float]:
    """Mean (error / sigma)^2 per axis the solution has a sigma for, after ``SETTLE_S``."""
    solution, _ = run_estimator(dataset, entry, show_progress=False)
    e = solution_errors(dataset.read("truth"), solution).errors
    e = e[e["t"] >= e["t"].iloc[0] + SETTLE_S]
    return {err[4:]: float(np.nanmean((e[err] / e[std]) ** 2)) for err, std in AXES
            if std in e}


@pytest.fixture(scope="module")
def canyon(tmp_path_factory):
    """The SUMO city canyon (NLOS ranges of tens of metres), shortened as in CI."""
    sc = load_scenario(REPO / "scenarios" / "sumo_city_canyon.yaml",
                       ["trajectory.max_duration=150"], seed=1)
    return open_dataset(generate_dataset(sc, tmp_path_factory.mktemp("c") / "d",
                                         show_progress=False))


# quickstart: the session's README quickstart drive (tests/conftest.py; tunnel outage, a BMI-class
# IMU with a 1 deg/s turn-on gyro bias and 70 mg accelerometer bias), seed 1


def _assert_consistent(nse: dict[str, float]) -> None:
    assert len(nse) == 9, nse
    assert max(nse.values()) < 10.0, nse
    assert np.mean(list(nse.values())) > 0.3, nse


@pytest.mark.parametrize("drive", ["quickstart", "canyon"])
def test_tc_ekf_is_consistent(drive, request):
    _assert_consistent(_nse(request.getfixturevalue(drive), "tc_ekf"))


# urban_canyon's first 600 m, into the canyon and an underpass (slow), and the CI drive: its
# first 300 m, 200 m of canyon, the underpass
IDEAL_IMU_DRIVES = ci_and_slow("300m", ((300, 200),), ((600, 400),), "600m")


@pytest.mark.parametrize("lengths_m", IDEAL_IMU_DRIVES)
def test_an_ideal_imu_keeps_a_tilt_sigma_as_large_as_its_error(tmp_path, lengths_m):
    """urban_canyon's ``ideal`` IMU (a datasheet of zeros) on the first metres of its drive,
    into the canyon and an underpass: the filter's noise floor (a tactical grade's,
    ``sensor_datasheet``) keeps its roll and pitch sigma at the mechanisation's own error;
    with the datasheet's own noise (the old floors, 1e-10) the roll's mean (error / sigma)^2
    is over 10 (456-522 over three seeds of the whole drive)."""
    open_road_m, canyon_m = lengths_m
    segments = ("[{stop: {duration: 20}}, {accelerate: {to_speed: 12.0, accel: 1.5}}, "
                f"{{straight: {{length: {open_road_m}}}}}, {{turn: {{angle: 90, radius: 30}}}}, "
                f"{{straight: {{length: {canyon_m}, zone: downtown}}}}, "
                "{straight: {length: 60, zone: underpass}}]")
    sc = load_scenario(REPO / "scenarios" / "urban_canyon.yaml",
                       [f"trajectory.segments={segments}"], seed=1)
    data = open_dataset(generate_dataset(sc, tmp_path / "d", show_progress=False))
    nse = _nse(data, "tc_ekf")
    print(f"{open_road_m} m + {canyon_m} m: roll and pitch mean (error / sigma)^2 "
          f"{nse['roll']:.2f}, {nse['pitch']:.2f}", end="")
    assert nse["roll"] < 10.0 and nse["pitch"] < 10.0, nse
    bare = _nse(data, {"name": "tc_ekf", "config": {"gyro_noise": 1e-10, "accel_noise": 1e-9}})
    print(f"; with the datasheet's own noise {bare['roll']:.1f}, {bare['pitch']:.1f}")
    assert bare["roll"] > 10.0, bare


@pytest.mark.slow
@pytest.mark.parametrize("drive", ["quickstart", "canyon"])
def test_tc_ukf_is_consistent(drive, request):
    _assert_consistent(_nse(request.getfixturevalue(drive), "tc_ukf"))


def test_paper_tuning_claims_far_more_than_it_has(quickstart):
    """The reproduction's setting (white pseudoranges, an automotive-grade bias prior on a
    1 deg/s IMU) against the datasheet's: the down axis is 10x over-confident, as measured
    before the datasheet tuning."""
    paper = _nse(quickstart, {"name": "tc_ekf", "config": {"tuning": "paper"}})
    assert paper["d"] > 10.0


def test_karamat_position_is_consistent_in_the_canyon(canyon):
    """riss3d_tc_ekf's datasheet tuning (the yaw's sigma that of the velocity's direction, the
    range rates' side-slip noise, the ionosphere's shared residual as states, the
    pseudoranges' expected NLOS delay taken off) on the canyon's first 150 s, seed 1 (a
    junction turn, a red-light stop, reflected ranges): north and east within the goal of
    docs/scores.md (0.3-3), no axis above 10. Measured: north 0.64, east 0.35, height 1.4
    (7.9 with the reflected delays zero-mean in R and the ionosphere white,
    docs/reproduction_karamat2015.md, "Consistency"), yaw 0.17 (too cautious at the
    stop)."""
    nse = _nse(canyon, "riss3d_tc_ekf")
    assert {"n", "e", "d", "yaw"} <= set(nse)
    assert 0.3 < nse["n"] < 3.0 and 0.3 < nse["e"] < 3.0, nse
    assert max(nse.values()) < 10.0, nse


def test_karamat_heading_is_consistent_on_the_quickstart(quickstart):
    """Through the final stop: the heading reported at a standstill is the last direction of
    travel turned by the azimuth state (it was the azimuth state, tens of degrees off)."""
    nse = _nse(quickstart, "riss3d_tc_ekf")
    assert nse["yaw"] < 10.0 and nse["n"] < 10.0 and nse["e"] < 10.0, nse


def test_karamat_height_is_consistent_on_the_quickstart(quickstart):
    """The height is the integral of v_o sin p (eqs. 6, 9) with p from the forward accelerometer
    (eq. 2) and the quickstart IMU's 70 mg bias: consistent since the vertical-velocity error
    is eq. 6 linearised in the pitch and speed errors (0.24 on seed 1; it was 33 on average
    over seeds 1-5 while v_u was an independent state whose corrections eq. 6 threw away)."""
    assert _nse(quickstart, "riss3d_tc_ekf")["d"] < 10.0
