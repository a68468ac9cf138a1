"""The numbers behind the "Not shown" analysis of docs/gnss-errors.md: the ARL1 static hour's
residual std by elevation band with the geodetic preset's terms changed one at a time, the
spread of the satellites' hour-mean residuals above 30 deg, and the true ionosphere against
Klobuchar from the station's dual-frequency code (P2 - P1), beside the simulated one, the real
P1 residual split by that code into its ionosphere and ionosphere-free parts, and the
broadcast orbit and clock against the NGA precise ephemeris of the same day along ARL1's lines
of sight (the hour's signal-in-space error as the precise product gives it).

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
from test_gnss_orbits import read_sp3_positions

from simulator.earth import ecef_to_geodetic, ned_to_ecef_matrix
from simulator.gnss.constants import C_M_S, SECONDS_PER_WEEK
from simulator.gnss.ephemeris import ephemeris_arrays, gather, satellite_state, select_ephemeris
from simulator.gnss.fix import primary_rows
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


def broadcast_against_precise(nav: pd.DataFrame) -> pd.DataFrame:
    """Signal-in-space error of the broadcast orbit and clock along ARL1's lines of sight over
    the hour, against the NGA precise ephemeris (refdata 1a, 300 s, antenna phase centre,
    ionosphere-free clocks): (broadcast - precise) . los - c (broadcast clock - precise clock),
    the broadcast clock without its relativistic term and T_GD (both products' clocks are
    ionosphere-free and leave the periodic relativistic term to the user), elevation above
    10 deg, the mean over the satellites of each epoch removed (the clock datums differ by a
    constant). By tow and sv; sign as a residual (measured minus modelled) sees it."""
    sp3 = read_sp3_positions(FOLDER / "test_input_sp3_nav_2015_200.sp3")
    tow = sp3["epoch"].to_numpy() - WEEK * SECONDS_PER_WEEK
    sp3 = sp3[tow <= 3600.0]
    tow = tow[tow <= 3600.0]
    eph = ephemeris_arrays(nav, WEEK)
    idx = select_ephemeris(eph, sp3["sv"].to_numpy(), tow)
    ok = idx >= 0
    rec = gather(eph, idx[ok])
    state = satellite_state(rec, tow[ok])
    precise = sp3[["x", "y", "z"]].to_numpy()[ok]
    los = precise - ARL1_XYZ
    los /= np.linalg.norm(los, axis=1)[:, None]
    lat, lon, _ = ecef_to_geodetic(ARL1_XYZ)
    el = np.degrees(np.arcsin(-(los @ ned_to_ecef_matrix(lat, lon))[:, 2]))
    clock = state["clock_s"] - state["relativistic_s"] + rec["tgd"]
    sis = (np.einsum("ni,ni->n", state["pos"] - precise, los)
           - C_M_S * (clock - sp3["clock_s"].to_numpy()[ok]))
    out = pd.DataFrame({"tow": tow[ok], "sv": sp3["sv"].to_numpy()[ok], "el": el,
                        "sis_res": -sis})[el > 10.0]
    out["sis_res"] -= out.groupby("tow")["sis_res"].transform("mean")
    return out


def ionosphere_against_klobuchar(nav: pd.DataFrame, real: pd.DataFrame) -> pd.DataFrame:
    """The true L1 ionosphere against the broadcast (Klobuchar) delay K, a K + b fitted (b
    takes the receiver's bias), for the station (from its dual-frequency code) and for the
    geodetic preset's simulated hour (seed 1), printed; the real residuals with both. The
    simulated receiver's L1 C/A rows only (``primary_rows``: its L2 and L5 rows carry their own
    signal's delay, (f_L1 / f)^2 times L1's)."""
    lat, lon, alt = ecef_to_geodetic(ARL1_XYZ)
    start = {"lat": float(np.degrees(lat)), "lon": float(np.degrees(lon)), "alt": float(alt),
             "heading": 0.0}
    truth = drive([{"stop": {"duration": 3570}}], start=start, utc=gps_to_utc(WEEK, 0.0),
                  rate_hz=1.0)
    out = receiver(preset="geodetic", rate=1 / 30, constellation=str(FOLDER / "arlm200a.15n")
                   ).generate(truth, np.random.default_rng(1))
    keys = ["t", "sv", "signal"]
    sim = primary_rows(out["gnss_raw"]).merge(out["truth_gnss"][keys + ["iono_true"]], on=keys)
    both = real.merge(dual_frequency_iono(nav), on=["tow", "sv"]).merge(
        sim.rename(columns={"t": "tow"})[["tow", "sv", "iono", "iono_true"]], on=["tow", "sv"])
    design = np.column_stack([both["iono"], np.ones(len(both))])
    for name, column in (("real (dual-frequency)", "iono_dual"), ("simulated, seed 1",
                                                                  "iono_true")):
        coef, *_ = np.linalg.lstsq(design, both[column], rcond=None)
        left = both[column] - design @ coef
        print(f"{name}: ionosphere = {coef[0]:.2f} K + {coef[1]:.2f} m, the rest's std "
              f"{left.std():.2f} m ({len(both)} residuals)")
    return both


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
              f"{min(spread):.2f}-{max(spread):.2f} m")
    print(f"real hour-mean spread above 30 deg: {hour_mean_spread(real):.2f} m")

    # the hour's signal-in-space error as the NGA precise ephemeris gives it
    sis = broadcast_against_precise(nav)
    by_sv = sis.groupby("sv").agg(el=("el", "mean"), mean=("sis_res", "mean"),
                                  std=("sis_res", "std"))
    print("broadcast minus NGA precise along ARL1's lines of sight, per satellite (m):")
    print(by_sv.round(2).T.to_string())
    print(f"  rms {np.sqrt((sis['sis_res'] ** 2).mean()):.2f} m; hour-mean spread above 30 deg "
          f"{by_sv.loc[by_sv['el'] > 30, 'mean'].std(ddof=0):.2f} m")
    merged = real.merge(sis[["tow", "sv", "sis_res"]],
                        on=["tow", "sv"])
    for sign, name in ((-1.0, "the real residuals minus it"), (1.0, "plus it")):
        corrected = merged.assign(pr_res=merged["pr_res"] + sign * merged["sis_res"])
        corrected["pr_res"] -= corrected.groupby("tow")["pr_res"].transform("mean")
        print(f"  {name}: hour-mean spread above 30 deg {hour_mean_spread(corrected):.2f} m "
              f"(as filed {hour_mean_spread(merged):.2f} m, at the SP3 epochs)")

    both = ionosphere_against_klobuchar(nav, real)

    # the real P1 residual split by the station's own dual-frequency code: its ionosphere and
    # T_GD part (I_dual - K) and what is left, the ionosphere-free residual (signal in space,
    # troposphere, multipath); each epoch's mean removed from each part
    parts = both.assign(iono_part=both["iono_dual"] - both["iono"])
    parts["free_part"] = parts["pr_res"] - parts["iono_part"]
    for key in ("pr_res", "iono_part", "free_part"):
        parts[key] -= parts.groupby("tow")[key].transform("mean")
    print("real hour-mean spread above 30 deg: P1 residual "
          f"{hour_mean_spread(parts):.2f} m = ionosphere and T_GD part "
          f"{hour_mean_spread(parts.assign(pr_res=parts['iono_part'])):.2f} m + "
          "ionosphere-free part "
          f"{hour_mean_spread(parts.assign(pr_res=parts['free_part'])):.2f} m")
    means = parts.assign(el=np.degrees(parts["elevation"])).groupby("sv")[
        ["el", "iono_part", "free_part"]].mean()
    high = means[means["el"] > 30.0]
    print(f"  their correlation over the satellites above 30 deg: "
          f"{np.corrcoef(high['iono_part'], high['free_part'])[0, 1]:.2f}")


if __name__ == "__main__":
    main()
