"""Time histories of one seed for the paper-layout figures (``Experiment.history``,
``Paper.figures``) and the panels that draw them.

``error_history`` puts every solution's errors against the truth (the scorer's,
``simulator.scoring.align``) on one time grid: per label the horizontal, north and east errors,
the heading error, the velocity errors, the sensor-error estimates' errors the dataset's truth
has (``err_gyro_scale_factor_z``, ...), and the NEES of the position block (3-D, or the
horizontal one of a 2-D solution; ``simulator.scoring.consistency.block_nees``); and the GNSS
outage windows as a 0/1 column. Values between solution rows are linearly interpolated (a
solution's rows are 10 Hz or faster; the grid is coarser).

The panels draw a history column per label against time with the outages shaded, and the NEES
with the chi-square 95 % band of one epoch.

Public names
------------
HISTORY_STEP_S, OUTAGE, error_history, history_panel, nees_panel, labels_of.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from simulator.dataset.io import Dataset
from simulator.reproduce import measures as m
from simulator.scoring.align import ERR_ATT, ERR_H, ERR_POS, ERR_VEL
from simulator.scoring.consistency import BLOCKS, PLANAR_BLOCKS, block_nees, chi2_band

__all__ = ["HISTORY_STEP_S", "OUTAGE", "error_history", "history_panel", "labels_of",
           "nees_panel"]

HISTORY_STEP_S = 0.5  # s between the rows of a history
OUTAGE = "gnss_outage"  # history column: 1 inside a GNSS outage, 0 outside
_DEG = ("err_yaw", "err_pitch", "err_roll")
_NAVIGATION = {*ERR_POS, ERR_H, *ERR_VEL, *ERR_ATT}  # the other err_ columns: sensor errors


def _on_grid(t: np.ndarray, values: np.ndarray, grid: np.ndarray) -> np.ndarray:
    ok = np.isfinite(values)
    if ok.sum() < 2:
        return np.full(len(grid), np.nan)
    return np.interp(grid, t[ok], values[ok], left=np.nan, right=np.nan)


def _position_nees(errors: pd.DataFrame) -> tuple[np.ndarray, int]:
    position, horizontal = BLOCKS[0], PLANAR_BLOCKS["position"]
    nees = block_nees(errors, position)
    if np.isfinite(nees).any():
        return nees, position.dim
    return block_nees(errors, horizontal), horizontal.dim


def error_history(dataset: Dataset, solutions: Mapping[str, pd.DataFrame],
                  step_s: float = HISTORY_STEP_S) -> pd.DataFrame:
    """The errors of every solution on one grid (module docstring): columns ``t`` (s),
    ``gnss_outage`` (0/1) and per label ``LABEL.err_h``, ``.err_n``, ``.err_e`` (m),
    ``.err_vn``, ``.err_ve`` (m/s), ``.err_yaw_deg``, ``.err_pitch_deg``, ``.err_roll_deg``,
    ``.err_<sensor error>`` (its unit) and ``.nees_position`` with ``.nees_dof``."""
    truth = dataset.read("truth")
    grid = np.arange(float(truth["t"].iloc[0]), float(truth["t"].iloc[-1]) + 1e-9, step_s)
    out = {"t": grid, OUTAGE: m.inside_windows(grid, m.outages(dataset.read("events")))
           .astype(float)}
    for label, solution in solutions.items():
        e = m.errors(dataset, solution)
        t = e["t"].to_numpy(float)
        sensors = [c for c in e.columns if c.startswith("err_") and c not in _NAVIGATION]
        for name in ("err_h", "err_n", "err_e", "err_vn", "err_ve", *sensors):
            out[f"{label}.{name}"] = _on_grid(t, e[name].to_numpy(float), grid)
        for name in _DEG:
            out[f"{label}.{name}_deg"] = _on_grid(t, np.degrees(e[name].to_numpy(float)),
                                                  grid)
        nees, dof = _position_nees(e)
        out[f"{label}.nees_position"] = _on_grid(t, nees, grid)
        out[f"{label}.nees_dof"] = np.full(len(grid), float(dof))
    return pd.DataFrame(out)


def labels_of(history: pd.DataFrame) -> list[str]:
    """The solution labels of a history, in order."""
    return list(dict.fromkeys(c.split(".")[0] for c in history.columns if "." in c))


def _shade(ax: object, history: pd.DataFrame) -> None:
    t, inside = history["t"].to_numpy(), history[OUTAGE].to_numpy() > 0
    edges = np.flatnonzero(np.diff(np.r_[0, inside.astype(int), 0]))
    for start, end in zip(edges[::2], edges[1::2], strict=True):
        ax.axvspan(t[start], t[end - 1], color="0.85", zorder=0)


def history_panel(ax: object, history: pd.DataFrame, labels: Sequence[str], column: str,
                  ylabel: str, title: str = "", absolute: bool = False,
                  names: Mapping[str, str] | None = None) -> None:
    """``LABEL.column`` of each label against time (grey: GNSS outages), ``absolute`` for
    |value|; ``names`` maps labels to legend names."""
    _shade(ax, history)
    for label in labels:
        name = f"{label}.{column}"
        if name in history:
            y = history[name].to_numpy(float)
            ax.plot(history["t"], np.abs(y) if absolute else y, lw=1.0,
                    label=(names or {}).get(label, label))
    ax.set_xlabel("time, s", fontsize=8)
    ax.set_ylabel(ylabel, fontsize=8)
    ax.set_title(title, fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)


def nees_panel(ax: object, history: pd.DataFrame, labels: Sequence[str], title: str,
               names: Mapping[str, str] | None = None) -> None:
    """Position NEES of each label (log axis) with the one-epoch chi-square 95 % band of its
    degrees of freedom (dashed)."""
    history_panel(ax, history, labels, "nees_position", "position NEES", title, names=names)
    ax.set_yscale("log")
    dofs = {int(history[f"{label}.nees_dof"].iloc[0]) for label in labels
            if f"{label}.nees_dof" in history}
    for dof in sorted(dofs):
        for bound in chi2_band(dof):
            ax.axhline(bound, color="k", ls="--", lw=0.7)
