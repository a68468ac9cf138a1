"""The plots of the scoring report (matplotlib's Agg canvas, no display), one function per PNG.

Every time plot shades the GNSS outages (red) and the degraded windows (orange: satellite
limits, multipath, canyon zones) of the events table.

* ``map``: the truth and every solution on a local map (east, north in m about the first truth
  point), the outages drawn over the truth;
* ``map_windows``: one panel per outage or degraded window (at most ``MAX_WINDOW_PANELS``, the
  longest): the truth during the window and 10 s either side, or, where that path is over
  ``ZOOM_RATIO`` times the largest error in the window, a zoom on the window's end, so that
  metre errors show;
* ``position_errors``: north, east and down errors against time, with the solution's +-3 sigma
  (``std_n, std_e, std_d``) as a band where it has them;
* ``attitude_errors``: roll, pitch and yaw errors (deg), +-3 sigma where ``std_roll...`` exist;
  the legend names every solution (also one without roll, and one without any attitude as
  "not estimated"); the y-range of each error panel
  follows the errors (at most ``BAND_RANGE`` times the largest error), so a huge sigma band
  does not flatten them;
* ``nees``: one panel per consistency block (position, velocity, attitude; horizontal and yaw
  of 2-D solutions), the per-epoch normalised estimation error squared of every solution with
  that block's sigmas, log scale, with the two-sided 95 % band of the chi-square distribution
  of the block's dimension (0.216-9.35 for 3) that a consistent estimator's NEES stays within
  95 % of the time (Bar-Shalom, Li, Kirubarajan 2001, section 5.4.2); the first
  ``CONSISTENCY_SKIP_S`` of each solution, not judged, are shaded grey;
* ``altitude``: the altitude of the truth and of every solution against time (a parking helix
  shows as its staircase of floors);
* ``horizontal_cdf``: the empirical CDF of the horizontal error, logarithmic error axis from
  the smallest 1st percentile of the solutions' errors, but not below ``CDF_FLOOR_M`` (a
  solution equal to the truth has errors of 1e-8 m that say nothing);
* ``gnss_sky`` (datasets with raw GNSS): a sky plot of the tracked satellites' tracks, and the
  number of satellites, HDOP/VDOP and C/N0 against time, every other fault hatched grey; with
  the dataset's ``truth_gnss`` also how many of the tracked signals were NLOS and the C/N0 of
  LOS and NLOS signals apart.

Every series of more than ``THIN_ABOVE_ROWS`` rows is thinned before it is drawn
(``envelope_rows``): in each run of rows that fall in the same half pixel (of time on a time
axis, of the map, of the CDF's two axes) the first and last rows and each series' least and
largest are kept, so every peak, every sigma band's widest and narrowest point and every break
of a line are drawn as they are, at a few thousand points a line instead of every row (the
report of a million-row solution drew every row, 0.56 GB more than scoring it).

Public names
------------
MAX_WINDOW_PANELS, THIN_ABOVE_ROWS, envelope_rows, time_series, map_path, cdf_steps,
shaded_windows, has_std, and one ``plot_<name>(ev, path)`` per PNG.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import FuncFormatter

from simulator.scoring.align import ERR_ATT, ERR_H, ERR_POS, local_ned
from simulator.scoring.consistency import (
    AXES,
    CONSISTENCY_SKIP_S,
    Block,
    block_nees,
    chi2_band,
    consistency_blocks,
)
from simulator.scoring.evaluate import Evaluation
from simulator.scoring.metrics import DEGRADED_KINDS, OUTAGE_KIND, degraded_windows

MAX_WINDOW_PANELS = 6  # zoomed map panels, the longest windows first
NEES_FLOOR = 1e-2  # lower end of the NEES plot's axis
CDF_FLOOR_M = 0.01  # the CDF's error axis never starts below 1 cm
BAND_RANGE = 3.0  # an error panel's y-range shows sigma bands up to this many times the errors
_ERROR_MARGIN = 1.5  # an error panel's y-range is at least this many times the largest error
# a window's panel shows its whole path unless that is over ZOOM_RATIO times the largest error
# in it; then it zooms on the window's end (+-3 times that error, at least 10 m)
ZOOM_RATIO = 20.0
_OUTAGE_COLOUR, _DEGRADED_COLOUR = "tab:red", "tab:orange"
_DPI = 110
_STD_POS, _STD_ATT = ("std_n", "std_e", "std_d"), ("std_roll", "std_pitch", "std_yaw")


THIN_ABOVE_ROWS = 20_000  # a series of at most this many rows (3 min at 100 Hz) is drawn whole
_CELLS_PER_PIXEL = 2  # the thinning's cells: half a pixel of the figure


def envelope_rows(runs: np.ndarray, *series: np.ndarray) -> np.ndarray:
    """The rows of a plotted series worth drawing, in order: every row of a series of at most
    ``THIN_ABOVE_ROWS`` rows; else, of each run of consecutive rows with the same ``runs``
    label (the rows inside one cell of the drawing, half a pixel), its first and last row and
    the rows of each series' least and largest finite value, and every row beside one where a
    series turns NaN or finite (a break of the line). Drawn in row order these rows ink the
    same pixels as every row: the M4 aggregation of Jugel et al. 2014 ("M4: a
    visualization-oriented time series data aggregation", PVLDB 7(10), section 3), cells of
    half a pixel.

    Parameters
    ----------
    runs : shape (n,), a label per row (a run is a stretch of equal consecutive labels).
    series : each shape (n,), the values drawn (NaN where a line breaks).

    Returns
    -------
    Indices of the rows kept, ascending.
    """
    n = len(runs)
    if n <= THIN_ABOVE_ROWS:
        return np.arange(n)
    starts = np.flatnonzero(np.r_[True, runs[1:] != runs[:-1]])
    run = np.repeat(np.arange(starts.size), np.diff(np.r_[starts, n]))
    keep = [starts, np.r_[starts[1:] - 1, n - 1]]
    for values in series:
        finite = np.isfinite(values)
        turns = np.flatnonzero(finite[1:] != finite[:-1])
        keep += [turns, turns + 1]
        for extreme in (np.fmin, np.fmax):  # NaN only where a run has no finite value
            at = np.flatnonzero(values == extreme.reduceat(values, starts)[run])
            keep.append(at[np.diff(run[at], prepend=-1) != 0])  # one row per run
    return np.unique(np.concatenate(keep))


def _pixels(fig: Figure) -> int:
    """Cells across the figure's longer side: ``_CELLS_PER_PIXEL`` per pixel of the PNG."""
    return _CELLS_PER_PIXEL * math.ceil(max(fig.get_size_inches()) * _DPI)


def _new_cell(cells: np.ndarray) -> np.ndarray:
    """Whether each row lies in another cell than the row before (``cells``: shape (n, k),
    the cell's index along each axis of the drawing; rows with a NaN share one cell)."""
    cells = np.where(np.isfinite(cells).all(axis=1, keepdims=True), cells, -np.inf)
    return np.r_[True, (cells[1:] != cells[:-1]).any(axis=1)]


def _thinned(t: np.ndarray, new_cell: np.ndarray, values: list[np.ndarray],
             drawn: list[np.ndarray]) -> list[np.ndarray]:
    """``t`` and ``values`` at the rows ``envelope_rows`` keeps of ``drawn`` in runs of rows
    in one cell (a run begins where ``new_cell``), a run also ending at every gap in ``t``
    (rows more than three output periods apart, median spacing of all rows), where a NaN is
    inserted so that a line is not drawn across a stretch without rows."""
    step = np.diff(t)
    after_gap = np.r_[False, step > 3.0 * np.median(step)]
    rows = envelope_rows(np.cumsum(new_cell | after_gap), *drawn)
    breaks = np.flatnonzero(after_gap[rows])
    return [np.insert(x[rows], breaks, np.nan, axis=0) for x in (t, *values)]


def time_series(fig: Figure, t: np.ndarray, *values: np.ndarray) -> list[np.ndarray]:
    """``t`` and ``values`` (each shape (n,)) as drawn against time in ``fig``: thinned to
    the envelope of each half-pixel time bin (``envelope_rows``) and broken (NaN) where rows
    are missing; a series of up to ``THIN_ABOVE_ROWS`` rows keeps every row."""
    t = np.asarray(t, dtype=float)
    values = [np.asarray(v, dtype=float) for v in values]
    if t.size < 3:
        return [t, *values]
    span = t[-1] - t[0]
    column = np.floor((t - t[0]) * (_pixels(fig) / span)) if span > 0 else np.zeros(t.size)
    return _thinned(t, _new_cell(column[:, None]), values, values)


def map_path(fig: Figure, t: np.ndarray, north_east: np.ndarray,
             view: tuple[float, float, float, float] | None = None) -> np.ndarray:
    """The rows of a path on a local map in ``fig`` to draw (``north_east``: shape (n, k),
    north and east in m in the first two columns, as ``local_ned`` gives them, at times
    ``t``), thinned to the rows that ``envelope_rows`` keeps in runs of squares of half a
    pixel of the ``view`` (east_min, east_max, north_min, north_max; the path's own extent by
    default) and broken (NaN) where rows are missing. The rows outside the view fall in
    eight cells, the regions around it (four half-strips and four quadrants): each is convex,
    so a line between two rows kept in one of them never crosses the view."""
    t = np.asarray(t, dtype=float)
    north_east = np.asarray(north_east, dtype=float)
    if t.size < 3:
        return north_east
    east, north = north_east[:, 1], north_east[:, 0]
    if view is None:
        finite = np.isfinite(east) & np.isfinite(north)
        if not finite.any():
            return _thinned(t, _new_cell(north_east[:, :2]), [north_east], [])[1]
        view = (east[finite].min(), east[finite].max(), north[finite].min(),
                north[finite].max())
    pixels = _pixels(fig)
    cell_m = max(view[1] - view[0], view[3] - view[2], 1e-9) / pixels
    square = np.floor(np.c_[(east - view[0]) / cell_m, (north - view[2]) / cell_m])
    below, above = square < 0, square >= pixels
    outside = (below | above).any(axis=1, keepdims=True)
    # a row outside the view: -1 / pixels below / above it along an axis, -2 within its range
    square = np.where(outside, np.where(below, -1, np.where(above, pixels, -2)), square)
    return _thinned(t, _new_cell(square), [north_east], [east, north])[1]


def cdf_steps(fig: Figure, errors: np.ndarray, left: float, right: float
              ) -> tuple[np.ndarray, np.ndarray]:
    """The empirical CDF of ``errors`` (sorted, finite, positive) as the points of a
    post-step line on a log axis from ``left`` to ``right``: the sorted errors and the
    fraction at or below each, thinned to the first and last point in each half pixel of
    both axes (errors left of the axis share one column)."""
    fraction = np.arange(1, errors.size + 1) / max(errors.size, 1)
    if errors.size <= THIN_ABOVE_ROWS:
        return errors, fraction
    pixels = _pixels(fig)
    row = np.floor(fraction * pixels)
    column = (np.floor(np.log(np.maximum(errors, left) / left) * (pixels / math.log(right / left)))
              if 0 < left < right else np.zeros(errors.size))
    rows = envelope_rows(np.cumsum(_new_cell(np.c_[column, row])))
    return errors[rows], fraction[rows]


def shaded_windows(ev: Evaluation) -> list[tuple[float, float, str]]:
    """(start, end, label) of every outage and degraded window, label ``GNSS outage`` or the
    degraded window's kind."""
    out = ev.events.loc[ev.events["kind"] == OUTAGE_KIND]
    windows = [(a, b, "GNSS outage") for a, b in zip(out["t_start"], out["t_end"], strict=True)]
    deg = degraded_windows(ev.events, ev.canyon_zones)
    windows += list(zip(deg["t_start"], deg["t_end"], deg["label"], strict=True))
    return [(float(a), float(b), str(k)) for a, b, k in windows]


def _shade(ax: Axes, ev: Evaluation, other_faults: bool = False) -> None:
    """Shade the outages and degraded windows; with ``other_faults`` also every other fault
    of the events table (grey, hatched), e.g. a fix jump or latency on a GNSS panel."""
    seen: set[str] = set()
    for a, b, kind in shaded_windows(ev):
        colour = _OUTAGE_COLOUR if kind == "GNSS outage" else _DEGRADED_COLOUR
        ax.axvspan(a, b, color=colour, alpha=0.15, lw=0, label=None if kind in seen else kind)
        seen.add(kind)
    if other_faults:
        shown = {OUTAGE_KIND, "zone", *DEGRADED_KINDS}
        rest = ev.events.loc[~ev.events["kind"].isin(shown)]
        for a, b, kind in zip(rest["t_start"], rest["t_end"], rest["kind"], strict=True):
            ax.axvspan(a, b, facecolor="none", edgecolor="grey", hatch="//", lw=0,
                       label=None if kind in seen else kind)
            seen.add(kind)


def _save(fig: Figure, path: Path) -> None:
    fig.savefig(path, dpi=_DPI)


def _origin(ev: Evaluation) -> tuple[float, float, float]:
    return tuple(float(x) for x in ev.truth[["lat", "lon", "alt"]].iloc[0])


def plot_map(ev: Evaluation, path: Path) -> None:
    truth = ev.truth
    origin = _origin(ev)
    ned = local_ned(truth, origin)
    fig = Figure(figsize=(7, 6), layout="constrained")
    ax = fig.add_subplot()
    t = truth["t"].to_numpy(float)
    line = map_path(fig, t, ned)
    ax.plot(line[:, 1], line[:, 0], color="black", lw=2.0, label="truth")
    for i, (a, b, kind) in enumerate(w for w in shaded_windows(ev) if w[2] == "GNSS outage"):
        inside = (t >= a) & (t <= b)
        line = map_path(fig, t[inside], ned[inside])
        ax.plot(line[:, 1], line[:, 0], color=_OUTAGE_COLOUR, lw=5.0, alpha=0.5,
                label=kind if i == 0 else None)
    for label, r in ev.results.items():
        sol = map_path(fig, r.solution["t"], local_ned(r.solution, origin))
        ax.plot(sol[:, 1], sol[:, 0], lw=1.0, label=label)
    ax.set(xlabel="east (m)", ylabel="north (m)", title="trajectories on a local map")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(loc="best", fontsize="small")
    _save(fig, path)


def plot_map_windows(ev: Evaluation, path: Path) -> None:
    windows = sorted(shaded_windows(ev), key=lambda w: w[0] - w[1])[:MAX_WINDOW_PANELS]
    windows.sort()
    n = len(windows)
    cols = min(n, 3)
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(4.2 * cols, 4.0 * rows), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    origin = _origin(ev)
    truth_t = ev.truth["t"].to_numpy()
    truth_ned = local_ned(ev.truth, origin)
    for ax, (a, b, kind) in zip(axes, windows, strict=False):
        span = (truth_t >= a - 10.0) & (truth_t <= b + 10.0)
        inside = (truth_t >= a) & (truth_t <= b)
        east, north = truth_ned[span, 1], truth_ned[span, 0]
        extent = max(np.ptp(east), np.ptp(north))
        worst = _worst_error(ev, a, b)
        title = f"{kind} {a:.0f}-{b:.0f} s"
        if extent > ZOOM_RATIO * max(worst, 1.0):  # the errors would not show: zoom on the end
            half = max(10.0, 3.0 * worst)
            centre = [np.interp(b, truth_t, truth_ned[:, i]) for i in (1, 0)]
            title += ", its end"
        else:  # a square around the window's path
            half = 0.5 * extent + 10.0 + 0.1 * extent
            centre = [0.5 * (east.min() + east.max()), 0.5 * (north.min() + north.max())]
        view = (centre[0] - half, centre[0] + half, centre[1] - half, centre[1] + half)
        line = map_path(fig, truth_t[span], truth_ned[span], view)
        ax.plot(line[:, 1], line[:, 0], color="black", lw=2.0, label="truth")
        colour = _OUTAGE_COLOUR if kind == "GNSS outage" else _DEGRADED_COLOUR
        line = map_path(fig, truth_t[inside], truth_ned[inside], view)
        ax.plot(line[:, 1], line[:, 0], color=colour, lw=5.0, alpha=0.4, label=kind)
        for label, r in ev.results.items():
            st = r.solution["t"].to_numpy()
            rows_in = (st >= a - 10.0) & (st <= b + 10.0)
            if rows_in.any():
                sol = map_path(fig, st[rows_in], local_ned(r.solution.loc[rows_in], origin),
                               view)
                ax.plot(sol[:, 1], sol[:, 0], lw=1.0, marker=".", ms=2, label=label)
        ax.set_xlim(view[0], view[1])
        ax.set_ylim(view[2], view[3])
        ax.set_aspect("equal", adjustable="box")
        ax.set(xlabel="east (m)", ylabel="north (m)", title=title)
        ax.legend(loc="best", fontsize="x-small")
    for ax in axes[n:]:
        ax.set_visible(False)
    _save(fig, path)


def _worst_error(ev: Evaluation, a: float, b: float) -> float:
    """The largest horizontal error of any solution in [a, b) (0 without rows)."""
    worst = 0.0
    for r in ev.results.values():
        e = r.errors.errors
        h = e[ERR_H].to_numpy(float)[(e["t"] >= a) & (e["t"] < b)]
        h = h[np.isfinite(h)]
        if h.size:
            worst = max(worst, float(h.max()))
    return worst


def _y_limit(errors: list[np.ndarray], bands: list[np.ndarray]) -> float | None:
    """Half the y-range of an error panel: ``_ERROR_MARGIN`` times the largest error, or the
    largest band if wider, but never over ``BAND_RANGE`` times the largest error (None without
    a non-zero error)."""
    largest = max((float(np.nanmax(np.abs(e))) for e in errors if np.isfinite(e).any()),
                  default=0.0)
    if largest <= 0:
        return None
    band = max((float(np.nanmax(b)) for b in bands if np.isfinite(b).any()), default=0.0)
    return min(max(_ERROR_MARGIN * largest, band), BAND_RANGE * largest)


def _error_panels(ev: Evaluation, path: Path, names: tuple[str, ...], stds: tuple[str, ...],
                  titles: tuple[str, ...], scale: float, unit: str, heading: str) -> None:
    fig = Figure(figsize=(9, 7.5), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    colours = {label: f"C{i}" for i, label in enumerate(ev.results)}
    legend: dict[str, object] = {}  # label -> handle, over every panel
    for ax, name, std, title in zip(axes, names, stds, titles, strict=True):
        _shade(ax, ev)
        drawn, bands = [], []
        for label, r in ev.results.items():
            e = r.errors.errors
            sigma = e[std].to_numpy(float) if std in e else np.full(len(e), np.nan)
            t, value, sigma = time_series(fig, e["t"], scale * e[name].to_numpy(float), sigma)
            if not np.isfinite(value).any():
                continue
            drawn.append(value)
            ax.plot(t, value, lw=1.0, color=colours[label], label=label)
            if np.isfinite(sigma).any():
                bound = 3.0 * scale * sigma
                bands.append(bound)
                ax.fill_between(t, -bound, bound, color=colours[label], alpha=0.15, lw=0,
                                label=f"{label} ±3σ")
        limit = _y_limit(drawn, bands)
        if limit is not None:
            ax.set_ylim(-limit, limit)
        handles, labels = ax.get_legend_handles_labels()
        for handle, label in zip(handles, labels, strict=True):
            legend.setdefault(label, handle)
        ax.set(ylabel=f"{title} ({unit})")
        ax.grid(alpha=0.3)
    for label in ev.results:  # a solution with none of the axes is named as such
        if label not in legend:
            legend[f"{label}: not estimated"] = Line2D([], [], color=colours[label], ls=":")
    axes[0].set_title(heading)
    if legend:  # nothing to list when no solution has any of the axes
        axes[0].legend(list(legend.values()), list(legend), loc="upper left", fontsize="x-small",
                       ncol=3)
    axes[-1].set_xlabel("t (s)")
    _save(fig, path)


def plot_position_errors(ev: Evaluation, path: Path) -> None:
    _error_panels(ev, path, ERR_POS, _STD_POS, ("north error", "east error", "down error"), 1.0,
                  "m", "position errors (solution - truth), ±3σ of the solution where given")


def plot_attitude_errors(ev: Evaluation, path: Path) -> None:
    _error_panels(ev, path, ERR_ATT, _STD_ATT, ("roll error", "pitch error", "yaw error"),
                  180.0 / math.pi, "deg", "attitude errors (solution - truth), ±3σ where given")


def _nees_blocks(ev: Evaluation) -> dict[str, tuple[Block, list[str]]]:
    """Block name -> (block, labels of the solutions with an NEES of it), in block order."""
    out: dict[str, tuple[Block, list[str]]] = {}
    for label, r in ev.results.items():
        e = r.errors.errors
        for block in consistency_blocks(e):
            if np.isfinite(block_nees(e, block)).any():
                out.setdefault(block.name, (block, []))[1].append(label)
    order = ("position", "horizontal", "velocity", "horizontal_velocity", "attitude", "yaw",
             *(axis for axis in AXES if axis != "yaw"))
    return {name: out[name] for name in order if name in out}


def has_std(ev: Evaluation) -> bool:
    """Whether any solution has the sigmas of a consistency block (a NEES plot)."""
    return bool(_nees_blocks(ev))


def plot_nees(ev: Evaluation, path: Path) -> None:
    blocks = _nees_blocks(ev)
    fig = Figure(figsize=(10, 2.4 + 2.2 * len(blocks)), layout="constrained")
    axes = np.atleast_1d(fig.subplots(len(blocks), 1, sharex=True, squeeze=False)).ravel()
    colours = {label: f"C{i}" for i, label in enumerate(ev.results)}
    for ax, (block, labels) in zip(axes, blocks.values(), strict=True):
        _shade(ax, ev)
        low, high = chi2_band(block.dim)
        ax.axhspan(low, high, color="tab:green", alpha=0.12, lw=0,
                   label=f"95 % chi-square band, {block.dim} dof")
        for label in labels:
            e = ev.results[label].errors.errors
            ax.plot(*time_series(fig, e["t"], block_nees(e, block)), lw=0.8,
                    color=colours[label], label=label)
            t0 = float(e["t"].iloc[0])
            ax.axvspan(t0, t0 + CONSISTENCY_SKIP_S, color="grey", alpha=0.08, lw=0)
        ax.axhline(block.dim, color="black", ls=":", lw=1.0)
        ax.set_yscale("log")
        # an estimator started from the truth has NEES near 0 at first: the axis starts at 1e-2
        ax.set_ylim(bottom=NEES_FLOOR)
        ax.set(ylabel=f"{block.name} NEES")
        ax.set_title(f"{block.name} ({', '.join(block.axes)}): band {low:.3g} - {high:.3g}, "
                     f"expected {block.dim} (dotted)", fontsize="small")
        ax.grid(alpha=0.3, which="both")
        ax.legend(loc="upper left", fontsize="x-small", ncol=4)
    fig.suptitle(f"NEES per epoch, log scale; grey: each solution's first "
                            f"{CONSISTENCY_SKIP_S:g} s, not judged")
    axes[-1].set_xlabel("t (s)")
    _save(fig, path)


def plot_altitude(ev: Evaluation, path: Path) -> None:
    fig = Figure(figsize=(9, 4), layout="constrained")
    ax = fig.add_subplot()
    _shade(ax, ev)
    ax.plot(*time_series(fig, ev.truth["t"], ev.truth["alt"]), color="black", lw=2.0,
            label="truth")
    for label, r in ev.results.items():
        ax.plot(*time_series(fig, r.solution["t"], r.solution["alt"]), lw=1.0, label=label)
    ax.set(xlabel="t (s)", ylabel="altitude (m, ellipsoidal)", title="altitude")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    _save(fig, path)


def plot_horizontal_cdf(ev: Evaluation, path: Path) -> None:
    fig = Figure(figsize=(6.5, 4), layout="constrained")
    ax = fig.add_subplot()
    errors = {}
    for label, r in ev.results.items():
        h = np.sort(r.errors.errors[ERR_H].to_numpy(float))
        errors[label] = h[np.isfinite(h) & (h > 0)]
    drawn = [h for h in errors.values() if h.size]
    smallest = min((float(h[0]) for h in drawn), default=CDF_FLOOR_M)
    largest = max((float(h[-1]) for h in drawn), default=0.0)
    left = max(CDF_FLOOR_M, min((float(np.percentile(h, 1.0)) for h in drawn),
                                default=CDF_FLOOR_M))
    # (a solution on the truth to 1 cm keeps the automatic axis, from the smallest error)
    view = (left, largest) if left < largest else (smallest, largest)
    for label, h in errors.items():
        ax.step(*cdf_steps(fig, h, *view), where="post", label=label)
    ax.set_xscale("log")
    if left < largest:
        ax.set_xlim(left=left)
    # plain numbers, the minor ticks labelled at 2 and 5 only (they overlap otherwise)
    ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:g}"))
    ax.xaxis.set_minor_formatter(FuncFormatter(
        lambda x, _: f"{x:g}" if f"{x:.0e}"[0] in "25" else ""))
    ax.set(xlabel="horizontal error (m, log scale)", ylabel="fraction of epochs",
           ylim=(0, 1.02), title="CDF of horizontal error")
    ax.grid(alpha=0.3, which="both")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="lower right", fontsize="small")
    _save(fig, path)


