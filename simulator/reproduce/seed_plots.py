"""Panels of the paper-layout figures drawn from the per-seed figure tables (every seed, not
one): a time history as one thin line per seed with the median over seeds on top, and bars of
the mean over seeds with a dot per seed. Used by the ``figures`` of the Chan, Karamat and Park
papers (``Paper.figures``).

Public names
------------
history_columns, seed_lines, seed_bars, new_figure, nees_figure, nees_history_figure.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from simulator.reproduce.histories import labels_of, nees_panel

__all__ = ["history_columns", "nees_figure", "nees_history_figure", "new_figure", "seed_bars",
           "seed_lines"]


def new_figure(panels: int, width_in: float = 4.2, height_in: float = 3.0
               ) -> tuple[Figure, list]:
    """A figure of ``panels`` side-by-side axes."""
    fig = Figure(figsize=(width_in * panels, height_in), layout="constrained")
    axes = fig.subplots(1, panels, squeeze=False)[0]
    return fig, list(axes)


def history_columns(table: pd.DataFrame, pattern: str) -> tuple[np.ndarray, list[str]]:
    """The columns of ``table`` matching ``pattern`` (a regular expression with one group, the
    time in seconds), sorted by that time: (times, column names)."""
    found = sorted((float(mt.group(1)), c) for c in table.columns
                   if (mt := re.fullmatch(pattern, c)))
    return np.array([t for t, _ in found]), [c for _, c in found]


def seed_lines(ax: object, table: pd.DataFrame, pattern: str, label: str, color: str,
               scale: float = 1.0) -> None:
    """One thin line per seed (a row of ``table``) of the history columns matching ``pattern``
    (``history_columns``) against their time, and the median over seeds in bold."""
    t, cols = history_columns(table, pattern)
    if not cols:
        return
    values = table[cols].to_numpy(float) * scale
    for row in values:
        ax.plot(t, row, color=color, lw=0.5, alpha=0.35)
    ax.plot(t, np.nanmedian(values, axis=0), color=color, lw=2.0, label=f"{label} (median)")


def seed_bars(ax: object, groups: Mapping[str, Sequence[float] | np.ndarray],
              colors: Sequence[str] = ("C0", "C1", "C2", "C3", "C4")) -> None:
    """A bar per group at the mean over seeds and a dot per seed."""
    rng = np.random.default_rng(0)  # the dots' horizontal jitter, the same every time
    for k, values in enumerate(groups.values()):
        v = np.asarray(values, float)
        color = colors[k % len(colors)]
        ax.bar(k, np.nanmean(v), color=color, alpha=0.4, width=0.7)
        ax.plot(k + rng.uniform(-0.2, 0.2, len(v)), v, "o", color=color, ms=3)
    ax.set_xticks(range(len(groups)), list(groups), rotation=30, ha="right",
                  rotation_mode="anchor", fontsize=8)


def nees_figure(tables: Mapping[str, pd.DataFrame]) -> list[tuple[str, Figure]]:
    """The position NEES of every filter of every experiment (``LABEL.nees_position`` or
    ``LABEL.nees_horizontal``), a dot per seed, with the consistent filter's 3 (or 2)."""
    nees = {f"{key}: {c.split('.')[0]}": table[c].to_numpy(float)
            for key, table in tables.items() for c in table.columns
            if c.endswith((".nees_position", ".nees_horizontal"))}
    if not nees:
        return []
    fig, axes = new_figure(1, width_in=max(6.0, 0.45 * len(nees)))
    seed_bars(axes[0], nees)
    axes[0].axhline(3.0, color="k", lw=0.8)
    axes[0].axhline(2.0, color="k", lw=0.8, ls=":")
    axes[0].set(ylabel="mean position NEES", yscale="log")
    return [("Position NEES of every filter, a dot per seed (a consistent filter: 3, or 2 for a "
             "2-D one, dotted)", fig)]


def nees_history_figure(histories: Mapping[str, pd.DataFrame]) -> list[tuple[str, Figure]]:
    """The position NEES of every filter against time on the first seed of each experiment
    with a history (``histories.nees_panel``: the one-epoch chi-square 95 % band dashed)."""
    if not histories:
        return []
    fig, axes = new_figure(len(histories), width_in=5.0)
    for ax, (key, history) in zip(axes, histories.items(), strict=True):
        nees_panel(ax, history, labels_of(history), key.replace("_", " "))
    return [("Position NEES against time, first seed (grey: GNSS outages; dashed: the "
             "one-epoch chi-square 95 % band)", fig)]
