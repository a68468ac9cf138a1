"""The README's picture of a report: ``landnav run scenarios/quickstart.yaml`` into a temporary
folder, then the top of its report (the first rows of the metrics table) beside two of its
plots (the map and the north/east/down errors), as ``docs/images/quickstart_report.png``.

Usage: ``PYTHONPATH=. python docs/report_picture.py``
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import matplotlib.image as mpimg
from matplotlib.figure import Figure

from simulator import pipeline

REPO = Path(__file__).resolve().parents[1]
OUT = REPO / "docs" / "images" / "quickstart_report.png"
ROWS = ("horizontal RMS (m)", "horizontal CEP95 (m)", "vertical RMS (m)", "yaw RMS (deg)",
        "coverage (fraction of the drive)")


def _metrics(report_md: str) -> tuple[list[str], list[list[str]]]:
    """The header and the chosen rows of the report's metrics table."""
    lines = [line for line in report_md.splitlines() if line.startswith("| ")]
    header = [c.strip() for c in lines[0].strip("|").split("|")]
    rows = [[c.strip() for c in line.strip("|").split("|")] for line in lines[1:]]
    return header, [row for row in rows if row[0] in ROWS]


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        scenario = pipeline.load_scenario(REPO / "scenarios" / "quickstart.yaml")
        run = Path(tmp) / "quickstart"
        pipeline.run(scenario, run)
        header, rows = _metrics((run / "report.md").read_text())
        fig = Figure(figsize=(13, 7.5), dpi=100)
        grid = fig.add_gridspec(2, 2, height_ratios=[1, 3])
        table_ax = fig.add_subplot(grid[0, :])
        table_ax.axis("off")
        table_ax.set_title("runs/quickstart/report.html: the metrics, then every plot",
                           loc="left")
        table = table_ax.table(cellText=rows, colLabels=header, loc="center", cellLoc="left")
        table.auto_set_font_size(False)
        table.set_fontsize(9)
        for i, name in enumerate(("map", "position_errors")):
            ax = fig.add_subplot(grid[1, i])
            ax.imshow(mpimg.imread(run / "plots" / f"{name}.png"))
            ax.axis("off")
        fig.tight_layout()
        OUT.parent.mkdir(exist_ok=True)
        fig.savefig(OUT)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
