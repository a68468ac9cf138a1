"""The report's consistency section and the plot fixes: NEES per block against the chi-square
band of its dimension, the attitude legend naming every solution, a CDF axis that starts at a
meaningful error, error panels whose range follows the errors, not a +-540 deg sigma band."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import chi2

from simulator.dataset.io import open_dataset
from simulator.scoring.evaluate import score_solutions
from simulator.scoring.report import format_number, write_report
from tests.scoring_helpers import (
    offset_solution,
    quickstart_truth,
    saved_figures,
    write_scoring_dataset,
)

OUTAGES = ((40.0, 60.0), (120.0, 150.0))


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The report of three solutions: a 3-D filter with sigmas (its yaw sigma 180 deg), a 2-D
    filter with horizontal and yaw sigmas, the truth itself; and every figure it drew."""
    truth = quickstart_truth()
    tmp = tmp_path_factory.mktemp("r")
    ds = open_dataset(write_scoring_dataset(tmp / "ds", truth, OUTAGES))
    sub = truth.iloc[::10].reset_index(drop=True)
    rng = np.random.default_rng(11)
    k = len(sub)
    pos, att = rng.standard_normal((k, 3)) * [1.0, 1.0, 2.0], rng.standard_normal((k, 3))
    ins = offset_solution(sub, dpos=tuple(pos.T), datt_deg=tuple(att.T))
    ins[["std_n", "std_e", "std_d"]] = [1.0, 1.0, 2.0]
    ins[["std_vn", "std_ve", "std_vd"]] = 0.1
    ins[["std_roll", "std_pitch"]] = np.radians(1.0)
    ins["std_yaw"] = np.radians(180.0)  # +-540 deg at 3 sigma
    planar = offset_solution(sub, dpos=(0.5, -0.5, 0.0), datt_deg=(0.0, 0.0, 2.0))
    planar[["alt", "roll", "pitch"]] = np.nan
    planar[["std_n", "std_e"]] = 0.5
    planar["std_yaw"] = np.radians(2.0)
    exact = sub[list(ins.columns[:10])]
    fixes = exact.assign(roll=np.nan, pitch=np.nan, yaw=np.nan)  # no attitude at all
    ev = score_solutions(ds, {"ins": (ins, None), "planar": (planar, None),
                              "exact": (exact, None), "fixes": (fixes, None)})
    (tmp / "report").mkdir()
    with saved_figures() as figures:
        text = write_report(tmp / "report", ev, "quickstart").read_text()
    return ev, text, figures


def test_consistency_section_lists_every_block_of_every_filter(written):
    ev, text, _ = written
    section = text.split("## Consistency", 1)[1].split("\n## ", 1)[0]
    ins = ev.results["ins"].scores["consistency"]
    planar = ev.results["planar"].scores["consistency"]
    for label, block, c in (("ins", "position", ins["position"]),
                            ("ins", "attitude", ins["attitude"]),
                            ("planar", "horizontal", planar["horizontal"]),
                            ("planar", "yaw", planar["yaw"])):
        row = next(line for line in section.splitlines()
                   if line.startswith(f"| {label} | {block} |"))
        assert format_number(c["nees"]) in row and format_number(c["inside_95"]) in row
    assert planar["horizontal"]["nees"] == pytest.approx(2.0, abs=1e-3)  # (0.5/0.5)^2 twice
    assert "| exact |" not in section  # no sigmas, no consistency row


def test_nees_plot_has_a_panel_per_block_with_its_chi_square_band(written):
    _, _, figures = written
    axes = figures["nees"].axes
    titles = [ax.get_title() for ax in axes]
    names = [t.split(" ", 1)[0] for t in titles]
    assert names == ["position", "horizontal", "velocity", "attitude", "yaw"]
    for ax, dim in zip(axes, (3, 2, 3, 3, 1), strict=True):
        assert ax.get_yscale() == "log"
        band = next(p for p in ax.patches if "chi-square band" in str(p.get_label()))
        pixels = band.get_transform().transform(band.get_path().vertices)[:, 1]
        bottom, top = ax.transData.inverted().transform(
            [[0, pixels.min()], [0, pixels.max()]])[:, 1]
        assert (bottom, top) == pytest.approx(chi2.ppf([0.025, 0.975], dim), rel=1e-6)
        assert f"{dim} dof" in band.get_label()


def test_attitude_legend_names_every_solution(written):
    _, _, figures = written
    legend = figures["attitude_errors"].axes[0].get_legend()
    labels = {t.get_text() for t in legend.get_texts()}
    assert labels == {"GNSS outage", "ins", "ins ±3σ", "planar", "planar ±3σ", "exact",
                      "fixes: not estimated"}  # planar has no roll, fixes no attitude


def test_a_huge_sigma_band_does_not_flatten_the_errors(written):
    ev, _, figures = written
    yaw_axis = figures["attitude_errors"].axes[2]
    largest = max(np.nanmax(np.abs(np.degrees(r.errors.errors["err_yaw"])))
                  for label, r in ev.results.items() if label != "fixes")
    low, high = yaw_axis.get_ylim()
    assert high == pytest.approx(-low)
    assert largest < high <= 3.0 * largest < 540.0


def test_cdf_axis_starts_at_a_meaningful_error(written):
    ev, _, figures = written
    left = figures["horizontal_cdf"].axes[0].get_xlim()[0]
    exact = ev.results["exact"].errors.errors["err_h"].to_numpy()
    assert np.nanmax(exact) < 1e-6  # the truth itself: errors that mean nothing
    assert left >= 0.01
    ins = ev.results["ins"].errors.errors["err_h"].to_numpy()
    assert left <= np.percentile(ins, 1.0)
