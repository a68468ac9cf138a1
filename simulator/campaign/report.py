"""The campaign report: ``report.md`` with the summary table (mean / median / p95 of the main
scores per label and sweep point, run and failure counts), the failed runs, and box plots in
``plots/`` of the distribution over runs of the horizontal RMS error (and of the error at the
end of GNSS outages, when the drive has outages), one box per label and sweep point.

Every file is written under a temporary name and renamed into place.

Public functions
----------------
write_campaign_report.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from simulator.campaign.worker import STATUS_FAILED, STATUS_OK
from simulator.outputs import real_subfolder, replace_file
from simulator.scoring.report import PLOTS, format_number, markdown_table

# (column, title) of the summary table and of the plots, in order
_TABLE = [("horizontal.rms", "horizontal RMS (m)"), ("horizontal.cep95", "horizontal CEP95 (m)"),
          ("vertical.rms", "vertical RMS (m)"), ("attitude.yaw_rms", "yaw RMS (deg)"),
          ("outages.end_horizontal", "outage end error (m)"),
          ("degraded.end_horizontal", "degraded-window end error (m)"),
          ("coverage.fraction", "coverage"), ("runtime.seconds", "runtime (s)")]
_PLOTTED = [("horizontal.rms", "horizontal RMS (m)", "horizontal_rms"),
            ("outages.end_horizontal", "horizontal error at the end of GNSS outages (m)",
             "outage_end")]


def _group_name(group: dict) -> str:
    """A box's tick: the label, and under it the sweep values (the axis names the keys)."""
    values = ", ".join(str(v) for v in group["sweep"].values())
    return f"{group['label']}\n{values}" if values else group["label"]


def _has(summary: dict, column: str) -> bool:
    return any((g["scores"].get(column) or {}).get("count") for g in summary["groups"])


def _summary_lines(summary: dict) -> list[str]:
    keys = list(summary["sweep"])
    shown = [(c, t) for c, t in _TABLE if _has(summary, c)]
    rows = []
    for g in summary["groups"]:
        cells = [g["label"], *(str(g["sweep"][k]) for k in keys), str(g["runs"]),
                 str(g["failed"])]
        for column, _ in shown:
            s = g["scores"].get(column) or {}
            cells.append(" / ".join(format_number(s.get(k)) for k in ("mean", "median", "p95")))
        rows.append(cells)
    return markdown_table(["label", *keys, "runs", "failed", *(t for _, t in shown)], rows)


def _failure_lines(runs: pd.DataFrame, keys: list[str]) -> list[str]:
    failed = runs[runs["status"] == STATUS_FAILED]
    if failed.empty:
        return ["No run failed."]
    rows = [[str(r["run_id"]), str(r["seed"]), *(str(r[k]) for k in keys), str(r["label"]),
             (str(r["error"]).strip().splitlines() or [""])[-1].replace("|", "\\|")]
            for _, r in failed.iterrows()]
    return ["The full tracebacks are in the `error` column of `runs.parquet`.", "",
            *markdown_table(["run", "seed", *keys, "label", "error"], rows)]


def _box_plot(runs: pd.DataFrame, summary: dict, column: str, title: str, path: Path) -> None:
    names, data = [], []
    for g in summary["groups"]:
        at = (runs["label"] == g["label"]) & (runs["status"] == STATUS_OK)
        for key, value in g["sweep"].items():
            at &= runs[key] == value
        values = runs.loc[at, column].to_numpy(dtype=float)
        names.append(_group_name(g))
        data.append(values[np.isfinite(values)])
    width_in, height_in = max(5.0, 1.2 * len(names) + 2.0), 4.5
    fig = Figure(figsize=(width_in, height_in), layout="constrained")
    ax = fig.add_subplot()
    ax.boxplot(data, showfliers=False)
    for i, values in enumerate(data, start=1):  # every run as a point over its box
        ax.plot(np.full(values.size, i), values, "o", ms=3, alpha=0.5, color="tab:blue")
    ax.set_xticks(range(1, len(names) + 1), names, fontsize="small")
    # wrapped to the figure (about 8 characters per inch of the default fonts), never clipped
    ax.set(xlabel=", ".join(["estimator", *summary["sweep"]]),
           ylabel=textwrap.fill(title, int(7 * height_in)),
           title=textwrap.fill(f"{title} over the runs", int(8 * width_in)))
    ax.grid(axis="y", alpha=0.3)
    replace_file(path, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))


def write_campaign_report(directory: Path, runs: pd.DataFrame, summary: dict) -> Path:
    """Write ``report.md`` and its plots into ``directory``; return the report's path."""
    directory = Path(directory)
    real_subfolder(directory / PLOTS)
    keys = list(summary["sweep"])
    ok = int((runs["status"] == STATUS_OK).sum())
    first, n = summary["base_seed"], summary["runs"]
    sweep = "".join(f" x {len(v)} values of `{k}`" for k, v in summary["sweep"].items())
    lines = [f"# Campaign: {summary['scenario']}", "",
             f"{n} run(s) (seeds {first} to {first + n - 1}) x {len(summary['labels'])} "
             f"estimator(s){sweep}: {ok} result(s) ok, {len(runs) - ok} failed.", "",
             "## Summary", "",
             "Each cell is mean / median / p95 over the runs that succeeded; metres, degrees, "
             "seconds. Outage (degraded-window) scores are each run's mean over its GNSS outages "
             "(degraded windows); a solution without GNSS has none.", "",
             *_summary_lines(summary), "", "## Failed runs", "", *_failure_lines(runs, keys), ""]
    for column, title, name in _PLOTTED:
        if _has(summary, column):
            _box_plot(runs, summary, column, title, directory / PLOTS / f"{name}.png")
            lines += [f"## {title[0].upper()}{title[1:]}", "",
                      f"![{title}]({PLOTS}/{name}.png)", ""]
    path = directory / "report.md"
    replace_file(path, lambda tmp: tmp.write_text("\n".join(lines), encoding="utf-8"))
    return path
