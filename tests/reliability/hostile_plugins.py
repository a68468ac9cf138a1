"""Plug-in estimators that misbehave in every way the reliability tests try."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import numpy as np

from estimators.base import Estimator


class _Base(Estimator):
    name = "hostile"
    needs = ("imu",)
    paper = "test double"

    def on_imu(self, t, row):
        self.t = t

    def solution(self, t):
        lat, lon, alt = self.initial.position
        return [np.degrees(lat), np.degrees(lon), alt, *self.initial.velocity,
                *self.initial.attitude]


class RaiseInSetup(_Base):
    def setup(self):
        raise RuntimeError("deliberate setup failure")


class RaiseInHandler(_Base):
    def on_imu(self, t, row):
        if t > 1.0:
            raise ZeroDivisionError("deliberate handler failure")


class WriteToRow(_Base):
    def on_imu(self, t, row):
        row[1] = 0.0


class ReturnDict(_Base):
    def solution(self, t):
        return {"lat": 1.0}


class ReturnShort(_Base):
    def solution(self, t):
        return [1.0, 2.0]


class ReturnStrings(_Base):
    def solution(self, t):
        return ["a"] * 9


class DuplicateColumns(_Base):
    output_columns = (*_Base.output_columns, "yaw")


class NoneDefaults(_Base):
    defaults = None


class CallsExit(_Base):
    def on_imu(self, t, row):
        sys.exit(0)


class AllNan(_Base):
    def solution(self, t):
        return [np.nan] * 9


class OneMegahertz(_Base):
    output_rate_hz = 1e6


class LeavesTheProcess(_Base):
    def on_imu(self, t, row):
        os._exit(0)  # the hostile case itself: the process ends without unwinding


class NeverReturns(_Base):
    def on_imu(self, t, row):
        while True:
            time.sleep(0.01)


class Holds(_Base):
    """A well-behaved plug-in (it holds its initial state), light to import."""


class KillsItsWorker(_Base):
    """With ``config["kill"]``, kills the process it runs in at its first IMU message, as the
    out-of-memory killer would kill a campaign's worker mid-run."""

    defaults = {"kill": False}

    def on_imu(self, t, row):
        if self.config["kill"]:
            os.kill(os.getpid(), signal.SIGKILL)


class LeavesSleepers(_Base):
    """At setup, starts a sleeping process and forks a sleeping copy of itself, both meant to
    outlive it; appends their ids to the file ``config["pids"]``."""

    defaults = {"pids": ""}

    def setup(self):
        sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
        forked = os.fork()
        if forked == 0:
            time.sleep(600)
            os._exit(0)  # the copy never returns into the estimator's caller
        with open(self.config["pids"], "a", encoding="utf-8") as pids:
            pids.write(f"{sleeper.pid} {forked}\n")
