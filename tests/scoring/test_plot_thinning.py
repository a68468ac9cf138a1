"""The report's plots draw long series thinned (``plots.envelope_rows``), and what a reader
must see survives: a peak of one sample, a sigma band's widest point, the breaks of a line,
the CDF within half a pixel; a short series is drawn untouched. The thinned line is checked
against matplotlib's own drawing of every row: the two rasters ink the same pixels, to one
pixel."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from scipy.ndimage import binary_dilation

from simulator.columns import SOLUTION
from simulator.scoring import plots
from simulator.scoring.align import ERR_H, local_ned
from simulator.scoring.evaluate import score_solutions
from simulator.scoring.report import write_report
from tests.scoring_helpers import offset_solution

N_LONG = 200_000  # rows of a long series (ten times the thinning's threshold)


def _wandering(n: int, seed: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times (s), an error that wanders with noise, and a slowly varying sigma."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 600.0, n)
    error = np.cumsum(rng.normal(0.0, 0.01, n)) + rng.normal(0.0, 0.05, n)
    return t, error, 0.5 + 0.1 * np.sin(t / 30.0)


def test_a_short_series_is_drawn_untouched():
    n = plots.THIN_ABOVE_ROWS
    t, error, sigma = _wandering(n)
    t[n // 2:] += 10.0  # a gap: the line breaks there, as before thinning existed
    drawn_t, drawn_error, drawn_sigma = plots.time_series(Figure(), t, error, sigma)
    for drawn, full in ((drawn_t, t), (drawn_error, error), (drawn_sigma, sigma)):
        np.testing.assert_array_equal(drawn, np.insert(full, n // 2, np.nan))
    north_east = np.c_[error, sigma]
    np.testing.assert_array_equal(plots.map_path(Figure(), t, north_east),
                                  np.insert(north_east, n // 2, np.nan, axis=0))
    errors = np.sort(np.abs(error))
    x, y = plots.cdf_steps(Figure(), errors, errors[0], errors[-1])
    np.testing.assert_array_equal(x, errors)
    np.testing.assert_array_equal(y, np.arange(1, n + 1) / n)


def test_a_spike_of_one_sample_survives_thinning():
    t, error, sigma = _wandering(N_LONG)
    error[123_457] = 8.0  # one sample, 3 ms of a 600 s series
    sigma[54_321] = 3.0
    error[150_000] = -5.0
    no_sigma = np.full(N_LONG, np.nan)  # (a solution without this sigma)
    drawn_t, drawn_error, drawn_sigma, drawn_none = plots.time_series(
        Figure(figsize=(9, 7.5)), t, error, sigma, no_sigma)
    assert drawn_t.size < 0.1 * N_LONG  # thinned
    assert np.isnan(drawn_none).all()
    assert drawn_error[drawn_t == t[123_457]] == [8.0]
    assert drawn_error[drawn_t == t[150_000]] == [-5.0]
    assert drawn_sigma[drawn_t == t[54_321]] == [3.0]
    assert (drawn_t[0], drawn_t[-1]) == (t[0], t[-1])  # the time axis is the same
    # the kept rows are rows of the series, in order
    rows = np.searchsorted(t, drawn_t)
    assert np.all(np.diff(rows) > 0)
    np.testing.assert_array_equal(drawn_error, error[rows])
    np.testing.assert_array_equal(drawn_sigma, sigma[rows])


def test_breaks_of_a_line_survive_thinning():
    t, error, _ = _wandering(N_LONG)
    error[50_000:60_000] = np.nan  # the solution has no value there
    t[150_000:] += 30.0  # nor rows here
    drawn_t, drawn_error = plots.time_series(Figure(), t, error)
    missing = np.flatnonzero(np.isnan(drawn_error))
    assert drawn_t[missing[0] - 1] == t[49_999] and drawn_t[missing[-1] + 1] == t[150_000]
    inside = drawn_t[missing]
    assert np.isnan(inside).sum() == 1  # the gap: a NaN inserted
    assert inside[0] == t[50_000] and np.nanmax(inside) == t[59_999]  # the NaN run's ends
    assert drawn_t[np.flatnonzero(np.isnan(drawn_t))[0] - 1] == t[149_999]


def _raster(t: np.ndarray, error: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """The RGB pixels of an error line and its +-3 sigma band as the report draws them."""
    fig = Figure(figsize=(9, 2.5), dpi=110, layout="constrained")
    ax = fig.add_subplot()
    ax.plot(t, error, lw=1.0, color="C0")
    ax.fill_between(t, -3.0 * sigma, 3.0 * sigma, color="C0", alpha=0.15, lw=0)
    ax.set_xlim(0.0, 600.0)
    ax.set_ylim(-10.0, 10.0)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].astype(int)


def test_a_thinned_line_inks_the_pixels_of_every_row():
    t, error, sigma = _wandering(N_LONG // 2)
    error[70_000] = 8.0
    sigma[20_000] = 3.0
    full = _raster(t, error, sigma)
    thinned = _raster(*plots.time_series(Figure(figsize=(9, 2.5)), t, error, sigma))
    for darker_than in (30, 150, 300, 500):  # ink: this much below white (sum of RGB)
        ink_full = full.sum(axis=2) < 3 * 255 - darker_than
        ink_thinned = thinned.sum(axis=2) < 3 * 255 - darker_than
        assert ink_full.sum() > 1000
        assert not (ink_full & ~binary_dilation(ink_thinned)).any()
        assert not (ink_thinned & ~binary_dilation(ink_full)).any()


def test_the_cdf_is_thinned_within_half_a_pixel():
    errors = np.sort(np.random.default_rng(2).lognormal(0.0, 1.5, N_LONG))
    fig = Figure(figsize=(6.5, 4))
    x, y = plots.cdf_steps(fig, errors, 0.05, errors[-1])
    assert x.size < 0.1 * N_LONG
    assert (x[0], x[-1], y[-1]) == (errors[0], errors[-1], 1.0)
    # the drawn step function against the exact one, at every error and between them
    at = np.sort(np.r_[errors, 0.5 * (errors[1:] + errors[:-1])])
    exact = np.searchsorted(errors, at, side="right") / errors.size
    drawn = y[np.searchsorted(x, at, side="right") - 1]
    half_pixel = 1.0 / (2 * 4 * 110)  # of the figure's 4 in height at 110 dpi
    assert np.max(np.abs(drawn - exact)) <= half_pixel


def test_a_map_keeps_a_jump_and_drops_what_is_out_of_view():
    t = np.linspace(0.0, 600.0, N_LONG)
    noise = np.random.default_rng(3).normal(0.0, 0.001, (N_LONG, 2))  # 1 mm, below a pixel
    north_east = np.c_[0.1 * t, 20.0 * np.sin(t / 50.0)] + noise
    north_east[99_999] += 50.0  # one row jumps 50 m north-east
    fig = Figure(figsize=(7, 6))
    path = plots.map_path(fig, t, north_east)
    assert path.shape[0] < 0.2 * N_LONG
    assert np.any(np.all(path == north_east[99_999], axis=1))
    # zoomed on the first 10 m of the path: the rows past it fall in the regions around the
    # view, of which only the first, last and extreme rows of each visit are drawn
    view = (-5.0, 5.0, 0.0, 10.0)
    zoomed = plots.map_path(fig, t, north_east, view)
    def outside(rows: np.ndarray) -> np.ndarray:
        return (rows[:, 0] > 10.0) | (np.abs(rows[:, 1]) > 5.0)

    assert outside(north_east).sum() > 0.95 * N_LONG
    assert outside(zoomed).sum() < 100


@pytest.fixture(scope="module")
def dense_report(quickstart, tmp_path_factory):
    """The report of a 60 000-row solution (the quickstart truth at 300 Hz, 0.5 m off, with
    sigmas, one row 30 m off north) and every figure it drew."""
    truth = quickstart.read("truth")
    t = np.linspace(truth["t"].iloc[0], truth["t"].iloc[-1], 60_000)
    dense = pd.DataFrame({"t": t, **{c: np.interp(t, truth["t"], truth[c]) for c in SOLUTION
                                     if c not in ("t", "yaw")}})
    dense["yaw"] = np.interp(t, truth["t"], np.unwrap(truth["yaw"]))
    dn = np.full(t.size, 0.5)
    dn[31_234] = 30.0
    solution = offset_solution(dense, dpos=(dn, 0.0, 0.0))
    solution[["std_n", "std_e", "std_d"]] = 0.5
    ev = score_solutions(quickstart, {"dense": (solution, None)})
    figures = {}

    def keep(fig, path):
        figures[path.stem] = fig
        fig.savefig(path, dpi=plots._DPI)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(plots, "_save", keep)
        write_report(tmp_path_factory.mktemp("dense"), ev, "dense")
    return ev, figures


def test_every_plot_of_a_long_solution_is_thinned_and_keeps_its_peak(dense_report):
    ev, figures = dense_report
    errors = ev.results["dense"].errors.errors
    for name, fig in figures.items():
        for ax in fig.axes:
            for line in ax.get_lines():
                assert len(line.get_xdata()) < 20_000, (name, line.get_label())
            for band in (c for c in ax.collections if isinstance(c, PolyCollection)):
                assert all(len(p.vertices) < 40_000 for p in band.get_paths()), name

    def line(name: str, label: str = "dense", panel: int = 0) -> Line2D:
        return next(x for x in figures[name].axes[panel].get_lines() if x.get_label() == label)

    north = line("position_errors").get_ydata()
    assert np.nanmax(north) == pytest.approx(errors["err_n"].max()) == pytest.approx(30.0)
    assert np.nanmin(north) == pytest.approx(errors["err_n"].min())
    assert line("horizontal_cdf").get_xdata()[-1] == errors[ERR_H].max()
    t = line("nees").get_xdata()
    assert t[np.nanargmax(line("nees").get_ydata())] == errors["t"].iloc[31_234]
    jump = local_ned(ev.results["dense"].solution.iloc[[31_234]], plots._origin(ev))[0]
    on_map = np.c_[line("map").get_xdata(), line("map").get_ydata()]
    assert np.any(np.all(on_map == [jump[1], jump[0]], axis=1))
