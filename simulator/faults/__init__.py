"""Faults: transformations of streams and environments over intervals (outages, satellite limits,
multipath, pressure jumps, wheel slip...). Each kind registers its schema in ``FAULT_KINDS``.

Public names
------------
FAULT_KINDS, FAULT_FIELD.
"""

from __future__ import annotations

from simulator.scenario.schema import Record, Tagged

FAULT_KINDS: dict[str, Record] = {}

FAULT_FIELD = Tagged(FAULT_KINDS, what="fault kind")
