"""The reproduction report: ``report.md`` and a self-contained ``report.html`` (the Markdown
rendered by ``simulator.html_report``, its plots embedded as base64 PNG, no external file),
written into the run's output folder.

Contents, in order: the run's settings (seeds, quick or full, wall and CPU time, landnav version
and commit) and the rule that turns per-seed values into a word; a summary table (per paper, its
own claims and landnav's checks counted apart); then per paper its title and citation, its
experiments (scenario, seeds, failed seeds), a table of the paper's claims (the claim, the
paper's figure, landnav's figure over seeds, every condition that differs from the paper, the
evidence in words: direction per seed, median effect with its 95 % interval, sign-test p-value,
and the one word with its reason; a claim landnav cannot test with the reason), the claims
judged again under other values of a deciding condition, a table of landnav's own checks, the
failed runs with their errors, the figures in the layout of the paper's own (time histories of
the first seed, ``Paper.figures``) and one plot of each experiment's per-seed figures (a dot per
seed, symmetric-log axis, so a paired comparison shows seed by seed).

Markdown tables come from ``simulator.scoring.report.markdown_table``.

Public names
------------
write_report, summary_counts, PLOTS.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from simulator.html_report import write_html_report
from simulator.reproduce.evidence import ALPHA, evidence_text
from simulator.reproduce.paper import STATUSES, Claim, Verdict
from simulator.reproduce.results import UNTESTABLE
from simulator.scoring.report import markdown_table

if TYPE_CHECKING:  # the runner imports this module; its types only annotate here
    from simulator.reproduce.runner import ExperimentResult, PaperResult, Settings

__all__ = ["PLOTS", "summary_counts", "write_report"]

PLOTS = "plots"  # sub-folder of the output holding the markdown report's PNGs
_DPI = 100
_MAX_FIGURES_PER_PANEL = 16  # a panel with more figure columns shows the first ones


def summary_counts(results: Sequence[PaperResult], kind: str = "paper"
                   ) -> dict[str, dict[str, int]]:
    """Paper key -> {word: number of its claims of ``kind`` ("paper" or "check") judged so},
    the variants of a swept condition left out; paper claims count "not testable" too."""
    out = {}
    for r in results:
        claims = [c for c in r.paper.claims if c.kind == kind and not c.variant_of]
        words = [UNTESTABLE if c.untestable else r.verdicts[c.key].status for c in claims]
        out[r.paper.key] = {w: words.count(w) for w in (*STATUSES, UNTESTABLE)
                            if w != UNTESTABLE or kind == "paper"}
    return out


def _cell(text: str) -> str:
    """Text for a markdown table cell (no pipe or line break breaks the row)."""
    return " ".join(str(text).split()).replace("|", "\\|")


def _settings_rows(settings: Settings) -> list[tuple[str, str]]:
    seeds = settings.seeds
    where = (f"Dask scheduler {settings.scheduler}" if settings.scheduler
             else f"{settings.workers} local worker process(es)")
    return [("mode", "quick (shortened drives, no variant claims)" if settings.quick else "full"),
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


def _evidence_cell(v: Verdict) -> str:
    if v.evidence is None:
        return "no per-seed evidence"
    text = evidence_text(v.evidence)
    if v.magnitude is not None:
        met = "met" if v.magnitude.holds(v.evidence) else "not met"
        text += f"; the paper's magnitude ({v.magnitude.text}): {met}"
    return text


def _claim_rows(result: PaperResult, claims: Sequence[Claim]) -> list[list[str]]:
    rows = []
    for claim in claims:
        conditions = "; ".join(claim.conditions) or "none"
        head = f"**{claim.key}**: {claim.text}"
        if claim.variant:
            head = f"**{claim.key}** ({claim.variant}): {claim.text}"
        if claim.untestable:
            figure = result.verdicts[claim.key].measured if claim.key in result.verdicts \
                else "not tested"
            rows.append([head, claim.paper_figure, figure, conditions, "none",
                         f"**{UNTESTABLE}**: {claim.untestable}"])
            continue
        v = result.verdicts[claim.key]
        rows.append([head, claim.paper_figure, v.measured, conditions, _evidence_cell(v),
                     f"**{v.status}**: {v.reason}"])
    return rows


def _last_line(error: str) -> str:
    lines = [line for line in error.strip().splitlines() if line.strip()]
    return lines[-1] if lines else error


def _failure_rows(result: PaperResult) -> list[list[str]]:
    return [[key, str(seed), _last_line(error)]
            for key, e in result.experiments.items() for seed, error in sorted(e.failures.items())]


def _png(fig: Figure) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=_DPI)
    return buffer.getvalue()


def _plot(result: PaperResult) -> bytes | None:
    """PNG of each experiment's per-seed figures (None when no experiment has one)."""
    panels = [(key, e) for key, e in result.experiments.items() if len(e.table.columns)]
    if not panels:
        return None
    fig = Figure(figsize=(10, 3.2 * len(panels)), layout="constrained")
    for ax, (key, e) in zip(fig.subplots(len(panels), 1, squeeze=False)[:, 0], panels,
                            strict=True):
        _panel(ax, key, e)
    return _png(fig)


