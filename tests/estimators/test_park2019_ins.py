"""Park et al. 2019's INS/GPS/odometer EKF (``ins_odo_ekf``) is a working filter: horizontal RMS
under 5 m outside the GNSS outages of an underground-garage drive, on each of ten seeds
(issue 14), and it really uses its aids (the odometer/NHC update bounds the garage error). Two
garages: Park's (``park2019_underground_garage.yaml``, 20 Hz IMU, odometer scale factor 1.03,
shipped with the Park DR estimators) and ``parking_garage.yaml`` (100 Hz IMU)."""

from __future__ import annotations

import numpy as np
import pytest

from estimators.builtin.park2019_ins import ParkInsOdometer
from simulator.errors import InputError
from simulator.reproduce import park2019
from simulator.reproduce.measures import spread_text as spread
from simulator.reproduce.runner import run_experiment

EXPERIMENTS = [park2019.INS_PARK_GARAGE, park2019.INS_PARKING_GARAGE]
SEEDS = range(1, 11)


@pytest.fixture(scope="module", params=EXPERIMENTS, ids=lambda e: e.scenario)
def runs(request, tmp_path_factory) -> dict[str, np.ndarray]:
    """label -> per seed (horizontal RMS outside the outages, largest error in the garage's
    outage), figures of ``simulator.reproduce.park2019``, full-length drives."""
    # on the default automotive body: the constraint at the rear axle (from the datasheet's
    # installation geometry), its noise from the bicycle model's tyre slip. Measured, ten seeds:
    # RMS outside the outages median 2.77 m (1.64-3.02) on Park's garage, 3.29 m (2.48-3.85) on
    # parking_garage.yaml; garage maximum with the NHC 20.8 / 21.1 m against 43.9 / 44.6 m
    # without. At the IMU instead (nhc_point: imu), where the car slips sideways by up to 11 deg
    # in the 8 m turns, it was 3.83 / 7.56 m and 73.3 / 48.2 m: the violated constraint hurt
    table = run_experiment(request.param, SEEDS, tmp_path_factory.mktemp("park"))
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


def test_an_unknown_nhc_point_is_refused():
    with pytest.raises(InputError, match="nhc_point must be one of rear_axle, imu"):
        ParkInsOdometer({"nhc_point": "front_axle"}, None, {}, {})
