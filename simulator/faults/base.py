"""What a fault kind is: its parameters (schema) and a transformation of the streams over its
intervals. Faults draw randomness only from their own streams, so everything outside their
intervals stays byte-identical to the clean dataset.

Public names
------------
FaultKind, FaultContext, fault_kind, in_intervals.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from simulator.faults.triggers import TRIGGER_FIELDS
from simulator.schema import Field, Record

if TYPE_CHECKING:
    import pandas as pd


@dataclass
class FaultContext:
    """What a fault may look at besides the streams: the drive, the resolved sensor blocks and
    the fault's own random stream."""

    truth: object  # simulator.trajectory.kinematics.Kinematics
    sensors: dict
    rng: np.random.Generator


# apply(streams, intervals, params, context) changes streams in place; the streams it acts on
# are DataFrames (``apply_faults`` converts column tables before calling it)
Apply = Callable[["dict[str, pd.DataFrame]", list[tuple[float, float]], dict, FaultContext],
                 None]


@dataclass(frozen=True)
class FaultKind:
    name: str
    record: Record
    apply: Apply
    streams: tuple[str, ...]  # streams it acts on (one of them must exist)
    doc: str

    @property
    def changed_streams(self) -> tuple[str, ...]:
        """Every stream ``apply`` may change: those it acts on and, for a fault on the GNSS
        measurements, the GNSS truth table, which records the signals tracked and their true
        errors. A stream is written only once no fault will change it."""
        gnss = any(name.startswith("gnss_") for name in self.streams)
        return self.streams + (("truth_gnss",) if gnss else ())


def fault_kind(name: str, params: dict[str, Field], streams: tuple[str, ...], doc: str
               ) -> Callable[[Apply], FaultKind]:
    """Decorator making a fault kind of its ``apply`` function: its name, parameters (the
    trigger fields added), the streams it acts on and a one-line description (also the
    record's doc, which the scenario reference prints). The kinds are listed by name in
    ``simulator.faults.FAULT_REGISTRY``."""
    def wrap(apply: Apply) -> FaultKind:
        record = Record({**TRIGGER_FIELDS, **params},
                        doc=f"{doc} (acts on: {', '.join(streams)})")
        return FaultKind(name, record, apply, streams, doc)
    return wrap


def in_intervals(t: np.ndarray, intervals: list[tuple[float, float]]) -> np.ndarray:
    """Boolean mask of the times inside any of the half-open intervals [start, end): with the
    intervals sorted by start, ``t`` is inside one exactly when the latest end among those
    starting at or before ``t`` lies after it (one binary search per time, whatever the number
    of intervals)."""
    t = np.asarray(t, dtype=float)
    if not intervals:
        return np.zeros(t.shape, dtype=bool)
    bounds = np.asarray(sorted(intervals), dtype=float)
    latest_end = np.maximum.accumulate(bounds[:, 1])
    k = np.searchsorted(bounds[:, 0], t, side="right") - 1
    return (k >= 0) & (t < latest_end[np.maximum(k, 0)])
