"""The claim tables of the Chan, Karamat and Park reproduction documents, generated: every claim
of the paper module (``simulator/reproduce/{chan,karamat2015,park2019}.py``) with its figure,
kind and conditions swept, and, given a run's ``results.json``, its word, evidence and the run's
software line. Writes between the markers ``<!-- claims:begin -->`` and ``<!-- claims:end -->``
of ``docs/reproduction_{paper}.md``.

Usage: ``PYTHONPATH=. python docs/reproduction_claims.py [RUN_DIR/results.json]``
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from simulator.reproduce.papers import load_paper
from simulator.scoring.report import markdown_table

REPO = Path(__file__).resolve().parents[1]
PAPERS = {"chan": "reproduction_chan.md", "karamat2015": "reproduction_karamat2015.md",
          "park2019": "reproduction_park2019.md"}
BEGIN, END = "<!-- claims:begin -->", "<!-- claims:end -->"


def _cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def claims_table(key: str, results: dict | None) -> str:
    """The paper's claims as a Markdown table (with the run's words when ``results`` given)."""
    paper = load_paper(key)
    header = ["claim", "kind", "the paper", "deciding condition / why untestable"]
    if results:
        header += ["word", "evidence"]
    rows = []
    for claim in paper.claims:
        swept = [c for c in claim.conditions if "(the default:" in c or "(swept;" in c]
        note = claim.untestable or "; ".join(swept)
        kind = "variant" if claim.variant_of else claim.kind
        row = [f"**{claim.key}**: {claim.text}", kind, claim.paper_figure, note]
        if results:
            entry = results["claims"].get(f"{key}.{claim.key}")
            ev = (entry or {}).get("evidence") or {}
            row += [(entry or {}).get("verdict", "not run"),
                    (f"{ev.get('wins')}/{ev.get('n')} seeds, effect {ev.get('effect'):.3g} "
                     f"[{ev.get('ci_low'):.3g}, {ev.get('ci_high'):.3g}], p = "
                     f"{ev.get('p_sign'):.2g}") if ev else ""]
        rows.append([_cell(c) for c in row])
    stamp = (f"Words from the run of {results['software']} over seeds {results['seeds'][0]}-"
             f"{results['seeds'][-1]}{' (quick)' if results.get('quick') else ''}.\n\n"
             if results else "")
    return stamp + "\n".join(markdown_table(header, rows))


def main(argv: list[str]) -> None:
    results = json.loads(Path(argv[0]).read_text()) if argv else None
    for key, name in PAPERS.items():
        path = REPO / "docs" / name
        text = path.read_text()
        head, rest = text.split(BEGIN, 1)
        _, tail = rest.split(END, 1)
        path.write_text(f"{head}{BEGIN}\n{claims_table(key, results)}\n{END}{tail}")


if __name__ == "__main__":
    main(sys.argv[1:])
