"""The scoring report: ``report.md`` with the metrics of every solution side by side, a
per-outage table, and PNG plots in ``plots/`` (matplotlib's Agg canvas, no display):

* ``map.png``: the truth and every solution on a local map (east, north in m about the first
  truth point), the truth's GNSS-outage stretches drawn over it;
* ``horizontal_error.png``: horizontal error against time, outages shaded;
* ``attitude_error.png``: roll, pitch and yaw errors (deg) against time, outages shaded;
* ``horizontal_cdf.png``: the empirical CDF of each solution's horizontal error.

Numbers are printed with three decimals; a missing value prints as ``-``.

Public functions
----------------
write_report, print_scores, text_table, format_number, markdown_table.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from simulator.scoring.align import ERR_ATT, ERR_H, local_ned
from simulator.scoring.evaluate import Evaluation
from simulator.scoring.metrics import OUTAGE_KIND

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

PLOTS = "plots"  # sub-directory of the report directory holding the PNGs
_OUTAGE_COLOUR = "tab:red"

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
    ("nees", "position", "position NEES (expected 3)"),
    ("nees", "velocity", "velocity NEES (expected 3)"),
    ("nees", "attitude", "attitude NEES (expected 3)"),
    ("runtime", "seconds", "runtime (s)"),
    ("runtime", "realtime_factor", "real-time factor"),
    ("rows", "position", "rows scored (position)"),
    ("rows", "total", "rows in solution"),
]
# (group, key, column title) of the compact stdout table
_TEXT_COLUMNS = [
    ("horizontal", "rms", "h_rms"), ("horizontal", "cep95", "h_cep95"),
    ("horizontal", "max", "h_max"), ("vertical", "rms", "v_rms"), ("velocity", "rms", "vel_rms"),
    ("attitude", "yaw_rms", "yaw_rms"),
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
    """A compact fixed-width table of the main scores, one line per label (m, m/s, deg)."""
    header = ["label", *(title for _, _, title in _TEXT_COLUMNS), "worst_outage_end_%"]
    rows = []
    for label, s in scores.items():
        ends = [o["end_percent"] for o in s["outages"] if o["end_percent"] is not None]
        rows.append([label, *(format_number(_value(s, g, k)) for g, k, _ in _TEXT_COLUMNS),
                     format_number(max(ends) if ends else None)])
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(len(header))]
    return "\n".join("  ".join(c.rjust(w) if i else c.ljust(w)
                               for i, (c, w) in enumerate(zip(r, widths, strict=True)))
                     for r in [header, *rows])


def _outages(events: pd.DataFrame) -> list[tuple[float, float]]:
    rows = events.loc[events["kind"] == OUTAGE_KIND].sort_values("t_start")
    return list(zip(rows["t_start"].to_numpy(float), rows["t_end"].to_numpy(float), strict=True))


def _figure(size_in: tuple[float, float]) -> Figure:
    """A new figure (``size_in`` inches) on matplotlib's Agg canvas. matplotlib loads here, when
    a report is written: it takes a third of a second, which the commands that only print
    scores or run an estimator do not pay."""
    from matplotlib.figure import Figure

    return Figure(figsize=size_in, layout="constrained")


def print_scores(ev: Evaluation) -> None:
    """The compact table of every solution's scores on stdout and the scoring warnings (rows
    that could not be scored) on stderr."""
    for line in ev.warnings():
        print(f"warning: {line}", file=sys.stderr)
    print(text_table(ev.scores()))


def _shade(ax: Axes, outages: list[tuple[float, float]]) -> None:
    for i, (a, b) in enumerate(outages):
        ax.axvspan(a, b, color=_OUTAGE_COLOUR, alpha=0.15, lw=0,
                   label="GNSS outage" if i == 0 else None)


def _save(fig: Figure, path: Path) -> None:
    fig.savefig(path, dpi=110)


def _plot_map(ev: Evaluation, path: Path) -> None:
    truth = ev.truth
    origin = tuple(truth[["lat", "lon", "alt"]].iloc[0])
    ned = local_ned(truth, origin)
    fig = _figure((7, 6))
    ax = fig.add_subplot()
    ax.plot(ned[:, 1], ned[:, 0], color="black", lw=2.0, label="truth")
    t = truth["t"].to_numpy()
    for i, (a, b) in enumerate(_outages(ev.events)):
        inside = (t >= a) & (t <= b)
        ax.plot(ned[inside, 1], ned[inside, 0], color=_OUTAGE_COLOUR, lw=5.0, alpha=0.5,
                label="GNSS outage" if i == 0 else None)
    for label, r in ev.results.items():
        sol = local_ned(r.solution, origin)
        ax.plot(sol[:, 1], sol[:, 0], lw=1.0, label=label)
    ax.set(xlabel="east (m)", ylabel="north (m)", title="trajectories on a local map")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(loc="best", fontsize="small")
    _save(fig, path)


def _plot_horizontal(ev: Evaluation, path: Path) -> None:
    fig = _figure((8, 4))
    ax = fig.add_subplot()
    _shade(ax, _outages(ev.events))
    for label, r in ev.results.items():
        ax.plot(r.errors.errors["t"], r.errors.errors[ERR_H], lw=1.0, label=label)
    ax.set(xlabel="t (s)", ylabel="horizontal error (m)", title="horizontal error")
    ax.legend(loc="best", fontsize="small")
    _save(fig, path)


def _plot_attitude(ev: Evaluation, path: Path) -> None:
    fig = _figure((8, 7))
    axes = fig.subplots(3, 1, sharex=True)
    for ax, name, title in zip(axes, ERR_ATT, ("roll", "pitch", "yaw"), strict=True):
        _shade(ax, _outages(ev.events))
        for label, r in ev.results.items():
            ax.plot(r.errors.errors["t"], np.degrees(r.errors.errors[name]), lw=1.0, label=label)
        ax.set(ylabel=f"{title} error (deg)")
    axes[0].set_title("attitude errors")
    axes[0].legend(loc="best", fontsize="small")
    axes[-1].set_xlabel("t (s)")
    _save(fig, path)


def _plot_cdf(ev: Evaluation, path: Path) -> None:
    fig = _figure((6, 4))
    ax = fig.add_subplot()
    for label, r in ev.results.items():
        h = np.sort(r.errors.errors[ERR_H].to_numpy(float))
        h = h[np.isfinite(h)]
        ax.step(h, np.arange(1, h.size + 1) / max(h.size, 1), where="post", label=label)
    ax.set(xlabel="horizontal error (m)", ylabel="fraction of epochs", ylim=(0, 1.02),
           title="CDF of horizontal error")
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize="small")
    _save(fig, path)


def _metrics_lines(scores: dict[str, dict]) -> list[str]:
    rows = [[title, *(format_number(_value(s, g, k)) for s in scores.values())]
            for g, k, title in _TABLE_ROWS
            if any(_value(s, g, k) is not None for s in scores.values())]
    return markdown_table(["metric", *scores], rows)


def _outage_lines(scores: dict[str, dict], outages: list[tuple[float, float]]) -> list[str]:
    if not outages:
        return ["The dataset has no GNSS outage."]
    header = ["#", "start (s)", "duration (s)", "distance (m)"]
    for label in scores:
        header += [f"{label} max (m)", f"{label} end (m)", f"{label} end (%)"]
    rows = []
    for i, (a, b) in enumerate(outages):
        entries = [s["outages"][i] for s in scores.values()]
        distance = entries[0]["distance"] if entries else None
        row = [str(i + 1), format_number(a), format_number(b - a), format_number(distance)]
        for o in entries:
            row += [format_number(o[k]) for k in ("max_horizontal", "end_horizontal",
                                                   "end_percent")]
        rows.append(row)
    return markdown_table(header, rows)


def write_report(directory: Path, ev: Evaluation, title: str, note: str | None = None) -> Path:
    """Write ``report.md`` and ``plots/*.png`` into ``directory`` (which must exist).

    Parameters
    ----------
    directory : where to write (use inside ``atomic_output_dir``).
    ev : the evaluation (truth, events, scored solutions).
    title : the report's heading (the dataset or scenario).
    note : a paragraph placed under the heading (e.g. "no estimator was named").

    Returns
    -------
    Path of ``report.md``.
    """
    directory = Path(directory)
    (directory / PLOTS).mkdir(exist_ok=True)
    scores = ev.scores()
    outages = _outages(ev.events)
    t = ev.truth["t"].to_numpy(float)
    lines = [f"# {title}", ""]
    if note:
        lines += [note, ""]
    lines += [f"Drive: {t[-1] - t[0]:.1f} s, {ev.truth['distance'].iloc[-1]:.1f} m, "
              f"{len(outages)} GNSS outage(s). Metres, m/s and degrees; errors are solution "
              "minus truth in the local NED frame of the true position.", ""]
    plots = [("map", "Trajectories", _plot_map)]
    if ev.results:
        lines += ["## Metrics", "", *_metrics_lines(scores), "",
                  "## GNSS outages", "", *_outage_lines(scores, outages), ""]
        plots += [("horizontal_error", "Horizontal error", _plot_horizontal),
                  ("attitude_error", "Attitude errors", _plot_attitude),
                  ("horizontal_cdf", "CDF of horizontal error", _plot_cdf)]
    for name, heading, plot in plots:
        plot(ev, directory / PLOTS / f"{name}.png")
        lines += [f"## {heading}", "", f"![{heading}]({PLOTS}/{name}.png)", ""]
    path = directory / "report.md"
    path.write_text("\n".join(lines), encoding="utf-8")
    return path
