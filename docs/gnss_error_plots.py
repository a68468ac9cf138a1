"""The figure of docs/gnss-errors.md: the static ARL1 hour (2015-07-19 00:00-01:00 GPST, real
broadcast file) simulated with the ``geodetic`` and ``automotive`` presets beside the real
station receiver, through the one residual procedure of ``tests/gnss/test_gnss_arl1.py``, and
the second real station's hour (GEONET 0759, 2005-04-02) beside the geodetic preset there.

Run from the repository root (needs ``../shared/refdata`` beside the checkout and georinex):

    PYTHONPATH=.:tests:tests/gnss python docs/gnss_error_plots.py

Writes docs/images/gnss_arl1_residuals.png and prints the figures it plots.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from test_gnss_arl1 import (  # noqa: E402
    ARL1_XYZ,
    ELEVATION_BINS_DEG,
    GSI0759,
    SEEDS,
    _nav,
    _real_observations,
    _simulated,
    autocorrelation,
    navigation,
    real_observations,
    residuals,
    simulated,
    std_by_elevation,
)

OUT = Path(__file__).resolve().parent / "images" / "gnss_arl1_residuals.png"
LAGS_S = np.arange(30, 630, 30)


def main() -> None:
    nav = _nav()
    real = residuals(_real_observations(), nav, ARL1_XYZ)
    geodetic = [residuals(_simulated("geodetic", seed), nav, ARL1_XYZ) for seed in SEEDS]
    automotive = residuals(_simulated("automotive"), nav, ARL1_XYZ)

    fig, axes = plt.subplots(1, 4, figsize=(20, 4.5))
    centres = np.arange(len(ELEVATION_BINS_DEG) - 1)
    labels = [f"{a}-{b}" for a, b in zip(ELEVATION_BINS_DEG[:-1], ELEVATION_BINS_DEG[1:],
                                         strict=True)]
    sims = np.array([std_by_elevation(r) for r in geodetic])
    std_real, std_auto = std_by_elevation(real), std_by_elevation(automotive)
    ax = axes[0]
    ax.bar(centres - 0.27, std_real, 0.27, label="real ARL1 (P1)")
    ax.bar(centres, sims.mean(axis=0), 0.27,
           yerr=[sims.mean(axis=0) - sims.min(axis=0), sims.max(axis=0) - sims.mean(axis=0)],
           label=f"geodetic preset ({len(sims)} seeds, range)")
    ax.bar(centres + 0.27, std_auto, 0.27, label="automotive preset")
    ax.set_xticks(centres, labels)
    ax.set_xlabel("elevation band, deg")
    ax.set_ylabel("pseudorange residual std, m")
    ax.legend()
    ax.set_title("Residual std by elevation")

    ax = axes[1]
    ax.plot(LAGS_S, [autocorrelation(real, lag) for lag in LAGS_S], "k-o", label="real ARL1")
    for seed, r in zip(SEEDS, geodetic, strict=True):
        ax.plot(LAGS_S, [autocorrelation(r, lag) for lag in LAGS_S], alpha=0.6,
                label=f"geodetic, seed {seed}")
    ax.plot(LAGS_S, [autocorrelation(automotive, lag) for lag in LAGS_S], "--",
            label="automotive")
    ax.axhspan(0.3, 0.8, xmin=0, xmax=0.06, color="grey", alpha=0.3)
    ax.set_xlabel("lag, s")
    ax.set_ylabel("autocorrelation (per-satellite mean removed)")
    ax.legend(fontsize=8)
    ax.set_title("Residual autocorrelation")

    ax = axes[2]
    for name, r, style in (("real", real, "-"), ("geodetic", geodetic[0], "--")):
        for sv in sorted(set(real["sv"]) & set(r["sv"]))[:3]:
            one = r[r["sv"] == sv]
            ax.plot(one["tow"] / 60.0, one["pr_res"], style, label=f"{name} G{sv:02d}")
    ax.set_xlabel("minutes of 2015-07-19 GPST")
    ax.set_ylabel("pseudorange residual, m")
    ax.legend(fontsize=8, ncol=2)
    ax.set_title("Residuals over the hour")
    ax = axes[3]
    nav_gsi = navigation(GSI0759)
    real_gsi = std_by_elevation(residuals(real_observations(GSI0759), nav_gsi, GSI0759.xyz,
                                          week=GSI0759.week))
    sims_gsi = np.array([std_by_elevation(residuals(simulated(GSI0759, "geodetic", seed),
                                                    nav_gsi, GSI0759.xyz, week=GSI0759.week))
                         for seed in SEEDS])
    ax.bar(centres - 0.2, real_gsi, 0.4, label="real GSI 0759 (C1, 2005)")
    ax.bar(centres + 0.2, sims_gsi.mean(axis=0), 0.4,
           yerr=[sims_gsi.mean(axis=0) - sims_gsi.min(axis=0),
                 sims_gsi.max(axis=0) - sims_gsi.mean(axis=0)],
           label=f"geodetic preset there ({len(sims_gsi)} seeds, range)")
    ax.plot(centres, std_real, "k_", markersize=20, mew=2, label="real ARL1 (2015)")
    ax.set_xticks(centres, labels)
    ax.set_xlabel("elevation band, deg")
    ax.set_ylabel("pseudorange residual std, m")
    ax.legend(fontsize=8)
    ax.set_title("A second real station")
    fig.tight_layout()
    OUT.parent.mkdir(exist_ok=True)
    fig.savefig(OUT, dpi=90)
    print("std by band real", np.round(std_real, 2), "geodetic mean", np.round(sims.mean(0), 2),
          "automotive", np.round(std_auto, 2))
    print("autocorrelation at 30 / 60 s: real", round(autocorrelation(real, 30), 2),
          round(autocorrelation(real, 60), 2), "geodetic",
          [round(autocorrelation(r, 30), 2) for r in geodetic],
          "automotive", round(autocorrelation(automotive, 30), 2))
    print("GSI 0759 std by band real", np.round(real_gsi, 2), "geodetic mean",
          np.round(sims_gsi.mean(0), 2))
    print("wrote", OUT)


if __name__ == "__main__":
    main()
