"""Park et al. 2019's INS/GPS/odometer EKF (``ins_odo_ekf``) is a working filter: horizontal RMS
under 5 m outside the GNSS outages of an underground-garage drive, on each seed (seeds 1-3; the ten
with ``--runslow``), and it really uses its aids (the odometer/NHC update bounds the garage error).
Two garages: Park's (``park2019_underground_garage.yaml``, 20 Hz IMU, odometer scale factor 1.03,
shipped with the Park DR estimators) and ``parking_garage.yaml`` (100 Hz IMU)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from estimators.base import InitialState
from estimators.builtin import park2019_ins
from estimators.builtin.park2019_ins import ParkInsOdometer
from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import open_dataset
from simulator.errors import InputError
from simulator.replay import run_estimator
from simulator.reproduce import park2019
from simulator.reproduce.measures import spread_text as spread
from simulator.reproduce.runner import run_experiment
from simulator.scenario import Scenario, validate_data
from tests.conftest import seed_sets

pytestmark = pytest.mark.usefixtures("shared_experiments")  # each (experiment, seed) once

EXPERIMENTS = [park2019.INS_PARK_GARAGE, park2019.INS_PARKING_GARAGE]
SEEDS = range(1, 11)


@pytest.fixture(scope="module", params=seed_sets(SEEDS))
def seeds(request) -> range:
    return request.param


@pytest.fixture(scope="module", params=EXPERIMENTS, ids=lambda e: e.scenario)
def runs(request, seeds, tmp_path_factory) -> dict[str, np.ndarray]:
    """label -> per seed (horizontal RMS outside the outages, largest error in the garage's
    outage), figures of ``simulator.reproduce.park2019``, full-length drives."""
    # on the default automotive body: the constraint at the rear axle (from the datasheet's
    # installation geometry), its noise from the bicycle model's tyre slip. Measured, ten seeds:
    # RMS outside the outages median 2.77 m (1.64-3.02) on Park's garage, 3.29 m (2.48-3.85) on
    # parking_garage.yaml; garage maximum with the NHC 20.8 / 21.1 m against 43.9 / 44.6 m
    # without. At the IMU instead (nhc_point: imu), where the car slips sideways by up to 11 deg
    # in the 8 m turns, it is 3.38 / 7.88 m and 72.0 / 48.7 m: the violated constraint hurts
    table = run_experiment(request.param, seeds, tmp_path_factory.mktemp("park"))
    return {label: table[[f"{label}.rms_outside_m", f"{label}.max_horizontal_m"]].to_numpy()
            for label in request.param.entries}


def test_horizontal_rms_outside_outages_is_under_5_m(runs):
    rms = runs["nhc"][:, 0]
    print(f"ins_odo_ekf horizontal RMS outside outages, m: {spread(rms)}")
    assert np.all(rms < 5.0), spread(rms)


def test_nhc_is_used_in_the_garage(runs):
    with_nhc, without = runs["nhc"][:, 1], runs["no_nhc"][:, 1]
    print(f"max garage error, m: with NHC {spread(with_nhc)}, odometer only {spread(without)}")
    assert np.median(with_nhc) < np.median(without)


def test_an_unknown_tuning_is_refused():
    with pytest.raises(InputError, match="tuning must be one of datasheet, paper"):
        ParkInsOdometer({"tuning": "guess"}, None, {}, {})


def test_an_unknown_nhc_point_is_refused():
    with pytest.raises(InputError, match="nhc_point must be one of rear_axle, imu"):
        ParkInsOdometer({"nhc_point": "front_axle"}, None, {}, {})


def test_fix_error_states_take_the_receivers_carrier_smoothing_time():
    """The options beyond the paper's 15 states: three fix-error states with the datasheet's
    carrier-smoothing time (100 s for the automotive receiver), none when the receiver's
    errors are white (``carrier_smoothing: 0``), and the odometer scale factor."""
    initial = InitialState(0.0, np.array([0.6, 2.2, 40.0]), np.zeros(3), np.zeros(3))
    columns = {"imu": {c: i + 1 for i, c in enumerate(
                   ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"))},
               "gnss_fix": {c: i + 1 for i, c in enumerate(
                   ("lat", "lon", "alt", "vn", "ve", "vd", "fix"))},
               "odometer": {"speed": 1}}
    config = {"tuning": "paper", "fix_error_states": True, "odometer_scale_state": True}

    def states(smoothing: float) -> int:
        sheet = {"gnss": {"carrier_smoothing": smoothing}}
        est = ParkInsOdometer(config, initial, columns, {}, imu_output="rate", datasheet=sheet)
        return est.ins.n_states

    assert states(100.0) == 19 and states(0.0) == 16
    paper = {"tuning": "paper"}
    assert ParkInsOdometer(paper, initial, columns, {}, imu_output="rate").ins.n_states == 15
    # the datasheet tuning always carries the fix's correlated error, the reflected fixes'
    # unit states and the odometer scale factor
    assert ParkInsOdometer(None, initial, columns, {}, imu_output="rate").ins.n_states == 22
    # and, with a gyro scale factor in the sheet, the three yaw-response states before them
    sheet = {"imu": {"gyro": {"scale_factor": 0.005, "misalignment": 1e-3}}}
    est = ParkInsOdometer(None, initial, columns, {}, imu_output="rate", datasheet=sheet)
    assert est.ins.n_states == 25 and est.ins.extra_start == 18


def test_the_antenna_lever_arm_is_taken_from_the_datasheet(tmp_path):
    """Error-free IMU, odometer and receiver on a rigid body with the antenna 1.5 m ahead of the
    IMU and 1.2 m above it: the filter that reads the lever arm from the datasheet follows the
    IMU's truth within a decimetre (measured 0.007 m rms); told the antenna sits on the IMU (the
    datasheet's lever arm zeroed), it is pulled towards the antenna (1.39 m rms)."""
    segments = [{"stop": {"duration": 5}}, {"accelerate": {"to_speed": 10.0, "accel": 1.0}},
                {"turn": {"angle": 90, "radius": 40}}, {"straight": {"length": 200}},
                {"turn": {"angle": -90, "radius": 40}}, {"straight": {"length": 200}}]
    data = {"name": "arm", "seed": 1, "vehicle": "rigid",
            "start": {"utc": "2024-05-01T03:00:00Z", "lat": 37.5, "lon": 127.0, "alt": 40.0,
                      "heading": 30.0},
            "trajectory": {"kind": "segments", "segments": segments},
            "sensors": {"imu": {"preset": "ideal", "rate": 100, "output": "increment"},
                        "odometer": {"preset": "ideal", "rate": 10},
                        "gnss": {"preset": "ideal", "rate": 1, "outputs": ["fix"],
                                 "antenna_lever_arm": [1.5, 0.0, -1.2]}}}
    scenario = Scenario(tmp_path / "arm.yaml", validate_data(data, "arm.yaml"), [])
    folder = generate_dataset(scenario, tmp_path / "arm", show_progress=False)
    errors = []
    for zeroed in (False, True):
        if zeroed:
            manifest = json.loads((folder / "manifest.json").read_text())
            manifest["datasheet"]["gnss"]["antenna_lever_arm"] = [0.0, 0.0, 0.0]
            (folder / "manifest.json").write_text(json.dumps(manifest))
        ds = open_dataset(folder)
        solution, _ = run_estimator(ds, "ins_odo_ekf", show_progress=False)
        truth = ds.read("truth")
        t = solution["t"].to_numpy()
        d_n = np.radians(solution["lat"] - np.interp(t, truth["t"], truth["lat"])) * 6.36e6
        d_e = (np.radians(solution["lon"] - np.interp(t, truth["t"], truth["lon"]))
               * 6.39e6 * np.cos(np.radians(37.5)))
        errors.append(float(np.sqrt(np.mean(d_n**2 + d_e**2))))
    print(f"horizontal RMS with the lever arm {errors[0]:.3f} m, without {errors[1]:.3f} m")
    assert errors[0] < 0.1 and errors[1] > 0.5, errors


