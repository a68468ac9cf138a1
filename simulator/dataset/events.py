"""The events table (SPEC section 5, ``events.parquet``): every zone and fault actually applied,
and every stretch without any GNSS measurement exactly once as ``gnss_outage``.

Public functions
----------------
zone_events, gnss_outage_intervals, events_table.
"""

from __future__ import annotations

import numpy as np

from simulator import columns as col
from simulator.tables import ColumnTable

_EVENT_TYPES = {"t_start": float, "t_end": float, "kind": str, "detail": str}


def zone_events(zones: list[tuple[float, float, str]]) -> list[dict]:
    """One ``zone`` row per stretch of the drive in a zone: consecutive segments in the same
    zone (a garage of fourteen segments) make one row, so that the stretch is one window."""
    merged: list[list] = []
    for a, b, name in sorted(zones, key=lambda z: z[0]):
        if merged and merged[-1][2] == name and abs(a - merged[-1][1]) < 1e-9:
            merged[-1][1] = b
        else:
            merged.append([a, b, name])
    return [{"t_start": a, "t_end": b, "kind": "zone", "detail": name} for a, b, name in merged]


def gnss_outage_intervals(epoch_t: np.ndarray, has_measurement: np.ndarray,
                          end_t: float) -> list[tuple[float, float]]:
    """Maximal stretches of consecutive GNSS epochs without a single measurement.

    An outage runs from its first empty epoch to the next epoch with measurements (or to the end
    of the drive).
    """
    epoch_t = np.asarray(epoch_t, dtype=float)
    empty = ~np.asarray(has_measurement, dtype=bool)
    if not empty.any():
        return []
    edges = np.diff(np.concatenate([[0], empty.astype(int), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    out = []
    for a, b in zip(starts, stops, strict=True):
        t_end = epoch_t[b] if b < len(epoch_t) else end_t
        out.append((float(epoch_t[a]), float(t_end)))
    return out


def events_table(rows: list[dict]) -> ColumnTable:
    """Events sorted by start time, then kind (rows that tie keep their order), as a column
    table with the SPEC columns."""
    rows = sorted(rows, key=lambda r: (float(r["t_start"]), str(r["kind"])))
    return {name: np.array([_EVENT_TYPES[name](r[name]) for r in rows], dtype=_EVENT_TYPES[name])
            for name in col.EVENTS}
