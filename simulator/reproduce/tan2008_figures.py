"""Tan et al. 2008's figures redrawn from landnav's seed-1 history, in the paper's layout: Fig. 9
(the north-east trajectory: the GPS fixes dotted, the INS/GPS solution solid, the 400-470 s
blockage inset), Fig. 10 ((a) north and (b) east velocity against GPS's), Figs. 6-7 (the
heading standing still without and with the filter's standstill updates), and the position
NEES of every configuration.

Public names
------------
history, figures.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from simulator.dataset.io import Dataset
from simulator.earth import ecef_to_ned, geodetic_to_ecef
from simulator.reproduce.histories import OUTAGE, error_history, history_panel, nees_panel

__all__ = ["figures", "history"]

NAMES = {"full": "NHC + height + magnetometer", "constraints": "NHC + height",
         "free": "no aiding in the outage", "closed": "closed loop in the outage",
         "no_standstill": "without the standstill updates"}


def _north_east(table: pd.DataFrame, origin: tuple[float, float, float]) -> np.ndarray:
    xyz = geodetic_to_ecef(np.radians(table["lat"].to_numpy(float)),
                           np.radians(table["lon"].to_numpy(float)),
                           table["alt"].to_numpy(float))
    return ecef_to_ned(xyz, *origin)[:, :2]


def history(dataset: Dataset, solutions: Mapping[str, pd.DataFrame]) -> pd.DataFrame:
    """Seed 1's errors of every configuration (``histories.error_history``) with, on the same
    grid, the north/east position (m from the start) and velocity of the truth, the GPS fixes
    (NaN between fixes and in outages) and each configuration's solution."""
    out = error_history(dataset, solutions)
    grid = out["t"].to_numpy()
    truth = dataset.read("truth")
    origin = (np.radians(truth["lat"].iloc[0]), np.radians(truth["lon"].iloc[0]),
              float(truth["alt"].iloc[0]))
    fixes = dataset.read("gnss_fix")
    tables = {"truth": truth, **solutions}
    extra = {}
    for name, table in tables.items():
        t = table["t"].to_numpy(float)
        ne = _north_east(table, origin)
        for k, axis in enumerate(("north_m", "east_m")):
            extra[f"{name}.{axis}"] = np.interp(grid, t, ne[:, k], left=np.nan, right=np.nan)
        for axis in ("vn", "ve"):
            extra[f"{name}.{axis}"] = np.interp(grid, t, table[axis].to_numpy(float),
                                                left=np.nan, right=np.nan)
    nearest = np.clip(np.searchsorted(grid, fixes["t"].to_numpy(float)), 0, len(grid) - 1)
    ne = _north_east(fixes, origin)
    for k, axis in enumerate(("north_m", "east_m")):
        extra[f"gps.{axis}"] = np.full(len(grid), np.nan)
        extra[f"gps.{axis}"][nearest] = ne[:, k]
    for axis in ("vn", "ve"):
        extra[f"gps.{axis}"] = np.full(len(grid), np.nan)
        extra[f"gps.{axis}"][nearest] = fixes[axis].to_numpy(float)
    return pd.concat([out, pd.DataFrame(extra)], axis=1)


def _fig9(h: pd.DataFrame) -> Figure:
    fig = Figure(figsize=(10, 4.6), layout="constrained")
    whole, inset = fig.subplots(1, 2)
    outage = h[OUTAGE].to_numpy() > 0
    near = np.convolve(outage, np.ones(121), mode="same") > 0  # the outage and 30 s around
    for ax, rows, title in ((whole, slice(None), "trajectory"),
                            (inset, near, "the blockage, 400-470 s")):
        ax.plot(h["gps.east_m"][rows], h["gps.north_m"][rows], ".", ms=2, color="0.4",
                label="GPS fixes")
        ax.plot(h["truth.east_m"][rows], h["truth.north_m"][rows], color="k", lw=0.6,
                label="truth")
        for label in ("full", "constraints", "free"):
            ax.plot(h[f"{label}.east_m"][rows], h[f"{label}.north_m"][rows], lw=1.0,
                    label=NAMES[label])
        ax.set_xlabel("east, m", fontsize=8)
        ax.set_ylabel("north, m", fontsize=8)
        ax.set_title(title, fontsize=9)
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
    inset.legend(fontsize=7)
    fig.suptitle("Tan et al. Fig. 9 layout, seed 1", fontsize=10)
    return fig


def _fig10(h: pd.DataFrame) -> Figure:
    fig = Figure(figsize=(10, 3.4), layout="constrained")
    for ax, axis, title in zip(fig.subplots(1, 2), ("vn", "ve"),
                               ("(a) north velocity", "(b) east velocity"), strict=True):
        ax.plot(h["t"], h[f"gps.{axis}"], ".", ms=2, color="0.4", label="GPS")
        history_panel(ax, h, ("full",), axis, "m/s", title, names=NAMES)
    fig.suptitle("Tan et al. Fig. 10 layout, seed 1 (grey: the blockage)", fontsize=10)
    return fig


def _standstill(h: pd.DataFrame) -> Figure:
    fig = Figure(figsize=(10, 3.2), layout="constrained")
    ax = fig.subplots()
    still = h["t"] <= 70.0
    history_panel(ax, h[still], ("no_standstill", "full"), "err_yaw_deg", "heading error, deg",
                  "heading standing still (cf. Figs. 6-7), seed 1", names=NAMES)
    return fig


def figures(histories: Mapping[str, pd.DataFrame], tables: Mapping[str, pd.DataFrame]
            ) -> list[tuple[str, Figure]]:
    """The paper-layout figures (seed 1 of the outage experiment)."""
    if "outage" not in histories:
        return []
    h = histories["outage"]
    nees = Figure(figsize=(10, 3.0), layout="constrained")
    nees_panel(nees.subplots(), h, [k for k in NAMES if f"{k}.nees_position" in h],
               "position NEES of every configuration, seed 1 (dashed: one epoch's "
               "chi-square 95 % band)", NAMES)
    return [("Tan et al. Fig. 9 layout: trajectory with the 70 s blockage, seed 1", _fig9(h)),
            ("Tan et al. Fig. 10 layout: velocities against GPS, seed 1", _fig10(h)),
            ("Tan et al. Figs. 6-7: heading standing still without and with the standstill "
             "updates, seed 1", _standstill(h)),
            ("Position NEES of every Tan configuration, seed 1", nees)]
