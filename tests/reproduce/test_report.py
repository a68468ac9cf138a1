"""The reproduction report and results.json on synthetic results: every paper and claim with its
figure, conditions, evidence and word; the papers' claims and landnav's checks in separate
tables and tallied apart; the HTML page self-contained; results.json recomputed by the
independent script (tools/recompute_verdicts.py), which also catches a word that does not
follow from its values."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure

from simulator.reproduce import measures as m
from simulator.reproduce.paper import Claim, Experiment, Paper, Verdict
from simulator.reproduce.report import _panel, summary_counts, write_report
from simulator.reproduce.results import RESULTS_FILE, write_results
from simulator.reproduce.runner import ExperimentResult, PaperResult, Settings, ruled

REPOSITORY = Path(__file__).resolve().parents[2]
RECOMPUTE = REPOSITORY / "tools" / "recompute_verdicts.py"


def _measure(dataset, solutions):  # never called: the results below are given
    return {}


# per-seed values giving each word by the rule (six seeds: 6/6 has p = 1/64)
VALUES = {"shown": ([1.0] * 6, [2.0] * 6, None),
          "partly": ([1.0] * 6, [2.0] * 6, m.ev.Magnitude("at least 3 m lower", high=-3.0)),
          "not shown": ([1.0, 3.0] * 3, [2.0] * 6, None)}


def _verdict(status: str) -> Verdict:
    a, b, magnitude = VALUES[status]
    return m.paired_judgement({"a": a, "b": b}, "a", "b", better="lower", kind="difference",
                              unit="m", what=f"because {status}", magnitude=magnitude)


def _result(key: str, statuses: list[str], checks: list[str] = ()) -> PaperResult:
    experiment = Experiment("drive", "quickstart.yaml", {"a": {"name": "dead_reckoning"}},
                            _measure)
    claims = [Claim(f"{key}_claim{i}", f"claim {i} of {key} | with a pipe",
                    f"Table {i}: 1.{i} m", ("simulated", f"condition {i}"), lambda t: None)
              for i in range(len(statuses))]
    claims += [Claim(f"{key}_check{i}", f"check {i} of {key}", "not printed", (),
                     lambda t: None, kind="check") for i in range(len(checks))]
    claims.append(Claim(f"{key}_untestable", "a claim on the real van", "Fig. 12", (),
                        untestable="the van's drive is not printed"))
    paper = Paper(key, f"Title of {key}", f"Author, Journal ({key})", (experiment,),
                  tuple(claims))
    table = pd.DataFrame({"a.error_m": [1.0, 2.0, 4.0]},
                         index=pd.Index([1, 2, 4], name="seed"))
    words = [*statuses, *checks]
    verdicts = {c.key: _verdict(s) for c, s in zip(claims, words, strict=False)}
    return PaperResult(paper, {"drive": ExperimentResult(experiment, table,
                                                         {3: "Traceback ...\nValueError: boom"})},
                       verdicts)


SETTINGS = Settings((1, 2, 3, 4), True, 2, None, 12.0, 20.0, "landnav 0.1.0, commit abc")


def test_report_names_every_claim_in_two_tables_with_its_evidence(tmp_path):
    results = [_result("first", ["shown", "partly", "not shown"], ["shown"]),
               _result("second", ["shown", "shown"])]
    write_report(tmp_path, results, SETTINGS)
    md = (tmp_path / "report.md").read_text()
    page = (tmp_path / "report.html").read_text()
    for r in results:
        for text in (r.paper.title, r.paper.citation):
            assert text in md and text in page
        for claim in r.paper.claims:
            assert claim.key in md and claim.key in page and claim.paper_figure in md
            if claim.key in r.verdicts:
                assert r.verdicts[claim.key].measured in md
    assert "the van's drive is not printed" in md and "**not testable**" in md
    assert "simulated; condition 1" in md
    assert "direction held in 6 of 6 seeds" in md and "95 % bootstrap interval" in md
    assert "one-sided sign test p = 0.0156" in md
    assert "### The paper's claims" in md and "### landnav's checks and controls" in md
    # the check is in its own table, after the paper's claims
    assert md.index("**first_check0**") > md.index("### landnav's checks and controls")
    assert "| first | 1 | 1 | 1 | 1 | 1 | 0 | 0 |" in md
    assert "| second | 2 | 0 | 0 | 1 | 0 | 0 | 0 |" in md
    assert "quick (shortened drives)" in md and "commit abc" in md and "12 s" in md
    assert "| drive | 3 | ValueError: boom |" in md
    assert "with a pipe" in md and "\\|" in md
    assert "issue" not in md.lower() and "session" not in md.lower()
    assert summary_counts(results)["first"] == {"shown": 1, "partly": 1, "not shown": 1,
                                                "not testable": 1}
    assert summary_counts(results, "check")["first"] == {"shown": 1, "partly": 0,
                                                         "not shown": 0}
    assert (tmp_path / "plots" / "first.png").stat().st_size > 1000
    assert "![first: per-seed figures](plots/first.png)" in md


def test_html_is_self_contained(tmp_path):
    write_report(tmp_path, [_result("only", ["shown"])], SETTINGS)
    page = (tmp_path / "report.html").read_text()
    sources = re.findall(r"""(?:src|href)\s*=\s*['"]([^'"]*)""", page)
    assert sources and all(s.startswith("data:image/png;base64,") for s in sources)
    assert "<link" not in page and "<script" not in page


