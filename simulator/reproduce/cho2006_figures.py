"""Cho & Choi 2006's figures redrawn from landnav's seed-1 histories, in the paper's layout:
Fig. 7 (situation I: (a) position error, (b) heading error, (c) accelerometer and (d) z-gyro
scale-factor estimation errors, EKF against SPKF; panel (e), the scale-factor covariance, is
replaced by the position NEES), Fig. 8 (situation II from -140 deg: heading and position
errors), Fig. 9 (situation III: position and heading errors around the 75-90 s blockage), the
van runs of Figs. 12-15 (error after the GPS loss from 0, -70 and -140 deg), and the NEES of
every filter of every experiment.

Public names
------------
history, figures.
"""

from __future__ import annotations

from collections.abc import Mapping

import pandas as pd
from matplotlib.figure import Figure

from simulator.dataset.io import Dataset
from simulator.reproduce.histories import error_history, history_panel, labels_of, nees_panel

__all__ = ["figures", "history"]

NAMES = {"ekf": "EKF", "spkf": "SPKF (simplex)", "spkf_sym": "SPKF (symmetric)",
         "ekf_m140": "EKF from -140 deg", "spkf_m140": "SPKF from -140 deg",
         "ekf_m70": "EKF from -70 deg", "spkf_m70": "SPKF from -70 deg",
         "drm1": "DRM1 (stand-alone after the loss)", "drm2": "DRM2 EKF"}


def history(dataset: Dataset, solutions: Mapping[str, pd.DataFrame]) -> pd.DataFrame:
    """Seed 1's errors of every entry (``histories.error_history``)."""
    return error_history(dataset, solutions)


def _fig7(h: pd.DataFrame) -> Figure:
    fig = Figure(figsize=(10, 7.5), layout="constrained")
    axes = fig.subplots(3, 2).ravel()
    labels = ("ekf", "spkf", "spkf_sym")
    panels = [("err_h", "position error, m", "(a) position error", True),
              ("err_yaw_deg", "heading error, deg", "(b) heading error", False),
              ("err_accel_scale_factor_x", "estimated - true", "(c) accelerometer scale "
               "factor", False),
              ("err_gyro_scale_factor_z", "estimated - true", "(d) z-gyro scale factor", False)]
    for ax, (column, unit, title, absolute) in zip(axes, panels, strict=False):
        history_panel(ax, h, labels, column, unit, title, absolute, NAMES)
    nees_panel(axes[4], h, labels, "(e) horizontal NEES (the paper: covariance)", NAMES)
    axes[5].set_axis_off()
    fig.suptitle("Situation I (cf. Cho & Choi Fig. 7), seed 1, fixes at the paper's R level",
                 fontsize=10)
    return fig


def _two_panels(h: pd.DataFrame, labels: tuple[str, ...], title: str) -> Figure:
    fig = Figure(figsize=(10, 3.4), layout="constrained")
    left, right = fig.subplots(1, 2)
    history_panel(left, h, labels, "err_yaw_deg", "heading error, deg", "heading error",
                  names=NAMES)
    history_panel(right, h, labels, "err_h", "position error, m", "position error",
                  names=NAMES)
    right.set_yscale("symlog", linthresh=10)
    fig.suptitle(title, fontsize=10)
    return fig


def _nees(histories: Mapping[str, pd.DataFrame]) -> Figure:
    fig = Figure(figsize=(10, 2.6 * len(histories)), layout="constrained")
    axes = fig.subplots(len(histories), 1, squeeze=False)[:, 0]
    for ax, (key, h) in zip(axes, histories.items(), strict=True):
        nees_panel(ax, h, labels_of(h), f"{key}: position NEES of every filter (dashed: "
                                        "one epoch's chi-square 95 % band)")
    return fig


def figures(histories: Mapping[str, pd.DataFrame], tables: Mapping[str, pd.DataFrame]
            ) -> list[tuple[str, Figure]]:
    """The paper-layout figures of the histories present (seed 1)."""
    out = []
    if "situation1" in histories:
        out.append(("Cho & Choi Fig. 7 layout: situation I, EKF against SPKF (simplex and "
                    "symmetric point sets), seed 1", _fig7(histories["situation1"])))
    if "situation2" in histories:
        out.append(("Cho & Choi Fig. 8 layout: situation II from -140 deg, seed 1",
                    _two_panels(histories["situation2"], ("ekf_m140", "spkf_m140"),
                                "Situation II (cf. Fig. 8), seed 1")))
    if "situation3" in histories:
        out.append(("Cho & Choi Fig. 9 layout: situation III, GPS blocked 75-90 s (grey), "
                    "seed 1", _two_panels(histories["situation3"], ("ekf", "spkf", "spkf_sym"),
                                          "Situation III (cf. Fig. 9), seed 1")))
    if "dr_outage" in histories:
        out.append(("Cho & Choi Figs. 12-15 (van runs) on the simulated curved drive: "
                    "stand-alone DRM1 and DRM2, and DRM2 EKF / SPKF from -70 and -140 deg; GPS "
                    "lost in the grey span, seed 1",
                    _two_panels(histories["dr_outage"], tuple(labels_of(histories["dr_outage"])),
                                "Van runs on the simulated drive (cf. Figs. 12-15), seed 1")))
    out.append(("Position NEES of every Cho filter, seed 1", _nees(histories)))
    return out
