"""The campaign report: ``report.md`` with the summary table (mean / median / p95 of the main
scores per label and sweep point, run and failure counts, and how many runs lack each score),
the average NEES over the runs of each consistency block against its chi-square 95 % band, the
failed runs, and box plots in ``plots/`` of the distribution over runs of the horizontal RMS
error (and of the error at the end of GNSS outages, when the drive has outages), one box per
label and sweep point. Under each box: the runs that have no value (a solution silent at an
outage's end has none, so a box of the few runs it spoke in cannot pass for the best) and the
mean coverage of the outages.

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
# the coverage shown under a box of a per-window score (its group's first key)
_WINDOW_COVERAGE = {"outages": "outages.coverage.fraction",
                    "degraded": "degraded.coverage.fraction"}


def _group_name(group: dict) -> str:
    """A box's tick: the label, and under it the sweep values (the axis names the keys)."""
    values = ", ".join(str(v) for v in group["sweep"].values())
    return f"{group['label']}\n{values}" if values else group["label"]


def _has(summary: dict, column: str) -> bool:
    """Whether some run has the score or is missing it (then its box shows the missing)."""
    return any((g["scores"].get(column) or {}).get("count")
               or (g["scores"].get(column) or {}).get("missing") for g in summary["groups"])


def _summary_lines(summary: dict) -> list[str]:
    keys = list(summary["sweep"])
    shown = [(c, t) for c, t in _TABLE if _has(summary, c)]
    rows = []
    for g in summary["groups"]:
        cells = [g["label"], *(str(g["sweep"][k]) for k in keys), str(g["runs"]),
                 str(g["failed"])]
        for column, _ in shown:
            s = g["scores"].get(column) or {}
            cell = " / ".join(format_number(s.get(k)) for k in ("mean", "median", "p95"))
            if s.get("missing"):
                cell += f" ({s['missing']} missing)"
            cells.append(cell)
        rows.append(cells)
    return markdown_table(["label", *keys, "runs", "failed", *(t for _, t in shown)], rows)


def _anees_lines(summary: dict) -> list[str]:
    """One row per label, sweep point and consistency block: ANEES, its band, the verdict."""
    keys = list(summary["sweep"])
    rows = []
    for g in summary["groups"]:
        for block, a in (g.get("anees") or {}).items():
            inside = a["anees"] is not None and a["lower"] <= a["anees"] <= a["upper"]
            verdict = ("inside" if inside else "too cautious" if a["anees"] < a["lower"]
                       else "overconfident")
            rows.append([g["label"], *(str(g["sweep"][k]) for k in keys), block,
                         format_number(a["anees"]), format_number(a["expected"]),
                         f"{format_number(a['lower'])} - {format_number(a['upper'])}",
                         str(a["runs"]), str(a["missing"]), verdict])
    if not rows:
        return ["No solution writes standard deviations: no consistency to judge."]
    return ["The mean over the runs of each run's time-averaged NEES (after its first minute), "
            "and the two-sided 95 % band of the average of N runs' NEES, chi2(N dim) / N: a "
            "consistent filter lies inside; above, it claims a confidence it does not have, "
            "below it is too cautious.", "",
            *markdown_table(["label", *keys, "block", "ANEES", "expected", "95 % band", "runs",
                             "missing", "verdict"], rows)]


def _paired_lines(summary: dict) -> list[str]:
    """One row per pair of labels, sweep point and score compared seed by seed."""
    keys = list(summary["sweep"])
    rows = []
    for c in summary.get("paired") or []:
        if not c["seeds"]:
            continue
        low, high = c["interval"]
        rows.append([c["a"], c["b"], *(str(c["sweep"][k]) for k in keys), c["score"],
                     format_number(c["median_difference"]),
                     f"{format_number(low)} to {format_number(high)}",
                     f"{c['a_smaller']} of {c['seeds']}",
                     "-" if c["sign_test_p"] is None else f"{c['sign_test_p']:.2g}",
                     str(c["missing"])])
    if not rows:
        return ["Fewer than two estimators with a common score: nothing to compare."]
    return ["Each pair of estimators on the same seeds: the median over the seeds of the "
            "difference a - b (metres; negative: a's error is smaller), its 95 % bootstrap "
            "interval, on how many seeds a's is smaller, and the two-sided sign test's "
            "p-value; `missing` counts the seeds where one of the two lacks the score.", "",
            *markdown_table(["a", "b", *keys, "score", "median a - b", "95 % interval",
                             "a smaller", "sign test p", "missing"], rows)]


