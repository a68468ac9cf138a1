"""Faults of the GNSS receiver's outputs.

Kinds here: ``gnss_outage`` (no measurement, no fix), ``gnss_fix_jump`` (a position step in the
fixes, as in the downtown data of Park et al. 2019), ``gnss_latency`` (fixes reported late),
``gnss_rate_drop`` (the receiver outputs fewer epochs).
"""

from __future__ import annotations

import numpy as np

from simulator.earth import radii_of_curvature
from simulator.faults.base import in_intervals, register
from simulator.scenario.schema import Number, Vector

# fix columns that describe the solution (blanked when there is none, delayed by latency)
FIX_SOLUTION = ("lat", "lon", "alt", "vn", "ve", "vd", "speed", "course", "hdop", "vdop")


def blank_fixes(fix, mask: np.ndarray) -> None:
    """Mark fix rows as 'no fix': fix = 0, no satellites, NaN solution (SPEC section 5)."""
    for name in FIX_SOLUTION:
        if name in fix:
            fix.loc[mask, name] = np.nan
    fix.loc[mask, "fix"] = 0
    if "num_sats" in fix:
        fix.loc[mask, "num_sats"] = 0


@register("gnss_outage", {}, ("gnss_fix", "gnss_raw"),
          "no GNSS measurement and no fix (a blocked sky, an antenna fault)")
def _gnss_outage(streams, intervals, params, context) -> None:
    for name in ("gnss_raw", "truth_gnss"):
        if name in streams:
            frame = streams[name]
            keep = ~in_intervals(frame["t"].to_numpy(), intervals)
            streams[name] = frame.loc[keep].reset_index(drop=True)
    if "gnss_fix" in streams:
        fix = streams["gnss_fix"]
        blank_fixes(fix, in_intervals(fix["t"].to_numpy(), intervals))


@register("gnss_fix_jump", {"offset": Vector(3, Number("m"), doc="north, east, down step, m")},
          ("gnss_fix",), "the position fixes jump by a fixed offset")
def _gnss_fix_jump(streams, intervals, params, context) -> None:
    fix = streams["gnss_fix"]
    mask = in_intervals(fix["t"].to_numpy(), intervals) & (fix["fix"].to_numpy() > 0)
    lat = np.radians(fix.loc[mask, "lat"].to_numpy())
    alt = fix.loc[mask, "alt"].to_numpy()
    rn, re = radii_of_curvature(lat)
    north, east, down = params["offset"]
    fix.loc[mask, "lat"] = np.degrees(lat + north / (rn + alt))
    fix.loc[mask, "lon"] = fix.loc[mask, "lon"].to_numpy() + np.degrees(
        east / ((re + alt) * np.cos(lat)))
    fix.loc[mask, "alt"] = alt - down


@register("gnss_latency", {"latency": Number("s", gt=0, doc="how late the fixes are")},
          ("gnss_fix",), "fixes time-tagged late: each reports the epoch latency earlier")
def _gnss_latency(streams, intervals, params, context) -> None:
    fix = streams["gnss_fix"]
    t = fix["t"].to_numpy()
    mask = in_intervals(t, intervals)
    source = np.searchsorted(t, t[mask] - params["latency"] + 1e-9, side="right") - 1
    valid = source >= 0
    rows = np.flatnonzero(mask)
    columns = [c for c in (*FIX_SOLUTION, "fix", "num_sats") if c in fix]
    original = fix[columns].to_numpy(copy=True)
    fix.loc[fix.index[rows[valid]], columns] = original[source[valid]]
    blank_fixes(fix, np.isin(np.arange(len(fix)), rows[~valid]))


@register("gnss_rate_drop", {"rate": Number("Hz", gt=0, doc="output rate during the fault")},
          ("gnss_fix", "gnss_raw"), "the receiver outputs epochs at a lower rate")
def _gnss_rate_drop(streams, intervals, params, context) -> None:
    period = 1.0 / params["rate"]
    for name in ("gnss_fix", "gnss_raw", "truth_gnss"):
        if name not in streams:
            continue
        frame = streams[name]
        t = frame["t"].to_numpy()
        drop = np.zeros(len(t), dtype=bool)
        for start, end in intervals:
            inside = (t >= start) & (t < end)
            phase = (t - start) / period
            drop |= inside & (np.abs(phase - np.round(phase)) > 1e-6)
        streams[name] = frame.loc[~drop].reset_index(drop=True)
