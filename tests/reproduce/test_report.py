"""The reproduction report on synthetic results: it names every paper and claim with its figure
and word, counts the words per paper, lists failed runs, and the HTML page is self-contained."""

from __future__ import annotations

import re

import pandas as pd
from matplotlib.figure import Figure

from simulator.reproduce.paper import Claim, Experiment, Paper, Verdict
from simulator.reproduce.report import _panel, summary_counts, write_report
from simulator.reproduce.runner import ExperimentResult, PaperResult, Settings


def _measure(dataset, solutions):  # never called: the results below are given
    return {}


def _result(key: str, statuses: list[str]) -> PaperResult:
    experiment = Experiment("drive", "quickstart.yaml", {"a": {"name": "dead_reckoning"}},
                            _measure)
    claims = tuple(Claim(f"{key}_claim{i}", f"claim {i} of {key} | with a pipe",
                         f"Table {i}: 1.{i} m", "simulated", lambda t: None)
                   for i in range(len(statuses)))
    paper = Paper(key, f"Title of {key}", f"Author, Journal ({key})", (experiment,), claims)
    table = pd.DataFrame({"a.error_m": [1.0, 2.0, 4.0]},
                         index=pd.Index([1, 2, 4], name="seed"))
    verdicts = {c.key: Verdict(s, f"figure of {c.key}: median 2 m", f"because {s}")
                for c, s in zip(claims, statuses, strict=True)}
    return PaperResult(paper, {"drive": ExperimentResult(experiment, table,
                                                         {3: "Traceback ...\nValueError: boom"})},
                       verdicts)


SETTINGS = Settings((1, 2, 3, 4), True, 2, None, 12.0, 20.0, "landnav 0.1.0, commit abc")


def test_report_names_every_paper_claim_figure_and_word(tmp_path):
    results = [_result("first", ["shown", "partly", "not shown"]),
               _result("second", ["shown", "shown"])]
    write_report(tmp_path, results, SETTINGS)
    md = (tmp_path / "report.md").read_text()
    page = (tmp_path / "report.html").read_text()
    for r in results:
        for text in (r.paper.title, r.paper.citation):
            assert text in md and text in page
        for claim in r.paper.claims:
            v = r.verdicts[claim.key]
            assert claim.key in md and v.measured in md and claim.paper_figure in md
            assert claim.key in page and v.measured in page
    assert "| first | 1 | 1 | 1 |" in md and "| second | 2 | 0 | 0 |" in md
    assert "quick (shortened drives)" in md and "commit abc" in md and "12 s" in md
    # a failed run: its seed and the error's last line
    assert "| drive | 3 | ValueError: boom |" in md
    # a pipe in a cell does not break the row
    assert "with a pipe" in md and "\\|" in md
    assert summary_counts(results) == {"first": {"shown": 1, "partly": 1, "not shown": 1},
                                       "second": {"shown": 2, "partly": 0, "not shown": 0}}
    assert (tmp_path / "plots" / "first.png").stat().st_size > 1000
    assert "![first: per-seed figures](plots/first.png)" in md


def test_html_is_self_contained(tmp_path):
    write_report(tmp_path, [_result("only", ["shown"])], SETTINGS)
    page = (tmp_path / "report.html").read_text()
    sources = re.findall(r"""(?:src|href)\s*=\s*['"]([^'"]*)""", page)
    assert sources and all(s.startswith("data:image/png;base64,") for s in sources)
    assert "<link" not in page and "<script" not in page
    assert page.count("<table>") == page.count("</table>") == 5  # run, summary, 3 of the paper


def test_per_seed_plot_counts_the_seeds_without_a_figure():
    result = _result("p", ["shown"])
    e = result.experiments["drive"]
    e.table["b.end_m"] = [3.0, float("nan"), float("nan")]  # silent at two seeds' outage ends
    e.table["c.none_m"] = float("nan")  # a figure the filter does not have at all
    ax = Figure().add_subplot()
    _panel(ax, "drive", e)
    assert [t.get_text() for t in ax.get_xticklabels()] == ["a.error_m", "b.end_m (2 missing)"]
