"""The list of claims of the Chan, Karamat and Park reproduction documents, generated from the
paper modules (``simulator/reproduce/{chan,karamat2015,park2019}.py``): every claim with its
figure, kind, the deciding condition it is swept over or why it cannot be tested. Writes
between the markers ``<!-- claims:begin -->`` and ``<!-- claims:end -->`` of
``docs/reproduction_{paper}.md``. A run's words go into the pages' ``<!-- claims: PAPER -->``
blocks by ``tools/reproduction_tables.py``.

Usage: ``PYTHONPATH=. python docs/reproduction_claims.py``
"""

from __future__ import annotations

from pathlib import Path

from simulator.reproduce.papers import load_paper
from simulator.scoring.report import markdown_table

REPO = Path(__file__).resolve().parents[1]
PAPERS = {"chan": "reproduction_chan.md", "karamat2015": "reproduction_karamat2015.md",
          "park2019": "reproduction_park2019.md"}
BEGIN, END = "<!-- claims:begin -->", "<!-- claims:end -->"


def _cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def claims_table(key: str) -> str:
    """The paper's claims as a Markdown table."""
    header = ["claim", "kind", "the paper", "deciding condition / why untestable"]
    rows = []
    for claim in load_paper(key).claims:
        swept = [c for c in claim.conditions if "(the default:" in c or "(swept;" in c]
        kind = "variant" if claim.variant_of else claim.kind
        rows.append([_cell(c) for c in (f"**{claim.key}**: {claim.text}", kind,
                                        claim.paper_figure,
                                        claim.untestable or "; ".join(swept))])
    return "\n".join(markdown_table(header, rows))


def main() -> None:
    for key, name in PAPERS.items():
        path = REPO / "docs" / name
        text = path.read_text()
        head, rest = text.split(BEGIN, 1)
        _, tail = rest.split(END, 1)
        path.write_text(f"{head}{BEGIN}\n{claims_table(key)}\n{END}{tail}")


if __name__ == "__main__":
    main()
