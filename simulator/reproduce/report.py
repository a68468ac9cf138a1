"""The reproduction report: ``report.md`` and a self-contained ``report.html`` (its plots
embedded as base64 PNG, no external file), written into the run's output folder.

Contents, in order: the run's settings (seeds, quick or full, wall and CPU time, landnav version
and commit); a summary table (paper x how many claims are shown / partly / not shown); then per
paper its title and citation, its experiments (scenario, seeds, failed seeds), a table of every
claim (the claim, the paper's figure, landnav's figure over seeds, the conditions that differ,
the one word and its reason), the failed runs with their errors, and one plot: each
experiment's per-seed figures (a dot per seed, symmetric-log axis, so figures of several units
sit on one panel and a paired comparison shows seed by seed).

Markdown tables come from ``simulator.scoring.report.markdown_table``.

Public names
------------
write_report, summary_counts, PLOTS.
"""

from __future__ import annotations

import base64
import html
import io
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from simulator.reproduce.paper import STATUSES
from simulator.scoring.report import markdown_table

if TYPE_CHECKING:  # the runner imports this module; its types only annotate here
    from simulator.reproduce.runner import ExperimentResult, PaperResult, Settings

__all__ = ["PLOTS", "summary_counts", "write_report"]

PLOTS = "plots"  # sub-folder of the output holding the markdown report's PNGs
_DPI = 100
_MAX_FIGURES_PER_PANEL = 16  # a panel with more figure columns shows the first ones


def summary_counts(results: Sequence[PaperResult]) -> dict[str, dict[str, int]]:
    """Paper key -> {status: number of its claims judged so}."""
    return {r.paper.key: {s: sum(v.status == s for v in r.verdicts.values()) for s in STATUSES}
            for r in results}


def _cell(text: str) -> str:
    """Text for a markdown table cell (no pipe or line break breaks the row)."""
    return " ".join(str(text).split()).replace("|", "\\|")


def _settings_rows(settings: Settings) -> list[tuple[str, str]]:
    seeds = settings.seeds
    where = (f"Dask scheduler {settings.scheduler}" if settings.scheduler
             else f"{settings.workers} local worker process(es)")
    return [("mode", "quick (shortened drives)" if settings.quick else "full"),
            ("seeds", f"{len(seeds)} ({seeds[0]}..{seeds[-1]})" if seeds else "none"),
            ("wall time", f"{settings.wall_time_s:.0f} s"),
            ("CPU time of the runs", f"{settings.cpu_time_s:.0f} s"),
            ("executed on", where),
            ("software", settings.version)]


def _experiment_rows(result: PaperResult) -> list[list[str]]:
    rows = []
    for key, e in result.experiments.items():
        failed = ", ".join(str(s) for s in sorted(e.failures)) or "none"
        rows.append([key, e.experiment.scenario, ", ".join(e.experiment.entries),
                     str(len(e.table)), failed])
    return rows


def _claim_rows(result: PaperResult) -> list[list[str]]:
    rows = []
    for claim in result.paper.claims:
        v = result.verdicts[claim.key]
        rows.append([f"**{claim.key}**: {claim.text}", claim.paper_figure, v.measured,
                     claim.conditions, f"**{v.status}**: {v.reason}"])
    return rows


def _last_line(error: str) -> str:
    lines = [line for line in error.strip().splitlines() if line.strip()]
    return lines[-1] if lines else error


def _failure_rows(result: PaperResult) -> list[list[str]]:
    return [[key, str(seed), _last_line(error)]
            for key, e in result.experiments.items() for seed, error in sorted(e.failures.items())]


def _plot(result: PaperResult) -> bytes | None:
    """PNG of each experiment's per-seed figures (None when no experiment has one)."""
    panels = [(key, e) for key, e in result.experiments.items() if len(e.table.columns)]
    if not panels:
        return None
    fig = Figure(figsize=(10, 3.2 * len(panels)), layout="constrained")
    for ax, (key, e) in zip(fig.subplots(len(panels), 1, squeeze=False)[:, 0], panels,
                            strict=True):
        _panel(ax, key, e)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=_DPI)
    return buffer.getvalue()


def _panel(ax: object, key: str, e: ExperimentResult) -> None:
    table = e.table.dropna(axis=1, how="all")  # figures a filter does not have (NaN)
    columns = list(table.columns)[:_MAX_FIGURES_PER_PANEL]
    x = np.arange(len(columns))
    for seed, row in table[columns].iterrows():
        ax.plot(x, row.to_numpy(float), marker="o", linestyle="none", alpha=0.7,
                label=f"seed {seed}")
    ax.set_yscale("symlog", linthresh=1e-2)
    # a seed without a figure has no point: its count is in the tick, never silently dropped
    missing = table[columns].isna().sum()
    ax.set_xticks(x, [f"{c} ({missing[c]} missing)" if missing[c] else c for c in columns],
                  rotation=30, ha="right", fontsize=7)
    ax.set_title(f"{key} ({e.experiment.scenario}): per-seed figures", fontsize=9)
    ax.grid(True, alpha=0.3)
    if len(e.table) <= 12:
        ax.legend(fontsize=6, ncols=min(len(e.table), 6), loc="best")


