"""The scoring report: ``report.md`` with the metrics of every solution side by side, one table
per GNSS outage and degraded window (each solution's end error beside its coverage of the
window), the consistency of every solution with standard deviations (NEES per block, the share
inside the 95 % band, (e/sigma)^2 per axis, NIS), the estimated sensor errors, and the PNG plots
of ``simulator.scoring.plots`` in ``plots/``: the map and its zooms on each window,
north/east/down and attitude errors with +-3 sigma, NEES per block against its chi-square band,
altitude, the log-scale CDF of the horizontal error, and the sky, satellite count, DOP and C/N0
of a dataset with raw GNSS.

Numbers are printed with three decimals; a missing value prints as ``-``.

Public functions
----------------
write_report, print_scores, text_table, format_number, markdown_table.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

from simulator.columns import SENSOR_ERRORS
from simulator.display_units import display
from simulator.gnss.fix import primary_rows
from simulator.scoring.consistency import CONSISTENCY_SKIP_S
from simulator.scoring.evaluate import Evaluation
from simulator.scoring.metrics import OUTAGE_KIND, degraded_windows

PLOTS = "plots"  # sub-directory of the report directory holding the PNGs
NO_PLOTS = "Plots were not drawn (`--no-plots`)."

# (group, key, row title) of the metrics table, in order
_TABLE_ROWS = [
    ("horizontal", "rms", "horizontal RMS (m)"),
    ("horizontal", "mean", "horizontal mean (m)"),
    ("horizontal", "cep50", "horizontal CEP50 (m)"),
    ("horizontal", "cep95", "horizontal CEP95 (m)"),
    ("horizontal", "max", "horizontal max (m)"),
    ("vertical", "rms", "vertical RMS (m)"),
    ("vertical", "max", "vertical max (m)"),
    ("velocity", "rms", "velocity RMS (m/s)"),
    ("attitude", "roll_rms", "roll RMS (deg)"),
    ("attitude", "pitch_rms", "pitch RMS (deg)"),
    ("attitude", "yaw_rms", "yaw RMS (deg)"),
    ("coverage", "fraction", "coverage (fraction of the drive)"),
    ("coverage", "longest_gap", "longest gap without a row (s)"),
    ("nees", "position", "position NEES, whole drive (expected 3)"),
    ("nees", "velocity", "velocity NEES, whole drive (expected 3)"),
    ("nees", "attitude", "attitude NEES, whole drive (expected 3)"),
    ("runtime", "seconds", "runtime (s)"),
    ("runtime", "realtime_factor", "real-time factor"),
    ("rows", "position", "rows scored (position)"),
    ("rows", "total", "rows in solution"),
]
# (group, key, column title) of the compact stdout table
_TEXT_COLUMNS = [
    ("horizontal", "rms", "h_rms"), ("horizontal", "cep95", "h_cep95"),
    ("horizontal", "max", "h_max"), ("vertical", "rms", "v_rms"), ("velocity", "rms", "vel_rms"),
    ("attitude", "yaw_rms", "yaw_rms"), ("coverage", "fraction", "coverage"),
]


def format_number(x: float | int | None) -> str:
    """A score as printed in the report and on stdout: three decimals, ``-`` when missing."""
    if x is None:
        return "-"
    return str(x) if isinstance(x, int) else f"{x:.3f}"


def _value(scores: dict, group: str, key: str) -> float | None:
    return (scores.get(group) or {}).get(key)


def markdown_table(header: list[str], rows: list[list[str]]) -> list[str]:
    """The lines of a markdown table with ``header`` and ``rows`` of cell texts."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return lines + ["| " + " | ".join(row) + " |" for row in rows]


def text_table(scores: dict[str, dict]) -> str:
    """A compact fixed-width table of the main scores, one line per label (m, m/s, deg); the
    worst outage end error is ``no-row`` when the solution has no end error at some outage (it
    would otherwise be the worst of the outages it spoke at)."""
    header = ["label", *(title for _, _, title in _TEXT_COLUMNS), "worst_outage_end_%"]
    rows = []
    for label, s in scores.items():
        outages = s["outages"] or ()
        ends = [o["end_percent"] for o in outages if o["end_percent"] is not None]
        silent = any(o["end_horizontal"] is None for o in outages)
        rows.append([label, *(format_number(_value(s, g, k)) for g, k, _ in _TEXT_COLUMNS),
                     "no-row" if silent else format_number(max(ends) if ends else None)])
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(len(header))]
    return "\n".join("  ".join(c.rjust(w) if i else c.ljust(w)
                               for i, (c, w) in enumerate(zip(r, widths, strict=True)))
                     for r in [header, *rows])


def print_scores(ev: Evaluation) -> None:
    """The compact table of every solution's scores on stdout and the scoring warnings (rows
    that could not be scored) on stderr."""
    for line in ev.warnings():
        print(f"warning: {line}", file=sys.stderr)
    print(text_table(ev.scores()))


