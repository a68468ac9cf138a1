"""``ins_lkf``'s ``tuning: datasheet`` magnetometer heading variance (``_mag_variance``)
against a Monte Carlo of the simulator's own field disturbance (``simulator.stochastic.
gauss_markov``, what ``simulator.sensors.mag`` adds in covered zones): over a minute of
updates at the filter's interval, the heading error's mean has the variance the filter
claims for it, R / N for N updates (the disturbance's white equivalent 2 sigma^2 T / interval),
where the paper's 2 deg claims a hundred times less."""

from __future__ import annotations

import math

import numpy as np

from estimators.base import InitialState
from estimators.builtin.tan2008 import TanLinearisedKF
from simulator import columns as col
from simulator.stochastic import gauss_markov

MICRO_T = 1e-6
SHEET = {"mag": {"disturbance": 10 * MICRO_T, "disturbance_time": 2.0, "noise": 0.3 * MICRO_T,
                 "soft_iron": 0.02}}
B_NED = np.array([20.0, 0.0, 40.0]) * MICRO_T  # a level field of 20 uT horizontal


def _estimator(tuning: str) -> TanLinearisedKF:
    initial = InitialState(0.0, np.radians([45.0, 7.0, 0.0]) * [1, 1, 0], np.zeros(3),
                           np.zeros(3))
    columns = {"imu": {c: i for i, c in enumerate(col.IMU)},
               "gnss_fix": {c: i for i, c in enumerate(col.GNSS_FIX)}}
    units = {"imu": dict(col.IMU), "gnss_fix": dict(col.GNSS_FIX)}
    est = TanLinearisedKF({"tuning": tuning}, initial, columns, units, datasheet=SHEET)
    est._mag.field_ned = B_NED  # as learnt while GPS aided
    return est


def test_the_heading_variance_covers_the_simulated_disturbance():
    est = _estimator("datasheet")
    interval = est.config["update_interval"]
    n_updates, windows = 120, 400  # a minute of updates, 400 independent minutes
    rng = np.random.default_rng(7)
    sheet = SHEET["mag"]
    d = gauss_markov(n_updates * windows, interval, np.full(3, sheet["disturbance"]),
                     sheet["disturbance_time"], rng)
    m = B_NED + d + sheet["noise"] * rng.standard_normal(d.shape)  # level, heading north
    heading_error = -np.arctan2(m[:, 1], m[:, 0])
    means = heading_error.reshape(windows, n_updates).mean(axis=1)
    claimed = float(est._mag_variance()[0, 0]) / n_updates
    ratio = float(np.var(means)) / claimed
    # the Monte Carlo's own spread: the variance of 400 means to 7 % (1 sigma); the window of
    # 30 correlation times shortens the Gauss-Markov mean's variance by about T / W (3 %)
    print(f"variance of the mean over claimed: {ratio:.3f}")
    assert 0.75 < ratio < 1.25, ratio
    paper = float(_estimator("paper")._mag_variance()[0, 0]) / n_updates
    assert float(np.var(means)) > 50 * paper
    assert math.isclose(paper * n_updates, math.radians(2.0) ** 2)
