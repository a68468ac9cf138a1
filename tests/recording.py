"""An estimator for tests that records every message and every solution request it gets."""

from __future__ import annotations

from functools import partialmethod

import numpy as np

from estimators.base import Estimator


class Recorder(Estimator):
    """Takes every stream an estimator may take; remembers what it was handed."""

    name = "recorder"
    needs = ("imu",)
    uses = ("odometer", "baro", "mag", "gnss_fix", "gnss_raw")
    paper = "test double"
    defaults = {"gain": 1.0, "flag": False}

    last: Recorder | None = None  # the latest instance, for the test to inspect

    def setup(self) -> None:
        Recorder.last = self
        self.seen: list[tuple[str, float, np.ndarray]] = []
        self.asked: list[tuple[float, int]] = []

    def _record(self, stream: str, t: float, row: np.ndarray) -> None:
        self.seen.append((stream, t, np.array(row)))

    on_imu = partialmethod(_record, "imu")
    on_odometer = partialmethod(_record, "odometer")
    on_baro = partialmethod(_record, "baro")
    on_mag = partialmethod(_record, "mag")
    on_gnss_fix = partialmethod(_record, "gnss_fix")
    on_gnss_raw = partialmethod(_record, "gnss_raw")

    def solution(self, t):
        self.asked.append((t, len(self.seen)))
        lat, lon, alt = self.initial.position
        return [np.degrees(lat), np.degrees(lon), alt, *self.initial.velocity,
                *self.initial.attitude]


class Peeker(Estimator):
    """Asks for the truth: must be refused."""

    name = "peeker"
    needs = ("truth",)

    def on_truth(self, t, row):
        pass


class Miscounted(Recorder):
    """Returns fewer values than its output columns: a plug-in bug reported clearly."""

    def solution(self, t):
        return [0.0, 0.0, 0.0]


class Mute(Estimator):
    """Takes the IMU but never reports: refused, it has no solution method."""

    name = "mute"
    needs = ("imu",)

    def on_imu(self, t, row):
        pass
