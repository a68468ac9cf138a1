"""The shipped urban canyon (scenarios/urban_canyon.yaml: 1 km of a Berlin centre street, eaves
22 m high, 22 m wide, closed perimeter blocks of 20 m plots with 22 m cross streets every 110 m,
building heights spread 3 m; sources in the scenario's comment) under the physical NLOS model:
how many satellites the receiver keeps there, how many of them arrive by reflection or
diffraction only, and how good its fixes are.

Issue 19 asks for at least 7 tracked satellites on average with at least 30 % of them NLOS and a
CEP50 of 5-20 m (the Berlin u-blox log of refdata 3d: 9.9 GPS satellites tracked, 53 % NLOS, the
weakest at 21-23 dB-Hz). Measured (``PYTHONPATH=. python -m simulator.cli generate
scenarios/urban_canyon.yaml -o OUT --seed N``; figures inside the ``downtown`` zone): seeds 1-3
9.44 tracked of the 10 above the mask, 58 % NLOS, CEP50 7.0 m; seeds 4-8 9.52, 58 %, 7.2 m.
Before the facades' diffuse scattering (``scattering_coefficient`` 0: specular reflections and
diffraction over the roofs only) the same street kept 6.94 (seeds 1-3), 42-44 % NLOS, CEP50
8.5-9.7 m: a satellite 10-20 deg up across the street has no specular path (a single reflection
needs 31 deg, a double one 20 deg) and loses 35 dB or more diffracting over the roof, so only
26 % of the 10-20 deg samples were kept; the lit upper part of the facade across the street
scatters enough of it to keep 85 % at 18-30 dB-Hz, as the real log's weakest satellites. The
simulated NLOS signals are 14.3 dB below the LOS ones (real log 15.6 dB).
What the street's parts do (geometric optics only, seeds 1-3): the same street with continuous
facades of one height (no cross streets, no height spread) keeps 6.73-7.00 with 45-47 % NLOS and
CEP50 10.9-11.9 m; the former street (40 m facades 25 m apart, in Seoul) with 110 m blocks and
20 m cross streets keeps 5.6-6.0."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from simulator.earth import geodetic_to_ecef, ned_to_ecef_matrix
from simulator.pipeline import generate, load_scenario

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "urban_canyon.yaml"
BERLIN_LOG = (Path(__file__).resolve().parents[3] / "shared" / "refdata" / "vehicle"
              / "smartloc_berlin_2016-06-06" / "tu_chemnitz_berlin_1_raw.csv")
SEEDS = (1, 2, 3)


@pytest.fixture(scope="module")
def canyon_figures(tmp_path_factory):
    tracked, nlos, errors, cn0_los, cn0_nlos = [], [], [], [], []
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
        raw = data.read("gnss_raw").merge(inside[["t", "sv", "nlos"]], on=["t", "sv"])
        cn0_los.append(raw.loc[raw["nlos"] == 0, "cn0"])
        cn0_nlos.append(raw.loc[raw["nlos"] == 1, "cn0"])
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
                      "cep50": np.median(np.concatenate(errors)),
                      "drop": pd.concat(cn0_los).mean() - pd.concat(cn0_nlos).mean()})


def test_canyon_keeps_many_satellites_as_nlos_only(canyon_figures):
    assert canyon_figures["nlos"] >= 0.30  # measured 0.58


def test_canyon_fixes_have_a_plausible_cep50(canyon_figures):
    assert 5.0 <= canyon_figures["cep50"] <= 20.0  # measured 7.0 m


def test_canyon_keeps_at_least_seven_tracked_satellites(canyon_figures):
    print(f"tracked satellites in the canyon, mean: {canyon_figures['tracked']:.2f}")
    assert canyon_figures["tracked"] >= 7.0  # measured 9.44


def test_canyon_nlos_signals_lose_what_the_berlin_log_shows(canyon_figures):
    """The NLOS signals' C/N0 below the LOS ones' against the Berlin u-blox log with NLOS
    labels (refdata 3d: 15.6 dB): within 3 dB (measured 14.3 dB). The reflection loss's mean
    was set from the log, the scattered and diffracted paths' losses from physics, so the
    drop of the mixture is a check, not a fit."""
    log = BERLIN_LOG
    if not log.exists():
        pytest.skip(f"reference data {log} not available (needs the shared/ folder beside the "
                    "repository checkout)")
    real = pd.read_csv(log, sep=";")
    real = real[real.iloc[:, 24] == "GPS"]  # gnssId
    cn0, label = real.iloc[:, 28], real.iloc[:, -1].astype(str)
    real_drop = cn0[label == "0"].mean() - cn0[label == "1"].mean()
    print(f"NLOS below LOS: real {real_drop:.1f} dB, simulated {canyon_figures['drop']:.1f} dB")
    assert 14.0 < real_drop < 17.0
    assert abs(canyon_figures["drop"] - real_drop) < 3.0