def test_odometer_period_spaces_the_odometer_updates(tmp_path, monkeypatch):
    """``odometer_period``: with 0 every 10 Hz odometer sample is an update, with 1 s one per
    second (the GPS rate); counted at the odometer measurement model."""
    data = {"name": "odo", "seed": 1, "vehicle": "rigid",
            "start": {"utc": "2024-05-01T03:00:00Z", "lat": 37.5, "lon": 127.0, "alt": 40.0,
                      "heading": 0.0},
            "trajectory": {"kind": "segments", "segments": [
                {"accelerate": {"to_speed": 10.0, "accel": 1.0}}, {"straight": {"length": 200}}]},
            "sensors": {"imu": {"preset": "ideal", "rate": 100},
                        "odometer": {"preset": "ideal", "rate": 10},
                        "gnss": {"preset": "ideal", "rate": 1, "outputs": ["fix"]}}}
    scenario = Scenario(tmp_path / "odo.yaml", validate_data(data, "odo.yaml"), [])
    ds = open_dataset(generate_dataset(scenario, tmp_path / "odo", show_progress=False))
    calls = []
    original = park2019_ins.aiding.odometer

    def counted(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(park2019_ins.aiding, "odometer", counted)
    counts = []
    for period in (0.0, 1.0):
        calls.clear()
        run_estimator(ds, {"name": "ins_odo_ekf", "config": {"tuning": "paper",
                                                              "odometer_period": period}},
                      show_progress=False)
        counts.append(len(calls))
    duration = ds.read("odometer")["t"].iloc[-1] - ds.read("odometer")["t"].iloc[0]
    assert counts[0] == pytest.approx(10 * duration, abs=2)
    assert counts[1] == pytest.approx(duration, abs=2)