def _markdown(results: Sequence[PaperResult], settings: Settings,
              plots: dict[str, str]) -> str:
    lines = ["# landnav reproduce: the seed papers' claims", "",
             "Each claim of the papers (or the issue's criterion for it) beside landnav's "
             "figure over seeds, paired per seed where two estimators are compared, with one "
             "word: **shown**, **partly** (the effect is there, short of the criterion) or "
             "**not shown**, and the reason.", "", "## Run", ""]
    lines += markdown_table(["setting", "value"], [list(r) for r in _settings_rows(settings)])
    lines += ["", "## Summary", ""]
    counts = summary_counts(results)
    lines += markdown_table(["paper", *STATUSES], [[r.paper.key, *(str(counts[r.paper.key][s])
                                                                   for s in STATUSES)]
                                                   for r in results])
    for r in results:
        lines += ["", f"## {r.paper.key}: {r.paper.title}", "", r.paper.citation, "",
                  "### Experiments", ""]
        lines += markdown_table(["experiment", "scenario", "entries", "seeds with figures",
                                 "failed seeds"], _experiment_rows(r))
        lines += ["", "### Claims", ""]
        lines += markdown_table(["claim", "paper", "landnav", "conditions that differ",
                                 "verdict"],
                                [[_cell(c) for c in row] for row in _claim_rows(r)])
        failures = _failure_rows(r)
        if failures:
            lines += ["", "### Failed runs", ""]
            lines += markdown_table(["experiment", "seed", "error"],
                                    [[_cell(c) for c in row] for row in failures])
        if r.paper.key in plots:
            lines += ["", f"![{r.paper.key}: per-seed figures]({plots[r.paper.key]})"]
    return "\n".join(lines) + "\n"


def _html_table(header: list[str], rows: list[list[str]]) -> str:
    def cell(text: str, tag: str) -> str:
        escaped = html.escape(str(text))
        # **word** -> <b>word</b>, the one markup the cells use
        parts = escaped.split("**")
        escaped = "".join(f"<b{_STATUS_CLASS.get(p, '')}>{p}</b>" if i % 2 else p
                          for i, p in enumerate(parts))
        return f"<{tag}>{escaped}</{tag}>"

    head = "".join(cell(h, "th") for h in header)
    body = "".join("<tr>" + "".join(cell(c, "td") for c in row) + "</tr>" for row in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


_STATUS_CLASS = {"shown": " class='shown'", "partly": " class='partly'",
                 "not shown": " class='not-shown'"}  # the verdict words, coloured
_STYLE = """.shown{color:#1b6e20;} .partly{color:#a65f00;} .not-shown{color:#b00020;}
body{font-family:sans-serif;max-width:1200px;margin:auto;padding:1em;}
table{border-collapse:collapse;margin:0.5em 0;font-size:0.9em;}
td,th{border:1px solid #bbb;padding:4px 6px;vertical-align:top;text-align:left;}
th{background:#eee;} img{max-width:100%;}"""


def _html(results: Sequence[PaperResult], settings: Settings, pngs: dict[str, bytes]) -> str:
    counts = summary_counts(results)
    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'>",
             "<title>landnav reproduce</title>", f"<style>{_STYLE}</style></head><body>",
             "<h1>landnav reproduce: the seed papers' claims</h1>",
             "<p>Each claim beside landnav's figure over seeds (paired per seed where two "
             "estimators are compared) with one word: shown, partly or not shown, and the "
             "reason.</p><h2>Run</h2>",
             _html_table(["setting", "value"], [list(r) for r in _settings_rows(settings)]),
             "<h2>Summary</h2>",
             _html_table(["paper", *STATUSES], [[r.paper.key, *(str(counts[r.paper.key][s])
                                                                for s in STATUSES)]
                                                for r in results])]
    for r in results:
        parts += [f"<h2>{html.escape(r.paper.key)}: {html.escape(r.paper.title)}</h2>",
                  f"<p>{html.escape(r.paper.citation)}</p><h3>Experiments</h3>",
                  _html_table(["experiment", "scenario", "entries", "seeds with figures",
                               "failed seeds"], _experiment_rows(r)),
                  "<h3>Claims</h3>",
                  _html_table(["claim", "paper", "landnav", "conditions that differ",
                               "verdict"], _claim_rows(r))]
        failures = _failure_rows(r)
        if failures:
            parts += ["<h3>Failed runs</h3>",
                      _html_table(["experiment", "seed", "error"], failures)]
        if r.paper.key in pngs:
            data = base64.b64encode(pngs[r.paper.key]).decode("ascii")
            parts.append(f"<img alt='{html.escape(r.paper.key)}: per-seed figures' "
                         f"src='data:image/png;base64,{data}'>")
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


def write_report(directory: Path, results: Sequence[PaperResult], settings: Settings) -> Path:
    """Write ``report.md`` (with ``plots/PAPER.png``) and ``report.html`` into ``directory``
    (the runner's temporary output folder, renamed when complete); the path of report.md."""
    pngs = {r.paper.key: png for r in results if (png := _plot(r)) is not None}
    plots = {}
    if pngs:
        (directory / PLOTS).mkdir(exist_ok=True)
        for key, png in pngs.items():
            (directory / PLOTS / f"{key}.png").write_bytes(png)
            plots[key] = f"{PLOTS}/{key}.png"
    (directory / "report.html").write_text(_html(results, settings, pngs), encoding="utf-8")
    path = directory / "report.md"
    path.write_text(_markdown(results, settings, plots), encoding="utf-8")
    return path
