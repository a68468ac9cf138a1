"""The numbers behind the "Not shown" analysis of docs/gnss-errors.md: the ARL1 static hour's
residual std by elevation band with the geodetic preset's terms changed one at a time, the
spread of the satellites' hour-mean residuals above 30 deg, and the true ionosphere against
Klobuchar from the station's dual-frequency code (P2 - P1), beside the simulated one.

Run from the repository root (needs ``../shared/refdata`` beside the checkout and georinex):

    PYTHONPATH=.:tests:tests/gnss python docs/gnss_arl1_budget.py
"""

from __future__ import annotations

import warnings

import georinex
import numpy as np
import pandas as pd
from gnss_helpers import drive, receiver
from test_gnss_arl1 import (
    ARL1_XYZ,
    FOLDER,
    SEEDS,
    WEEK,
    _nav,
    _real_observations,
    _simulated,
    residuals,
    std_by_elevation,
)

from simulator.earth import ecef_to_geodetic
from simulator.gnss.constants import C_M_S, SECONDS_PER_WEEK
from simulator.timebase import gps_to_utc

CASES = {
    "SIS 0.5 m (the preset)": {},
    "SIS 0.7 m (Montenbruck et al. 2015)": {"sis_error": 0.7},
    "SIS 0.2 m": {"sis_error": 0.2},
    "no SIS error": {"sis_error": 0.0},
    "no ionosphere variation": {"iono_residual": 0.0},
    "the ionosphere alone": {"sis_error": 0.0, "multipath": 0.0, "tracking_noise": 0.0,
                             "tropo_residual": 0.0},
}
# L1 / L2 frequency ratio squared (IS-GPS-200): P2 - P1 = (GAMMA - 1) (I_L1 + c T_GD) + receiver
GAMMA = (1575.42 / 1227.60) ** 2


def hour_mean_spread(res: pd.DataFrame) -> float:
    """rms spread about their mean of the satellites' hour-mean residuals above 30 deg."""
    by_sv = res.assign(el=np.degrees(res["elevation"])).groupby("sv")[["pr_res", "el"]].mean()
    return float(by_sv.loc[by_sv["el"] > 30.0, "pr_res"].std(ddof=0))


def dual_frequency_iono(nav: pd.DataFrame) -> pd.DataFrame:
    """The station's L1 ionosphere from P2 - P1 with the broadcast T_GD (the receiver's own
    P1-P2 bias left in: a constant), by tow and sv."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        ds = georinex.load(FOLDER / "arlm200a.15o", meas=["P1", "P2"])
    frame = ds.to_dataframe().reset_index().dropna(subset=["P1", "P2"])
    frame = frame[frame["sv"].str.startswith("G")]
    tow = (frame["time"] - pd.Timestamp(1980, 1, 6)).dt.total_seconds() - WEEK * SECONDS_PER_WEEK
    sv = frame["sv"].str[1:].astype(int).to_numpy()
    tgd = nav.groupby("sv")["tgd"].first()
    iono = (frame["P2"] - frame["P1"]).to_numpy() / (GAMMA - 1.0) - C_M_S * tgd.loc[sv].to_numpy()
    return pd.DataFrame({"tow": tow.to_numpy(), "sv": sv, "iono_dual": iono})


def main() -> None:
    nav = _nav()
    real = residuals(_real_observations(), nav, ARL1_XYZ)
    print("residual std by band 10-20 / 20-30 / 30-45 / 45-90 deg, m")
    print(f"  real ARL1: {np.round(std_by_elevation(real), 2)}")
    for name, overrides in CASES.items():
        sims = [residuals(_simulated("geodetic", seed, **overrides), nav, ARL1_XYZ)
                for seed in SEEDS]
        std = np.mean([std_by_elevation(s) for s in sims], axis=0)
        spread = [hour_mean_spread(s) for s in sims]
        print(f"  {name}: {np.round(std, 2)}; hour-mean spread above 30 deg "
              f"{np.round(spread, 2)}")
    print(f"real hour-mean spread above 30 deg: {hour_mean_spread(real):.2f} m")

    # the true ionosphere against Klobuchar: a K + b fitted (b takes the receiver's bias)
    lat, lon, alt = ecef_to_geodetic(ARL1_XYZ)
    start = {"lat": float(np.degrees(lat)), "lon": float(np.degrees(lon)), "alt": float(alt),
             "heading": 0.0}
    truth = drive([{"stop": {"duration": 3570}}], start=start, utc=gps_to_utc(WEEK, 0.0),
                  rate_hz=1.0)
    out = receiver(preset="geodetic", rate=1 / 30, constellation=str(FOLDER / "arlm200a.15n")
                   ).generate(truth, np.random.default_rng(1))
    sim = out["gnss_raw"].merge(out["truth_gnss"][["t", "sv", "iono_true"]], on=["t", "sv"])
    both = real.merge(dual_frequency_iono(nav), on=["tow", "sv"]).merge(
        sim.rename(columns={"t": "tow"})[["tow", "sv", "iono", "iono_true"]], on=["tow", "sv"])
    design = np.column_stack([both["iono"], np.ones(len(both))])
    for name, column in (("real (dual-frequency)", "iono_dual"), ("simulated, seed 1",
                                                                  "iono_true")):
        coef, *_ = np.linalg.lstsq(design, both[column], rcond=None)
        left = both[column] - design @ coef
        print(f"{name}: ionosphere = {coef[0]:.2f} K + {coef[1]:.2f} m, the rest's std "
              f"{left.std():.2f} m ({len(both)} residuals)")


if __name__ == "__main__":
    main()
