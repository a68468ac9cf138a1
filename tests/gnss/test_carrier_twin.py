"""The real baseline's twin (refdata 1c/1d): the shipped scenario geonet_baseline_twin (a static
base at GEONET 0759, a static rover at 3040, 2005-04-02 00:00-00:59:30 GPST, 0759's navigation
file, geodetic preset on GPS L1/L2) exported as RINEX and processed by RTKLIB kinematic with the
options of the refdata README, beside the real pair processed the same way in the same test.

Claims: at least 95 % of epochs fixed; at most 2 cm 3-D RMS about the true rover position; the
double-difference residual std per elevation band (15-30/30-45/45-90 deg) and frequency within
0.6-1.6 x the real ones. Seed 1, as the scenario ships; the figures of seeds 1-3 are in
docs/gnss-carrier.md."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from tests.gnss.rtklib import kinematic, need_rnx2rtkp, residual_std_by_band

BASE_F3_XYZ = np.array([-3976219.1454, 3382371.6073, 3652511.1964])  # refdata 1c
SCENARIO = "geonet_baseline_twin.yaml"


@pytest.fixture(scope="module")
def processed(tmp_path_factory):
    from tests.conftest import SHARED

    if not (SHARED / "refdata").is_dir():
        pytest.skip(f"reference data not available: {SHARED / 'refdata'} is absent "
                    "(a user's clone has no ../shared; CI has it)")
    shared = SHARED
    need_rnx2rtkp()
    from simulator.dataset.export import export_rinex
    from simulator.dataset.io import open_dataset
    from simulator.pipeline import generate, load_scenario
    from tests.conftest import REPO

    work = tmp_path_factory.mktemp("twin")
    generate(load_scenario(REPO / "scenarios" / SCENARIO), work / "twin", show_progress=False)
    dataset = open_dataset(work / "twin")
    obs, nav = export_rinex(dataset, work / "rinex")
    base = json.loads((work / "twin" / "manifest.json").read_text())["gnss_base"]
    real_dir = shared / "refdata" / "gnss"
    sim = kinematic(obs, obs.with_name("twin_base.obs"),
                    real_dir / "gsi0759_2005-04-02_rtklib" / "07590920.05n",
                    np.array([base["x"], base["y"], base["z"]]), work / "twin.pos")
    real = kinematic(real_dir / "gsi3040_2005-04-02_rtklib" / "30400920.05o",
                     real_dir / "gsi0759_2005-04-02_rtklib" / "07590920.05o",
                     real_dir / "gsi0759_2005-04-02_rtklib" / "07590920.05n", BASE_F3_XYZ,
                     work / "real.pos")
    truth = pd.read_parquet(work / "twin" / "truth_gnss.parquet")
    rover = truth[["antenna_x", "antenna_y", "antenna_z"]].iloc[0].to_numpy()
    fixed = sim["q"] == 1
    figures = {"fixed": fixed.mean(), "epochs": len(fixed),
               "rms_3d": float(np.sqrt(np.mean(np.sum((sim["xyz"][fixed] - rover) ** 2, 1))))}
    for freq in (1, 2):
        for kind in ("carrier", "code"):
            s = residual_std_by_band(sim["sat"], freq, kind)
            r = residual_std_by_band(real["sat"], freq, kind)
            figures[f"{kind} L{freq}"] = (s, r, s / r)
    print(f"\ntwin: {fixed.sum()}/{len(fixed)} fixed, 3-D RMS {100 * figures['rms_3d']:.1f} cm "
          f"(real: {(real['q'] == 1).sum()}/{len(real['q'])} fixed)")
    for key, value in figures.items():
        if isinstance(value, tuple):
            s, r, ratio = value
            print(f"{key}: twin {np.round(s, 4)}, real {np.round(r, 4)} m, ratio "
                  f"{np.round(ratio, 2)} (bands 15-30/30-45/45-90)")
    return figures


def test_twin_fixes_at_least_95_percent_of_epochs(processed):
    assert processed["epochs"] >= 110
    assert processed["fixed"] >= 0.95


@pytest.mark.parametrize("key", ["carrier L1", "carrier L2", "code L1", "code L2"])
def test_twin_double_difference_residuals_lie_within_0_6_to_1_6_of_the_real_ones(processed, key):
    """The P2 code's ratio sits at the lower bound: with the GNSS draws before each error
    process had its own stream, seeds 1-3 gave 0.48, 0.62 and 0.57 x the real std in the
    30-45 deg band (docs/gnss-carrier.md), and seed 1 of the present streams lies within the
    bound; which side a seed falls on is its draw, so the claim for P2 is at its edge."""
    ratio = processed[key][2]
    assert np.all((ratio >= 0.6) & (ratio <= 1.6)), ratio


def test_twin_fixed_solution_within_2_cm_rms(processed):
    assert processed["rms_3d"] <= 0.02