def _metrics_lines(scores: dict[str, dict]) -> list[str]:
    rows = [[title, *(format_number(_value(s, g, k)) for s in scores.values())]
            for g, k, title in _TABLE_ROWS
            if any(_value(s, g, k) is not None for s in scores.values())]
    return markdown_table(["metric", *scores], rows)


def _end_cell(o: dict, key: str) -> str:
    """An end error (or end %) cell: ``no row`` where the solution has no row within 1 s of
    the window's end, so a silent solution never reads as a small error."""
    if o and o.get(key) is None and o.get("end_horizontal") is None:
        return "no row"
    return format_number(o.get(key))


def _window_lines(scores: dict[str, dict], group: str, n: int, empty: str) -> list[str]:
    """One row per outage (``group`` = outages) or degraded window: its span and distance,
    then each solution's end error beside the share of the window it covers, its end error as
    % of the distance and its largest error (``-`` for a solution without GNSS, ``no row``
    where it has no row within 1 s of the window's end)."""
    if not n:
        return [empty]
    header = ["#", "start (s)", "duration (s)", "distance (m)"]
    if group == "degraded":
        header[1:1] = ["kind", "satellites"]
    for label in scores:
        header += [f"{label} end (m)", f"{label} coverage", f"{label} end (%)",
                   f"{label} max (m)"]
    rows = []
    for i in range(n):
        entries = [s[group][i] if s.get(group) is not None else {} for s in scores.values()]
        first = next((o for o in entries if o), {})
        row = [str(i + 1), *(format_number(first.get(k)) for k in ("start", "duration",
                                                                   "distance"))]
        if group == "degraded":
            row[1:1] = [str(first.get("kind", "-")), format_number(first.get("satellites"))]
        for o in entries:
            row += [_end_cell(o, "end_horizontal"),
                    format_number((o.get("coverage") or {}).get("fraction")),
                    _end_cell(o, "end_percent") if o.get("distance") else "-",
                    format_number(o.get("max_horizontal"))]
        rows.append(row)
    note = ("The end error is the error of the solution's last row in the window, if that row "
            "lies within 1 s of the window's end; `no row` where it does not: a solution silent "
            "at the end has no end error to rank it by (read its coverage beside it).")
    return [note, "", *markdown_table(header, rows)]


def _consistency_lines(scores: dict[str, dict]) -> list[str]:
    """One row per solution and consistency block: NEES against its dimension, the share of
    epochs inside the 95 % band, and each axis's mean (error / sigma)^2; then the NIS."""
    rows = []
    for label, s in scores.items():
        for block, c in (s.get("consistency") or {}).items():
            if c is None:
                continue
            axes = ", ".join(f"{axis} {format_number(v)}" for axis, v in c["nse"].items())
            rows.append([label, block, format_number(c["nees"]),
                         format_number(c["nees_expected"]), format_number(c["inside_95"]),
                         format_number(c.get("with_sigma")), axes])
    if not rows:
        return ["No solution writes standard deviations (`std_*` columns)."]
    lines = [f"After each solution's first {CONSISTENCY_SKIP_S:g} s. NEES is the time average "
             "of eᵀP⁻¹e (P diagonal from the 1-sigma columns), expected its dimension for a "
             "consistent filter; `inside 95 %` the share of epochs inside the chi-square 95 % "
             "band (0.95 for a consistent filter); `with σ` the share of the epochs with an "
             "error that carry a sigma (the others, a NaN or zero sigma, are left out of the "
             "NEES: below 1, the figures hold for part of the drive); `(e/σ)²` the mean per "
             "axis (1 when consistent, above: overconfident, below: too cautious).", "",
             *markdown_table(["solution", "block", "NEES", "expected", "inside 95 %",
                              "with σ", "(e/σ)² per axis"], rows)]
    nis = [[label, format_number(s["nis"]["mean"]), format_number(s["nis"]["expected"]),
            str(s["nis"]["updates"])] for label, s in scores.items() if s.get("nis")]
    if nis:
        lines += ["", "GNSS innovations (NIS, expected their dimension):", "",
                  *markdown_table(["solution", "NIS", "expected", "updates"], nis)]
    return lines


def _sensor_value(x: float | None, column: str) -> str:
    """An estimated sensor error in its datasheet unit (deg/h, mg, ppm, ...)."""
    return "-" if x is None else display(x, SENSOR_ERRORS.get(column, ""))


def _sensor_lines(scores: dict[str, dict]) -> list[str]:
    rows = [[label, name, _sensor_value(v["rms"], name), _sensor_value(v["final"], name)]
            for label, s in scores.items() for name, v in (s.get("sensor_errors") or {}).items()]
    if not rows:
        return ["No solution estimates a sensor error the dataset has the truth of."]
    return markdown_table(["solution", "column", "RMS error", "final error"], rows)