def _failure_lines(runs: pd.DataFrame, keys: list[str]) -> list[str]:
    failed = runs[runs["status"] == STATUS_FAILED]
    if failed.empty:
        return ["No run failed."]
    rows = [[str(r["run_id"]), str(r["seed"]), *(str(r[k]) for k in keys), str(r["label"]),
             (str(r["error"]).strip().splitlines() or [""])[-1].replace("|", "\\|")]
            for _, r in failed.iterrows()]
    return ["The full tracebacks are in the `error` column of `runs.parquet`.", "",
            *markdown_table(["run", "seed", *keys, "label", "error"], rows)]


def _group_runs(runs: pd.DataFrame, group: dict) -> pd.DataFrame:
    """The successful runs of one label and sweep point."""
    at = (runs["label"] == group["label"]) & (runs["status"] == STATUS_OK)
    for key, value in group["sweep"].items():
        at &= runs[key] == value
    return runs.loc[at]


def _box_note(group: dict, rows: pd.DataFrame, column: str) -> str:
    """Under a box: how many of the runs scored on it have no value (``summary.json``'s
    ``missing``), and for a window score the windows' mean coverage, so that a solution silent
    in the windows is not read as the best."""
    stats = group.get("scores", {}).get(column) or {}
    scored = (stats.get("count") or 0) + (stats.get("missing") or 0)
    if not scored:
        return "not scored"
    note = f"{stats.get('missing') or 0}/{scored} missing"
    coverage = _WINDOW_COVERAGE.get(column.partition(".")[0])
    if coverage is not None and coverage in rows:
        fraction = rows[coverage].to_numpy(dtype=float)
        if np.isfinite(fraction).any():
            note += f"\ncoverage {np.nanmean(fraction):.2f}"
    return note


def _box_plot(runs: pd.DataFrame, summary: dict, column: str, title: str, path: Path) -> None:
    names, data = [], []
    for g in summary["groups"]:
        rows = _group_runs(runs, g)
        values = rows[column].to_numpy(dtype=float)
        names.append(f"{_group_name(g)}\n{_box_note(g, rows, column)}")
        data.append(values[np.isfinite(values)])
    width_in, height_in = max(5.0, 1.2 * len(names) + 2.0), 5.0
    fig = Figure(figsize=(width_in, height_in), layout="constrained")
    ax = fig.add_subplot()
    ax.boxplot(data, showfliers=False)
    for i, values in enumerate(data, start=1):  # every run as a point over its box
        ax.plot(np.full(values.size, i), values, "o", ms=3, alpha=0.5, color="tab:blue")
    ax.set_xticks(range(1, len(names) + 1), names, fontsize="small")
    # wrapped to the figure (about 8 characters per inch of the default fonts), never clipped
    ax.set(xlabel=", ".join(["estimator", *summary["sweep"]]),
           ylabel=textwrap.fill(title, int(7 * height_in)),
           title=textwrap.fill(f"{title} over the runs (runs without a value: missing)",
                               int(8 * width_in)))
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
             "(degraded windows), missing when the solution has no row within 1 s of one "
             "window's end; `(k missing)` counts the runs without the score, which the "
             "statistics cannot include. A solution without GNSS has no outage scores.", "",
             *_summary_lines(summary), "", "## Consistency over the runs (ANEES)", "",
             *_anees_lines(summary), "", "## Paired comparison", "", *_paired_lines(summary),
             "", "## Failed runs", "", *_failure_lines(runs, keys), ""]
    for column, title, name in _PLOTTED:
        if _has(summary, column):
            _box_plot(runs, summary, column, title, directory / PLOTS / f"{name}.png")
            lines += [f"## {title[0].upper()}{title[1:]}", "",
                      f"![{title}]({PLOTS}/{name}.png)", ""]
    path = directory / "report.md"
    replace_file(path, lambda tmp: tmp.write_text("\n".join(lines), encoding="utf-8"))
    return path