def plot_gnss_sky(ev: Evaluation, path: Path, raw: pd.DataFrame,
                  fix: pd.DataFrame | None) -> None:
    fig = Figure(figsize=(11, 7.5), layout="constrained")
    grid = fig.add_gridspec(3, 2, width_ratios=(1, 1.6))
    sky = fig.add_subplot(grid[:, 0], projection="polar")
    sky.set_theta_zero_location("N")
    sky.set_theta_direction(-1)
    for sv, track in raw.groupby("sv"):
        sky.plot(track["azimuth"], 90.0 - np.degrees(track["elevation"]), ".", ms=1.5)
        last = track.iloc[-1]
        sky.annotate(f"G{int(sv):02d}", (last["azimuth"], 90.0 - math.degrees(last["elevation"])),
                     fontsize="x-small")
    sky.set_rlim(0, 90)
    sky.set_yticks([0, 30, 60, 90], labels=["90", "60", "30", "0"])
    sky.set_title("sky plot of tracked satellites (elevation deg)")
    count, dop, cn0 = (fig.add_subplot(grid[i, 1]) for i in range(3))
    per_epoch = raw.groupby("t")["sv"].count()
    epochs = fix["t"] if fix is not None else per_epoch.index
    tracked = per_epoch.reindex(epochs, fill_value=0)
    count.step(tracked.index, tracked.to_numpy(), where="post", label="tracked")
    if fix is not None:
        count.step(fix["t"], fix["num_sats"], where="post", label="used in the fix")
    if "nlos" in raw:  # the truth says which signals arrived without line of sight
        nlos = raw.groupby("t")["nlos"].sum().reindex(epochs, fill_value=0)
        count.step(nlos.index, nlos.to_numpy(), where="post", label="of them NLOS (truth)")
    if fix is not None:
        dop.plot(fix["t"], fix["hdop"], lw=1.0, label="HDOP")
        dop.plot(fix["t"], fix["vdop"], lw=1.0, label="VDOP")
        dop.set_yscale("log")
        dop.legend(loc="upper left", fontsize="x-small")
    if "nlos" in raw:
        for flag, label in ((0, "line of sight"), (1, "NLOS (truth)")):
            part = raw[raw["nlos"] == flag]
            cn0.scatter(part["t"], part["cn0"], s=1, label=label)
        cn0.legend(loc="lower left", fontsize="x-small", markerscale=4)
    else:
        cn0.scatter(raw["t"], raw["cn0"], s=1, c=raw["sv"], cmap="tab20")
    for ax, label in ((count, "satellites"), (dop, "DOP"), (cn0, "C/N0 (dB-Hz)")):
        _shade(ax, ev, other_faults=True)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    count.legend(loc="lower left", fontsize="x-small")
    cn0.set_xlabel("t (s)")
    _save(fig, path)
