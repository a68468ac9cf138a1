"""The receiver's reported fix accuracy (``std_*`` of ``gnss_fix``, ``simulator.gnss.fix``)
against the truth it does not see: in a street canyon with reflected (NLOS) signals, the
fraction of |error| / reported 1-sigma within 1, 2 and 3 (68, 95, 99.7 % for an honest Gaussian
report), and the same report without the reflections' terms, which misses them.

The drive is not the one the receiver's extra-path model was taken from (scenarios/
urban_canyon.yaml): a 35 m street canyon 18 m wide like benchmarks/consistency/canyon.yaml.
Measured on that drive, seeds 1-5 (epochs with a reflected signal in the fix, 429): north
0.85 / 0.99 / 0.998, east 0.80 / 0.98 / 0.995, down 0.58 / 0.98 / 1.0; velocity 0.69-0.73 /
0.96-0.98 / 0.998. The bounds below are wide for the time correlation of the errors (one street
of reflections is a few independent draws, not a hundred)."""

from __future__ import annotations

import numpy as np
import pytest
from gnss_helpers import drive, receiver

from simulator.earth import ecef_to_geodetic, geodetic_to_ecef, ned_to_ecef_matrix
from simulator.gnss.fix import receiver_fixes

CANYON = {"sky": "canyon", "building_height": 35.0, "building_height_spread": 8.0,
          "street_width": 18.0, "block_length": 80.0, "cross_street_width": 18.0,
          "facade_length": 15.0, "building_gap": 2.0}
SEGMENTS = [{"stop": {"duration": 5}}, {"accelerate": {"to_speed": 10.0, "accel": 1.5}},
            {"straight": {"length": 500, "zone": "street"}},
            {"turn": {"angle": 90, "radius": 15, "zone": "street"}},
            {"straight": {"length": 350, "zone": "street"}}]
SEEDS = (1, 2)


def _errors(out: dict, fix) -> tuple[np.ndarray, np.ndarray]:
    """NED position errors of the fixes against the true antenna, and the NLOS count."""
    tg = out["truth_gnss"]
    antenna = tg.groupby("t")[["antenna_x", "antenna_y", "antenna_z"]].first()
    nlos = tg[tg["tracked"] == 1].groupby("t")["nlos"].sum()
    fix = fix[fix["fix"] == 2]
    truth = antenna.reindex(fix["t"].to_numpy()).to_numpy()
    lat, lon, _ = ecef_to_geodetic(truth)
    got = geodetic_to_ecef(np.radians(fix["lat"]), np.radians(fix["lon"]), fix["alt"])
    err = np.einsum("nji,nj->ni", ned_to_ecef_matrix(lat, lon), got - truth)
    return err, nlos.reindex(fix["t"].to_numpy()).fillna(0).to_numpy()


@pytest.fixture(scope="module")
def canyon():
    """Per seed: the errors, the reported sigmas with the receiver's model and without it (the
    measurements' own 1-sigmas only), the NLOS counts."""
    truth = drive(SEGMENTS, zones={"street": CANYON}, start={"lat": 40.758, "lon": -73.9855,
                                                             "alt": 20.0, "heading": 120.0})
    gnss = receiver(preset="automotive")
    rows = []
    for seed in SEEDS:
        out = gnss.generate(truth, np.random.default_rng(seed))
        fix = out["gnss_fix"]
        bare = receiver_fixes(fix["t"].to_numpy(), out["gnss_raw"])
        err, nlos = _errors(out, fix)
        keep = fix["fix"].to_numpy() == 2
        rows.append((err, fix.loc[keep, ["std_n", "std_e", "std_d"]].to_numpy(),
                     bare.loc[keep, ["std_n", "std_e", "std_d"]].to_numpy(), nlos))
    return [np.concatenate(x) for x in zip(*rows, strict=True)]


def test_the_reported_accuracy_covers_the_reflected_fixes(canyon):
    err, std, _, nlos = canyon
    reflected = nlos > 0
    assert reflected.sum() > 60  # the street reflects: the test sees what it is about
    z = np.abs(err[reflected]) / std[reflected]
    within = [(z < k).mean(axis=0) for k in (1, 2, 3)]
    assert ((within[0] > 0.4) & (within[0] < 0.97)).all(), within[0]
    assert (within[1] > 0.85).all(), within[1]
    assert (within[2] > 0.95).all(), within[2]
    assert (np.mean(z**2, axis=0) < 3.0).all()


def test_without_the_reflections_model_the_report_misses_them(canyon):
    err, _, bare, nlos = canyon
    reflected = nlos > 0
    z = np.abs(err[reflected]) / bare[reflected]
    # the height sinks by metres the budget does not hold: outside the consistency goal of 3
    # (measured 5.2 on seeds 1-2)
    assert np.mean(z[:, 2] ** 2) > 3.0


def test_a_2d_fix_reports_no_vertical_accuracy():
    truth = drive([{"stop": {"duration": 30}}], rate_hz=1.0)
    out = receiver(preset="automotive").generate(truth, np.random.default_rng(3))
    raw = out["gnss_raw"]
    keep = (raw.groupby("t").cumcount() < np.where(raw["t"] >= 15, 3, 99)).to_numpy()
    fix = receiver_fixes(out["gnss_fix"]["t"].to_numpy(), raw[keep])
    two_d = fix["fix"] == 1
    assert two_d.any() and fix.loc[two_d, ["std_d", "std_vd"]].isna().all().all()
    assert (fix.loc[two_d, ["std_n", "std_e", "std_vn", "std_ve"]] > 0).all().all()