def _paper_figures(result: PaperResult) -> list[tuple[str, bytes]]:
    """(caption, PNG) of the paper's own figure layouts (``Paper.figures``), drawn from the
    first seed's histories and the per-seed figures; none when the paper has none or no
    history was recorded."""
    histories = {k: e.history for k, e in result.experiments.items() if e.history is not None}
    if result.paper.figures is None or not histories:
        return []
    tables = {k: e.table for k, e in result.experiments.items()}
    return [(caption, _png(fig)) for caption, fig in result.paper.figures(histories, tables)]


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


_CLAIM_COLUMNS = ["claim", "paper", "landnav", "conditions that differ from the paper",
                  "evidence", "verdict"]


def _claims_table(title: str, result: PaperResult, claims: Sequence[Claim]) -> list[str]:
    if not claims:
        return []
    return ["", f"### {title}", "", *markdown_table(
        _CLAIM_COLUMNS, [[_cell(c) for c in row] for row in _claim_rows(result, claims)])]


def _summary_rows(results: Sequence[PaperResult]) -> list[list[str]]:
    papers, checks = summary_counts(results, "paper"), summary_counts(results, "check")
    return [[r.paper.key, *(str(papers[r.paper.key][w]) for w in (*STATUSES, UNTESTABLE)),
             *(str(checks[r.paper.key][w]) for w in STATUSES)] for r in results]


def _markdown(results: Sequence[PaperResult], settings: Settings,
              plots: dict[str, list[tuple[str, str]]]) -> str:
    lines = ["# landnav reproduce: the seed papers' claims", "",
             "Each claim of the papers, quoted with its figure or table, beside landnav's "
             "figure over seeds (paired per seed where the paper compares two filters), the "
             "conditions that differ from the paper, the evidence and one word. The word "
             "follows from the per-seed values by one rule: per seed the paper's direction "
             "holds or not (a seed without a value counts as not); **shown** when the "
             "one-sided exact sign test in the paper's direction gives p below "
             f"{ALPHA:g} and the magnitude the paper prints (if any) is met by the median "
             "effect; **partly** when the direction is significant and the printed "
             "magnitude is not met; **not shown** otherwise. The median paired effect is "
             "given with its 95 % bootstrap interval. landnav's own checks (that a filter "
             "works, controls) are listed and counted apart from the papers' claims; a claim "
             "landnav cannot test says why. With three seeds nothing can be shown (the "
             "smallest one-sided p of three seeds is 1/8): --quick checks the mechanics, "
             "not the papers.", "", "## Run", ""]
    lines += markdown_table(["setting", "value"], [list(r) for r in _settings_rows(settings)])
    lines += ["", "## Summary", "",
              "Papers' claims (shown / partly / not shown / not testable) and landnav's own "
              "checks (shown / partly / not shown), counted apart; the claims judged again "
              "under another value of a deciding condition are not counted.", ""]
    lines += markdown_table(["paper", *(f"claims {w}" for w in (*STATUSES, UNTESTABLE)),
                             *(f"checks {w}" for w in STATUSES)], _summary_rows(results))
    for r in results:
        lines += ["", f"## {r.paper.key}: {r.paper.title}", "", r.paper.citation, "",
                  "### Experiments", ""]
        lines += markdown_table(["experiment", "scenario", "entries", "seeds with figures",
                                 "failed seeds"], _experiment_rows(r))
        claims = r.paper.claims
        lines += _claims_table("The paper's claims", r,
                               [c for c in claims if c.kind == "paper" and not c.variant_of])
        lines += _claims_table("Claims under other values of a deciding condition", r,
                               [c for c in claims if c.variant_of])
        lines += _claims_table("landnav's checks and controls (not claims of the paper)", r,
                               [c for c in claims if c.kind == "check" and not c.variant_of])
        failures = _failure_rows(r)
        if failures:
            lines += ["", "### Failed runs", ""]
            lines += markdown_table(["experiment", "seed", "error"],
                                    [[_cell(c) for c in row] for row in failures])
        if plots.get(r.paper.key):
            lines += ["", "### Figures", ""]
            for caption, path in plots[r.paper.key]:
                lines += [f"![{caption}]({path})", "", caption, ""]
    return "\n".join(lines) + "\n"


# the verdict words, coloured in the HTML page
VERDICT_COLOURS = {"shown": "color:#1b6e20", "partly": "color:#a65f00",
                   "not shown": "color:#b00020", UNTESTABLE: "color:#555555"}


def write_report(directory: Path, results: Sequence[PaperResult], settings: Settings) -> Path:
    """Write ``report.md`` (with its PNGs in ``plots/``) and ``report.html`` into ``directory``
    (the runner's temporary output folder, renamed when complete); the path of report.md."""
    plots: dict[str, list[tuple[str, str]]] = {}
    for r in results:
        pngs = _paper_figures(r)
        if (png := _plot(r)) is not None:
            pngs.append((f"{r.paper.key}: per-seed figures", png))
        for k, (caption, data) in enumerate(pngs):
            (directory / PLOTS).mkdir(exist_ok=True)
            name = f"{r.paper.key}.png" if k == len(pngs) - 1 else f"{r.paper.key}-{k + 1}.png"
            (directory / PLOTS / name).write_bytes(data)
            plots.setdefault(r.paper.key, []).append((caption, f"{PLOTS}/{name}"))
    path = directory / "report.md"
    path.write_text(_markdown(results, settings, plots), encoding="utf-8")
    write_html_report(path, VERDICT_COLOURS)
    return path
