"""Faults of the GNSS receiver's outputs.

Kinds here: ``gnss_outage`` (no measurement, no fix), ``gnss_satellite_limit`` (only a few
satellites left, the lowest lost first), ``gnss_multipath`` (large correlated pseudorange errors
on the lowest satellites), ``gnss_fix_jump`` (a position step in the fixes, as in the downtown
data of Park et al. 2019), ``gnss_latency`` (fixes reported late), ``gnss_rate_drop`` (the
receiver outputs fewer epochs). Faults on the measurements recompute the fixes inside their
intervals from the faulted measurements, so a fix degrades exactly as the measurements do.
"""

from __future__ import annotations

import numpy as np

from simulator.earth import geodetic_rates
from simulator.faults.base import fault_kind, in_intervals
from simulator.gnss.fix import receiver_fixes
from simulator.schema import Integer, ListOf, Number, Vector
from simulator.stochastic import gauss_markov

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


@fault_kind("gnss_outage", {}, ("gnss_fix", "gnss_raw"),
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


@fault_kind("gnss_fix_jump", {"offset": Vector(3, Number("m"), doc="north, east, down step, m")},
          ("gnss_fix",), "the position fixes jump by a fixed offset")
def _gnss_fix_jump(streams, intervals, params, context) -> None:
    fix = streams["gnss_fix"]
    mask = in_intervals(fix["t"].to_numpy(), intervals) & (fix["fix"].to_numpy() > 0)
    lat = np.radians(fix.loc[mask, "lat"].to_numpy())
    alt = fix.loc[mask, "alt"].to_numpy()
    d_lat, d_lon, d_alt = geodetic_rates(lat, alt, np.asarray(params["offset"], dtype=float))
    fix.loc[mask, "lat"] = np.degrees(lat + d_lat)
    fix.loc[mask, "lon"] = fix.loc[mask, "lon"].to_numpy() + np.degrees(d_lon)
    fix.loc[mask, "alt"] = alt + d_alt


@fault_kind("gnss_latency", {"latency": Number("s", gt=0, doc="how late the fixes are")},
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


@fault_kind("gnss_rate_drop", {"rate": Number("Hz", gt=0, doc="output rate during the fault")},
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


def _refix(streams, intervals, context) -> None:
    """Recompute the receiver's fixes inside the intervals from the (faulted) measurements, as
    the receiver itself would; fixes outside are untouched."""
    if "gnss_fix" not in streams:
        return
    fix, raw = streams["gnss_fix"], streams["gnss_raw"]
    t = fix["t"].to_numpy()
    mask = in_intervals(t, intervals)
    if not mask.any():
        return
    # solved from the start, so the receiver's history (the height a 2-D fix holds, the
    # smoothing state) is that of the real receiver; only the intervals' rows are written
    upto = t <= t[mask].max()
    gnss = context.sensors.get("gnss") or {}
    new = receiver_fixes(t[upto], raw.loc[raw["t"].to_numpy() <= t[mask].max()],
                         gnss.get("smoothing", 0.0), gnss.get("dop_mask", np.inf), gnss)
    fix.loc[mask, list(new.columns)] = new.to_numpy()[mask[upto]]


def _keys(frame) -> list[str]:
    """The columns naming one measurement: epoch, system (when the stream has several),
    satellite and signal (when it has several)."""
    return [c for c in ("t", "system", "sv", "signal") if c == "t" or c == "sv"
            or c in frame.columns]


def _set_tracked(streams, rows_dropped) -> None:
    """Mark dropped measurements as not tracked in the truth table."""
    if "truth_gnss" not in streams or rows_dropped.empty:
        return
    truth = streams["truth_gnss"]
    key = truth.set_index(_keys(rows_dropped)).index
    dropped = rows_dropped.set_index(_keys(rows_dropped)).index
    truth.loc[key.isin(dropped), "tracked"] = 0


@fault_kind("gnss_satellite_limit", {
    "count": Integer(min=0, doc="healthy satellites kept; the lowest are lost first, and "
                                "unhealthy ones with them"),
    "keep": ListOf(Integer(min=1), None, doc="or: the PRNs kept (the others are lost)"),
}, ("gnss_fix", "gnss_raw"), "only a few satellites left (partial outage, Karamat et al. 2015)")
def _gnss_satellite_limit(streams, intervals, params, context) -> None:
    raw = streams["gnss_raw"]
    inside = in_intervals(raw["t"].to_numpy(), intervals)
    if params["keep"] is not None:
        lost = inside & ~raw["sv"].isin(params["keep"]).to_numpy()
    else:
        # ``count`` usable satellites: an unhealthy one (tracked, never used) is not one of them
        healthy = (raw["health"] == 0).to_numpy() if "health" in raw else np.ones(len(raw), bool)
        elevation = raw["elevation"].where(healthy, -np.inf)
        # a satellite's rank among the epoch's satellites (its signals share its elevation)
        rank = elevation.groupby(raw["t"]).rank(ascending=False, method="dense").to_numpy()
        lost = inside & ((rank > params["count"]) | ~healthy)
    _set_tracked(streams, raw.loc[lost, _keys(raw)])
    streams["gnss_raw"] = raw.loc[~lost].reset_index(drop=True)
    _refix(streams, intervals, context)


@fault_kind("gnss_multipath", {
    "satellites": Integer(2, min=1, doc="how many satellites (the lowest at the start)"),
    "sigma": Number("m", 30.0, gt=0, doc="standard deviation of the multipath error"),
    "correlation_time": Number("s", 5.0, gt=0, doc="its Gauss-Markov correlation time"),
}, ("gnss_fix", "gnss_raw"), "haywire multipath: large correlated pseudorange errors")
def _gnss_multipath(streams, intervals, params, context) -> None:
    import pandas as pd

    raw = streams["gnss_raw"]
    t = raw["t"].to_numpy()
    epochs = np.unique(t)
    dt_s = float(np.min(np.diff(epochs))) if len(epochs) > 1 else 1.0
    error = np.zeros(len(raw))
    satellite = raw[_keys(raw)[1:]].astype(str).agg("".join, axis=1).to_numpy()
    for start, end in intervals:
        inside = (t >= start) & (t < end)
        if not inside.any():
            continue
        first = t[inside].min()
        at_start = raw.loc[inside & (t == first)].sort_values("elevation", kind="stable")
        for sat in satellite[at_start.index.to_numpy()][:params["satellites"]]:
            rows = np.flatnonzero(inside & (satellite == sat))
            steps = np.rint((t[rows] - first) / dt_s).astype(int)
            series = gauss_markov(steps.max() + 1, dt_s, np.array([params["sigma"]]),
                                  params["correlation_time"], context.rng)[:, 0]
            error[rows] = series[steps]
    raw["pseudorange"] = raw["pseudorange"].to_numpy() + error
    if "truth_gnss" in streams:
        truth = streams["truth_gnss"]
        extra = pd.Series(error, index=pd.MultiIndex.from_frame(raw[_keys(raw)]))
        key = pd.MultiIndex.from_frame(truth[_keys(raw)])
        truth["multipath"] = truth["multipath"].to_numpy() + extra.reindex(key).fillna(
            0.0).to_numpy()
    _refix(streams, intervals, context)


GNSS_FAULTS = (_gnss_outage, _gnss_fix_jump, _gnss_latency, _gnss_rate_drop,
               _gnss_satellite_limit, _gnss_multipath)
