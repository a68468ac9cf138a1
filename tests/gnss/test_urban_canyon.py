"""The shipped urban canyon (scenarios/urban_canyon.yaml: a 1 km street between 40 m facades,
25 m apart) under the physical NLOS model: how many satellites the receiver keeps there, how
many of them arrive by reflection or diffraction only, and how good its fixes are.

Issue 19 asks for at least 7 tracked satellites on average with at least 30 % of them NLOS and a
CEP50 of 5-20 m (the Berlin u-blox log of refdata 3d: 9.9 GPS satellites tracked, 53 % NLOS).
Measured over seeds 1-5 (``PYTHONPATH=. python -m simulator.cli generate
scenarios/urban_canyon.yaml -o OUT --seed N``): 5.4-5.9 tracked of the 9 above the mask,
66-68 % NLOS (95 % of them reflected, 5 % diffracted only), CEP50 8.5-11.6 m. The count falls
short: with continuous facades 1.6 times as high as the street is wide, a satellite across the
street needs 47 deg of elevation even to be reflected (tan(el) >= H / (1.5 w)); below that both
the direct and the reflected path are diffracted deep into the roof's shadow (over 25 dB).
Berlin's streets are about as wide as their eaves are high and have gaps and cross streets; this
model has neither (the scenario was not changed to make the figure appear)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from simulator.earth import geodetic_to_ecef, ned_to_ecef_matrix
from simulator.pipeline import generate, load_scenario

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "urban_canyon.yaml"
SEEDS = (1, 2, 3)


@pytest.fixture(scope="module")
def canyon_figures(tmp_path_factory):
    tracked, nlos, errors = [], [], []
    for seed in SEEDS:
        out = tmp_path_factory.mktemp(f"seed{seed}") / "dataset"
        data = generate(load_scenario(SCENARIO, seed=seed), out)
        truth = data.read("truth").set_index("t")
        tg, fix = data.read("truth_gnss"), data.read("gnss_fix")
        zone = truth["zone"].reindex(tg["t"].to_numpy(), method="nearest").to_numpy()
        inside = tg[(zone == "downtown") & (tg["tracked"] == 1)]
        epochs = tg.loc[zone == "downtown", "t"].nunique()
        tracked.append(len(inside) / epochs)
        nlos.append(inside["nlos"].mean())
        fix = fix[truth["zone"].reindex(fix["t"].to_numpy(), method="nearest").to_numpy()
                  == "downtown"]
        fix = fix[fix["fix"] > 0]
        k = truth.reindex(fix["t"].to_numpy(), method="nearest")
        lat, lon = np.radians(k["lat"].to_numpy()), np.radians(k["lon"].to_numpy())
        d = (geodetic_to_ecef(np.radians(fix["lat"].to_numpy()), np.radians(fix["lon"].to_numpy()),
                              fix["alt"].to_numpy())
             - geodetic_to_ecef(lat, lon, k["alt"].to_numpy()))
        ned = np.einsum("nji,nj->ni", ned_to_ecef_matrix(lat, lon), d)
        errors.append(np.hypot(ned[:, 0], ned[:, 1]))
    return pd.Series({"tracked": np.mean(tracked), "nlos": np.mean(nlos),
                      "cep50": np.median(np.concatenate(errors))})


def test_canyon_keeps_many_satellites_as_nlos_only(canyon_figures):
    assert canyon_figures["nlos"] >= 0.30  # measured 0.66-0.68


def test_canyon_fixes_have_a_plausible_cep50(canyon_figures):
    assert 5.0 <= canyon_figures["cep50"] <= 20.0  # measured 8.5-11.6 m per seed


@pytest.mark.xfail(strict=True, reason="measured 5.4-5.9 tracked satellites on average (goal "
                                       "7): continuous facades 1.6 times the street's width; "
                                       "see the module docstring")
def test_canyon_keeps_at_least_seven_tracked_satellites(canyon_figures):
    assert canyon_figures["tracked"] >= 7.0