def test_a_word_that_does_not_follow_from_the_evidence_is_replaced_by_the_rules():
    verdict = _verdict("not shown")
    forced = Verdict("shown", verdict.measured, verdict.reason, verdict.evidence,
                     verdict.per_seed)
    assert ruled(forced).status == "not shown" and "is not the rule's" in ruled(forced).reason
    assert ruled(Verdict("shown", "x", "no evidence")).status == "not shown"
    assert ruled(verdict) is verdict


def _recompute(path: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(RECOMPUTE), str(path)], capture_output=True,
                          text=True, timeout=120)


def test_results_json_is_recomputed_by_the_independent_script(tmp_path):
    results = [_result("first", ["shown", "partly", "not shown"], ["shown"])]
    path = write_results(tmp_path / RESULTS_FILE, results, SETTINGS)
    document = json.loads(path.read_text())
    claim = document["claims"]["first.first_claim1"]
    assert claim["kind"] == "paper" and claim["conditions"] == ["simulated", "condition 1"]
    assert claim["per_seed"] == {"a": [1.0] * 6, "b": [2.0] * 6}
    assert claim["evidence"]["wins"] == 6 and claim["verdict"] == "partly"
    assert document["summary"]["paper"] == {"shown": 1, "partly": 1, "not shown": 1,
                                            "not testable": 1}
    assert document["summary"]["check"]["shown"] == 1
    run = _recompute(path)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "0 disagreement(s)" in run.stdout
    # a tampered word, a tampered value: both caught
    claim["verdict"] = "shown"
    document["claims"]["first.first_claim0"]["per_seed"]["a"][0] = 5.0
    path.write_text(json.dumps(document))
    run = _recompute(path)
    assert run.returncode == 1
    assert "first.first_claim1: verdict stored 'shown', the rule gives 'partly'" in run.stdout
    assert "first.first_claim0: wins stored 6, recomputed 5" in run.stdout


def test_per_seed_plot_counts_the_seeds_without_a_figure():
    result = _result("p", ["shown"])
    e = result.experiments["drive"]
    e.table["b.end_m"] = [3.0, float("nan"), float("nan")]  # silent at two seeds' outage ends
    e.table["c.none_m"] = float("nan")  # a figure the filter does not have at all
    ax = Figure().add_subplot()
    _panel(ax, "drive", e)
    assert [t.get_text() for t in ax.get_xticklabels()] == ["a.error_m", "b.end_m (2 missing)"]


def test_the_pages_tables_are_written_from_results_json(tmp_path):
    results = [_result("first", ["shown", "partly"], ["shown"])]
    path = write_results(tmp_path / RESULTS_FILE, results, SETTINGS)
    page = tmp_path / "page.md"
    page.write_text("intro\n<!-- claims: first -->\nold\n<!-- end of claims -->\n"
                    "<!-- summary -->\nold\n<!-- end of summary -->\nend\n")
    run = subprocess.run([sys.executable, str(REPOSITORY / "tools" / "reproduction_tables.py"),
                          str(path), str(page)], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    text = page.read_text()
    assert "old" not in text and text.startswith("intro\n") and text.endswith("end\n")
    assert "| `first_claim1`: claim 1 of first \\| with a pipe | Table 1: 1.1 m |" in text
    assert "6 of 6 seeds in the paper's direction" in text and "**partly**" in text
    assert "**landnav's checks**" in text and "commit abc" in text
    assert "| first | 1 / 1 / 0 / 1 | 1 / 0 / 0 |" in text


def test_the_pages_tables_read_several_runs_each_paper_with_its_own_seeds(tmp_path):
    first = write_results(tmp_path / "first.json", [_result("first", ["shown"])], SETTINGS)
    other_settings = Settings((1, 2, 3, 4, 5), True, 2, None, 12.0, 20.0,
                              "landnav 0.1.0, commit def")
    second = write_results(tmp_path / "second.json", [_result("second", ["not shown"])],
                           other_settings)
    page = tmp_path / "page.md"
    page.write_text("<!-- claims: first -->\n<!-- end of claims -->\n"
                    "<!-- claims: second -->\n<!-- end of claims -->\n"
                    "<!-- summary -->\n<!-- end of summary -->\n")
    run = subprocess.run([sys.executable, str(REPOSITORY / "tools" / "reproduction_tables.py"),
                          str(first), str(second), str(page)], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    text = page.read_text()
    assert "(landnav 0.1.0, commit abc; quick, seeds 1-4, more" in text
    assert "(landnav 0.1.0, commit def; quick, seeds 1-5, more" in text
    assert "seeds 1-4; second: landnav 0.1.0, commit def; quick, seeds 1-5)" in text
    assert "| first | 1 / 0 / 0 / 1 |" in text and "| second | 0 / 0 / 1 / 1 |" in text