def _plots(ev: Evaluation) -> list[tuple[str, str, Callable[[Evaluation, Path], None]]]:
    """(file stem, heading, function(ev, path)) of the plots this evaluation calls for.
    matplotlib loads here, when a report is written (a third of a second that the commands
    which only print scores do not pay)."""
    from simulator.scoring import plots as plot

    out: list[tuple[str, str, Callable[[Evaluation, Path], None]]] = [
        ("map", "Trajectories", plot.plot_map)]
    if plot.shaded_windows(ev):
        out.append(("map_windows", "Each GNSS outage and degraded window, zoomed",
                    plot.plot_map_windows))
    if ev.results:
        out += [("position_errors", "North, east and down errors", plot.plot_position_errors),
                ("attitude_errors", "Attitude errors", plot.plot_attitude_errors)]
        if plot.has_std(ev):
            out.append(("nees", "NEES over time, per block", plot.plot_nees))
    out.append(("altitude", "Altitude", plot.plot_altitude))
    if ev.results:
        out.append(("horizontal_cdf", "CDF of horizontal error", plot.plot_horizontal_cdf))
    dataset = ev.dataset
    if dataset is not None and dataset.has("gnss_raw"):
        # a measurement is named by its epoch, system (several systems) and satellite; of a
        # receiver tracking several signals, each system's primary one
        keys = ["t", "system", "sv"] if "system" in dataset.units("gnss_raw") else ["t", "sv"]
        raw = primary_rows(dataset.read("gnss_raw"))[[*keys, "cn0", "elevation", "azimuth"]]
        if dataset.has("truth_gnss"):  # which signals were NLOS, from the truth
            truth = primary_rows(dataset.read("truth_gnss"))[[*keys, "nlos"]]
            raw = raw.merge(truth, on=keys, how="left")
        fix = (dataset.read("gnss_fix", ["t", "num_sats", "hdop", "vdop"])
               if dataset.has("gnss_fix") else None)
        if len(raw):
            out.append(("gnss_sky", "GNSS: sky plot, satellites, DOP and C/N0",
                        lambda e, path: plot.plot_gnss_sky(e, path, raw, fix)))
    return out


def write_report(directory: Path, ev: Evaluation, title: str, note: str | None = None,
                 plots: bool = True) -> Path:
    """Write ``report.md`` and ``plots/*.png`` into ``directory`` (which must exist).

    Parameters
    ----------
    directory : where to write (use inside ``atomic_output_dir``).
    ev : the evaluation (truth, events, scored solutions, and the dataset for its GNSS plots).
    title : the report's heading (the dataset or scenario).
    note : a paragraph placed under the heading (e.g. "no estimator was named").
    plots : draw the plots (about a third of a short run's time); without them the report
        holds the tables alone and says so, and no ``plots/`` is made.

    Returns
    -------
    Path of ``report.md``.
    """
    directory = Path(directory)
    if plots:
        (directory / PLOTS).mkdir(exist_ok=True)
    scores = ev.scores()
    n_outages = int((ev.events["kind"] == OUTAGE_KIND).sum())
    n_degraded = len(degraded_windows(ev.events, ev.canyon_zones))
    t = ev.truth["t"].to_numpy(float)
    lines = [f"# {title}", ""]
    if note:
        lines += [note, ""]
    lines += [f"Drive: {t[-1] - t[0]:.1f} s, {ev.truth['distance'].iloc[-1]:.1f} m, "
              f"{n_outages} GNSS outage(s), {n_degraded} degraded GNSS window(s). Metres, m/s "
              "and degrees; errors are solution minus truth in the local NED frame of the true "
              "position; `-` is a value that cannot be scored (a quantity the solution does not "
              "estimate, a window without a row, outages of a solution without GNSS).", ""]
    if ev.results:
        lines += ["## Metrics", "", *_metrics_lines(scores), "",
                  "## GNSS outages", "",
                  *_window_lines(scores, "outages", n_outages, "The dataset has no GNSS outage."),
                  "", "## Degraded GNSS windows", "",
                  *_window_lines(scores, "degraded", n_degraded,
                                 "The dataset has no degraded GNSS window."), "",
                  "## Consistency", "", *_consistency_lines(scores), "",
                  "## Estimated sensor errors", "", *_sensor_lines(scores), ""]
    if not plots:
        lines += [NO_PLOTS, ""]
    for name, heading, draw in _plots(ev) if plots else ():
        draw(ev, directory / PLOTS / f"{name}.png")
        lines += [f"## {heading}", "", f"![{heading}]({PLOTS}/{name}.png)", ""]
    path = directory / "report.md"
    path.write_text("\n".join(lines), encoding="utf-8")
    return path
