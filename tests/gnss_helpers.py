"""Shared builders for the GNSS tests: short drives (``conftest.build_drive``), receivers, and
the pooled autocorrelation of per-satellite series."""

from __future__ import annotations

import datetime as dt

import numpy as np
from conftest import build_drive

from simulator.schema import Context
from simulator.sensors.gnss import GNSS_FIELD, Gnss
from simulator.trajectory.kinematics import Kinematics

START = {"lat": 37.0, "lon": 127.0, "alt": 40.0, "heading": 0.0}


def drive(segments: list[dict], zones: dict | None = None, start: dict | None = None,
          utc: dt.datetime = dt.datetime(2024, 5, 1, 3, 0), rate_hz: float = 100.0
          ) -> Kinematics:
    """``conftest.build_drive`` with the GNSS tests' start (37 N, 127 E, heading 0) and zones."""
    return build_drive(segments, rate_hz=rate_hz, start=start or START,
                       utc=utc.strftime("%Y-%m-%dT%H:%M:%SZ"), environment={"zones": zones or {}})


def receiver(**config) -> Gnss:
    ctx = Context("test")
    resolved = GNSS_FIELD.check(config, ("sensors", "gnss"), ctx)
    assert not ctx.problems, ctx.problems
    return Gnss(resolved)


def pooled_autocorrelation(wide: np.ndarray, lag: int) -> float:
    """Autocorrelation at ``lag`` samples of series held as the columns of ``wide`` (epochs x
    satellites, NaN where a satellite has no value), pooled over every pair of epochs where both
    values exist: sum x_k x_(k+lag) / sqrt(sum x_k^2 sum x_(k+lag)^2)."""
    a, b = wide[:-lag], wide[lag:]
    both = np.isfinite(a) & np.isfinite(b)
    return float(np.sum(a[both] * b[both]) / np.sqrt(np.sum(a[both] ** 2) * np.sum(b[both] ** 2)))
