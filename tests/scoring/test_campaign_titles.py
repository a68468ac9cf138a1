"""Campaign box plots: a long score title is wrapped to the figure, never clipped."""

from __future__ import annotations

import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg

from simulator.campaign import report
from tests.scoring_helpers import saved_figures


def test_long_titles_fit_inside_the_figure(tmp_path):
    runs = pd.DataFrame({"label": ["a", "a", "b"], "status": ["ok"] * 3,
                         "outages.end_horizontal": [1.0, 2.0, 3.0]})
    summary = {"groups": [{"label": "a", "sweep": {}}, {"label": "b", "sweep": {}}],
               "sweep": {}}
    title = "horizontal error at the end of GNSS outages (m)"
    with saved_figures() as figures:
        report._box_plot(runs, summary, "outages.end_horizontal", title, tmp_path / "x.png")
    fig = figures["x"]
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    width, height = fig.bbox.width, fig.bbox.height
    ax = fig.axes[0]
    for text in (ax.title, ax.yaxis.label):
        box = text.get_window_extent(renderer)
        assert box.x0 >= 0 and box.x1 <= width and box.y0 >= 0 and box.y1 <= height, text
    assert "over the runs" in ax.get_title()
