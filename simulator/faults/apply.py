"""Applying a scenario's faults to the generated streams, each with its own random stream, and
the events rows that record them.

Public functions
----------------
fault_rng, apply_faults.
"""

from __future__ import annotations

import json
import zlib

import numpy as np

from simulator.faults import FAULT_REGISTRY
from simulator.faults.base import FaultContext
from simulator.faults.triggers import TRIGGER_FIELDS, fault_intervals
from simulator.tables import Table, as_frame


def fault_rng(seed: int, index: int, kind: str) -> np.random.Generator:
    """The random stream of fault number ``index``: its own SeedSequence child, so a fault never
    changes the draws of a sensor or of another fault."""
    key = zlib.crc32(f"fault/{index}/{kind}".encode())
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(1, key)))


def apply_faults(streams: dict[str, Table], scenario: dict, truth) -> list[dict]:
    """Apply every fault of a resolved scenario in order (in place); return their events rows.

    Each stream a fault acts on is turned into a DataFrame first (``simulator.tables``), so
    pandas is imported only when a fault applies.

    ``gnss_outage`` faults add no row of their own: the events table lists every stretch without
    any GNSS measurement exactly once, whatever caused it.
    """
    rows = []
    for index, fault in enumerate(scenario["faults"]):
        kind = FAULT_REGISTRY[fault["kind"]]
        rng = fault_rng(scenario["seed"], index, fault["kind"])
        intervals = fault_intervals(fault, truth, rng)
        params = {k: v for k, v in fault.items() if k not in TRIGGER_FIELDS and k != "kind"}
        context = FaultContext(truth=truth, sensors=scenario["sensors"], rng=rng)
        if not intervals or not any(name in streams for name in kind.streams):
            continue
        for name in kind.streams:  # faults are written with pandas
            if name in streams:
                streams[name] = as_frame(streams[name])
        kind.apply(streams, intervals, params, context)
        if fault["kind"] != "gnss_outage":
            detail = json.dumps({"fault": index, **params}, sort_keys=True)
            rows += [{"t_start": a, "t_end": b, "kind": fault["kind"], "detail": detail}
                     for a, b in intervals]
    return rows
