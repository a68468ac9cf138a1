"""Write the claims tables of the per-paper reproduction pages from a ``landnav reproduce`` run's
results.json, so the pages' figures are those of the report run.

Each page (docs/reproduction_PAPER.md) holds a block between the lines
``<!-- claims: PAPER -->`` and ``<!-- end of claims -->``; this script replaces the block by
the run's table of that paper's claims (the paper's claims, the claims under other values of a
deciding condition, landnav's checks), headed by the run's software, commit and seeds. A block
between ``<!-- summary -->`` and ``<!-- end of summary -->`` (docs/reproduction.md) gets the
run's summary: per paper its claims and landnav's checks by word, counted apart.

Usage::

    python tools/reproduction_tables.py RUN/results.json docs/reproduction_cho2006.md ...

Several runs (one per paper, say) are read as one: name each results.json before the pages.

A page without a block is left as it is and named; exit status 1 then, 0 otherwise.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

START = "<!-- claims: {paper} -->"
END = "<!-- end of claims -->"


def _cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def _evidence(claim: dict) -> str:
    e = claim["evidence"]
    if e is None:
        return "none"
    unit = f" {e['unit']}" if e["unit"] else ""
    kind = {"difference": "median paired difference", "ratio": "median paired ratio",
            "value": "median value"}[e["kind"]]

    def number(x: float | None) -> str:
        return "none" if x is None else f"{x:.3g}"

    extras = "".join([f", {e['ties']} ties" if e["ties"] else "",
                      f", {e['missing']} without a value" if e["missing"] else ""])
    return (f"{e['wins']} of {e['n']} seeds in the paper's direction{extras}; "
            f"{kind} {number(e['effect'])}{unit} (95 % interval {number(e['ci_low'])} to "
            f"{number(e['ci_high'])}{unit}); sign test p = {e['p_sign']:.3g}")


def table(document: dict, paper: str) -> list[str]:
    """The markdown lines of ``paper``'s claims in ``document`` (results.json)."""
    claims = [c for c in document["claims"].values() if c["paper"] == paper]
    lines = [f"Figures of `landnav reproduce` ({_run(document, paper)}, more "
             "where an experiment asks for them), written from its results.json by "
             "`tools/reproduction_tables.py`.", ""]
    groups = (("The paper's claims", lambda c: c["kind"] == "paper" and not c["variant_of"]),
              ("Under other values of a deciding condition", lambda c: bool(c["variant_of"])),
              ("landnav's checks", lambda c: c["kind"] == "check" and not c["variant_of"]))
    for title, keep in groups:
        rows = [c for c in claims if keep(c)]
        if not rows:
            continue
        lines += [f"**{title}**", "", "| claim | paper | landnav | evidence | word |",
                  "|---|---|---|---|---|"]
        for c in rows:
            head = f"`{c['claim']}`" + (f" ({c['variant']})" if c["variant"] else "")
            word = c["verdict"] + (f": {c['reason']}" if c["verdict"] == "not testable" else "")
            lines.append("| " + " | ".join(_cell(x) for x in (
                f"{head}: {c['statement']}", c["paper_figure"], c["measured"] or "none",
                _evidence(c), f"**{word}**")) + " |")
        lines.append("")
    return lines


def summary(document: dict) -> list[str]:
    """The markdown lines of the run's summary: per paper its claims and landnav's checks by
    word, counted apart."""
    words = ("shown", "partly", "not shown", "not testable")
    lines = [f"Summary of `landnav reproduce` ({_run(document)}), written from its results.json by "
             "`tools/reproduction_tables.py`.", "",
             "| paper | claims: " + " / ".join(words) + " | checks: shown / partly / not shown |",
             "|---|---|---|"]
    for paper, counts in document["summary"]["per_paper"].items():
        claims = " / ".join(str(counts["paper"].get(w, 0)) for w in words)
        checks = " / ".join(str(counts["check"].get(w, 0)) for w in words[:3])
        lines.append(f"| {paper} | {claims} | {checks} |")
    return lines


def rewrite(page: Path, document: dict) -> bool:
    """Replace the claims blocks (and a summary block) of ``page``; False when it has
    none."""
    text = page.read_text(encoding="utf-8")
    found = False
    for match in reversed(list(re.finditer(r"<!-- claims: (\w+) -->\n.*?<!-- end of claims "
                                           r"-->", text, re.S))):
        paper = match.group(1)
        block = "\n".join([START.format(paper=paper), *table(document, paper), END])
        text = text[:match.start()] + block + text[match.end():]
        found = True
    match = re.search(r"<!-- summary -->\n.*?<!-- end of summary -->", text, re.S)
    if match is not None:
        block = "\n".join(["<!-- summary -->", *summary(document), "<!-- end of summary -->"])
        text = text[:match.start()] + block + text[match.end():]
        found = True
    page.write_text(text, encoding="utf-8")
    return found


def combined(documents: list[dict]) -> dict:
    """One results document of several runs: their claims and per-paper summaries together,
    each paper's software and seeds kept with it (``by_paper``)."""
    first = documents[0]
    document = {**first, "claims": {}, "summary": {"per_paper": {}}, "by_paper": {}}
    for other in documents:
        if other["quick"] != first["quick"]:
            raise SystemExit("the runs mix --quick and full runs")
        document["claims"].update(other["claims"])
        document["summary"]["per_paper"].update(other["summary"]["per_paper"])
        for paper in other["summary"]["per_paper"]:
            document["by_paper"][paper] = {"software": other["software"],
                                           "seeds": other["seeds"]}
    return document


def _run(document: dict, paper: str | None = None) -> str:
    """The software and seeds of ``paper``'s run, or of the runs (the papers named where
    they differ from the first)."""
    def words(run: dict) -> str:
        quick = "quick, " if document["quick"] else ""
        return f"{run['software']}; {quick}seeds {run['seeds'][0]}-{run['seeds'][-1]}"

    by_paper = document.get("by_paper", {})
    if paper is not None:
        return words(by_paper.get(paper, document))
    others = [f"{p}: {words(r)}" for p, r in by_paper.items() if words(r) != words(document)]
    return words(document) + "".join(f"; {o}" for o in others)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", type=Path, nargs="+",
                        help="one or more results.json of landnav reproduce runs, then the pages")
    args = parser.parse_args(argv)
    runs = [f for f in args.files if f.suffix == ".json"]
    pages = [f for f in args.files if f.suffix != ".json"]
    if not runs or not pages:
        parser.error("name at least one results.json and one page")
    document = combined([json.loads(f.read_text(encoding="utf-8")) for f in runs])
    status = 0
    for page in pages:
        if not rewrite(page, document):
            print(f"{page}: no '<!-- claims: PAPER -->' block", file=sys.stderr)
            status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
