"""Park et al. 2019's INS/GPS/odometer EKF (``ins_odo_ekf``) is a working filter: horizontal RMS
under 5 m outside the GNSS outages of an underground-garage drive, on each of ten seeds
(issue 14), and it really uses its aids (the odometer/NHC update bounds the garage error). Two
garages: Park's (``park2019_underground_garage.yaml``, 20 Hz IMU, odometer scale factor 1.03,
shipped with the Park DR estimators) and ``parking_garage.yaml`` (100 Hz IMU)."""

from __future__ import annotations

import numpy as np
import pytest

from simulator.reproduce import park2019
from simulator.reproduce.measures import spread_text as spread
from simulator.reproduce.runner import run_experiment

EXPERIMENTS = [park2019.INS_PARK_GARAGE, park2019.INS_PARKING_GARAGE]
SEEDS = range(1, 11)


@pytest.fixture(scope="module", params=EXPERIMENTS, ids=lambda e: e.scenario)
def runs(request, tmp_path_factory) -> dict[str, np.ndarray]:
    """label -> per seed (horizontal RMS outside the outages, largest error in the garage's
    outage), figures of ``simulator.reproduce.park2019``, full-length drives."""
    # on a rigid body, where the non-holonomic constraint holds exactly (issue 13). With the
    # automotive body the IMU near the centre of gravity slips sideways by up to l_r / R (11 deg
    # in the garage's 8 m turns) and the same filter measured a median horizontal RMS outside
    # the outages of 15.9 m (15.1-17.4) and a median garage maximum of 66.9 m with the NHC
    # against 61.2 m without (parking_garage.yaml): the constraint, violated, no longer helps
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
