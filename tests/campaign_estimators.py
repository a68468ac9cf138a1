"""Test estimators for campaigns and plug-in runs: one that holds its start, one that fails, one
that kills its worker process, one that logs every run it makes. Light to import (numpy and
landnav's estimator base only): each campaign worker and plug-in check imports it afresh."""

from __future__ import annotations

import os
import time

import numpy as np

from estimators.base import Estimator


class HoldStart(Estimator):
    """Test estimator: holds its initial state (the truth perturbed by the scenario's ``init``)
    whatever the IMU says, so its errors are the truth's motion since the start."""

    name = "hold_start"
    needs = ("imu",)
    paper = "test double"

    def on_imu(self, t: float, row: np.ndarray) -> None:
        """Ignore the IMU."""

    def solution(self, t: float) -> list[float]:
        lat, lon, alt = self.initial.position
        return [np.degrees(lat), np.degrees(lon), alt, *self.initial.velocity,
                *self.initial.attitude]


class Fails(HoldStart):
    """Raises on its first IMU message: a failing estimator inside a campaign worker."""

    name = "fails"

    def on_imu(self, t: float, row: np.ndarray) -> None:
        raise RuntimeError(f"deliberate failure at t = {t}")


class Crashes(HoldStart):
    """Ends its process at once, as a crash in compiled code would."""

    name = "crashes"

    def on_imu(self, t: float, row: np.ndarray) -> None:
        os._exit(3)


class Counting(HoldStart):
    """Holds its initial state and appends one line per run to the file ``config["log"]``."""

    name = "counting"
    defaults = {"log": ""}

    def setup(self) -> None:
        with open(self.config["log"], "a", encoding="utf-8") as log:
            log.write(f"{os.getpid()}\n")


class Stuck(HoldStart):
    """Never returns from its first IMU message while the file ``config["stuck_while"]`` exists:
    a worker stuck in an endless loop. Once stuck, it makes the file ``STUCK_WHILE.inside`` (a
    test waits for it, not for a time that assumes an idle machine)."""

    name = "stuck"
    defaults = {"stuck_while": ""}

    def on_imu(self, t: float, row: np.ndarray) -> None:
        flag = self.config["stuck_while"]
        if os.path.exists(flag):
            with open(f"{flag}.inside", "a", encoding="utf-8"):
                pass
        while os.path.exists(flag):
            time.sleep(0.05)
