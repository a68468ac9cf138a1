"""``gnss_wls`` on epochs built from known geometry: exact pseudoranges of two systems with
their own clocks give the position to the millimetre and each clock; one faulty pseudorange is
excluded by the residual test; pseudorange errors with an ionosphere part common to the
satellites give position errors whose spread its sigmas match (a Monte Carlo); on the
quickstart dataset it lies within a metre of the truth."""

from __future__ import annotations

import numpy as np

from estimators.builtin.gnss_wls import GnssWls
from estimators.toolbox.gnss_model import predict
from simulator.earth import ecef_to_geodetic, geodetic_to_ecef, ned_to_ecef_matrix

COLUMNS = ("t", "sv", "pseudorange", "pseudorange_rate", "sat_x", "sat_y", "sat_z", "sat_vx",
           "sat_vy", "sat_vz", "sat_clock", "sat_clock_drift", "iono", "tropo", "cn0",
           "pseudorange_std", "system_code", "frequency")


def _epoch(rx: np.ndarray, clocks: dict[int, float], fault_m: float = 0.0) -> np.ndarray:
    rng = np.random.default_rng(4)
    n = 12
    directions = rng.normal(size=(n, 3))
    directions[:, 2] = np.abs(directions[:, 2]) + 0.3  # above the horizon at the pole
    lat, lon, _ = ecef_to_geodetic(rx)
    up = rx / np.linalg.norm(rx)
    basis = np.linalg.qr(np.column_stack([up, rng.normal(size=(3, 2))]))[0]
    los = (directions / np.linalg.norm(directions, axis=1, keepdims=True)) @ np.column_stack(
        [basis[:, 1], basis[:, 2], basis[:, 0]]).T
    sat = rx + 2.2e7 * los
    vel = rng.normal(scale=2000.0, size=(n, 3))
    code = np.where(np.arange(n) < 7, ord("G"), ord("E")).astype(float)
    geometric, rate, _ = predict(sat, vel, rx, np.zeros(3))
    pr = geometric + np.array([clocks[int(c)] for c in code])
    pr[3] += fault_m
    block = np.column_stack([np.zeros(n), np.arange(1, n + 1), pr, rate, sat, vel,
                             np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                             np.full(n, 45.0), np.full(n, 1.0), code, np.full(n, 1575.42e6)])
    return block


def _estimator(datasheet: dict | None = None) -> GnssWls:
    columns = {"gnss_raw": {c: i for i, c in enumerate(COLUMNS)}}
    return GnssWls({"elevation_mask": 0.0}, None, columns, {"gnss_raw": {}},
                   datasheet=datasheet)


def test_exact_ranges_give_position_and_one_clock_per_system():
    rx = geodetic_to_ecef(np.radians(48.0), np.radians(11.0), 500.0).ravel()
    est = _estimator()
    est.on_gnss_raw(0.0, _epoch(rx, {ord("G"): 1.0e5, ord("E"): 1.0e5 + 37.0}))
    row = dict(zip(GnssWls.output_columns, est.solution(0.0), strict=True))
    got = geodetic_to_ecef(np.radians(row["lat"]), np.radians(row["lon"]), row["alt"]).ravel()
    np.testing.assert_allclose(got, rx, atol=1e-3)
    assert abs(row["clock_bias"] - 1.0e5) < 1e-3
    np.testing.assert_allclose([row["vn"], row["ve"], row["vd"]], 0.0, atol=1e-6)
    assert row["num_sats"] == 12
    assert all(row[k] > 0 for k in ("std_n", "std_e", "std_d"))


def test_a_faulty_pseudorange_is_excluded():
    rx = geodetic_to_ecef(np.radians(48.0), np.radians(11.0), 500.0).ravel()
    est = _estimator()
    est.on_gnss_raw(0.0, _epoch(rx, {ord("G"): 0.0, ord("E"): 0.0}, fault_m=150.0))
    row = dict(zip(GnssWls.output_columns, est.solution(0.0), strict=True))
    got = geodetic_to_ecef(np.radians(row["lat"]), np.radians(row["lon"]), row["alt"]).ravel()
    np.testing.assert_allclose(got, rx, atol=1e-3)
    assert row["num_sats"] == 11


def test_sigmas_match_errors_with_a_common_ionosphere_part():
    """The automotive receiver's ionosphere residual: |1.5 - 1| of each broadcast delay common
    to the satellites (simulator.datasheet), the field 1.5 x 0.2 of it and 0.5 m each
    satellite's own. Errors drawn from that covariance, 400 epochs: the mean (error / sigma)^2
    per axis is 1 within 0.3 (a mean of 400 chi-square(1) draws has a standard deviation of
    0.07). Read as independent (no datasheet), the horizontal sigmas are over 1.4 times the
    errors (mean (error / sigma)^2 under 0.5)."""
    rx = geodetic_to_ecef(np.radians(48.0), np.radians(11.0), 500.0).ravel()
    clean = _epoch(rx, {ord("G"): 0.0, ord("E"): 0.0})
    iono = np.linspace(3.0, 9.0, len(clean))
    common = 0.5 * iono
    clean[:, COLUMNS.index("iono")] = iono
    clean[:, COLUMNS.index("pseudorange")] += iono  # the broadcast delay, which it removes
    clean[:, COLUMNS.index("pseudorange_std")] = np.hypot(0.5, np.hypot(0.5, 0.3) * iono)
    rng = np.random.default_rng(7)
    sheet = {"gnss": {"iono_scale": 1.5, "iono_residual": 0.2}}
    lat, lon, _ = ecef_to_geodetic(rx)
    c_en = ned_to_ecef_matrix(lat, lon).T
    ratios = {True: [], False: []}
    for _ in range(400):
        block = clean.copy()
        own = rng.normal(size=len(block)) * np.hypot(0.5, 0.3 * iono)
        block[:, COLUMNS.index("pseudorange")] += own + common * rng.normal()
        for with_sheet in (True, False):
            est = _estimator(sheet if with_sheet else None)
            est.on_gnss_raw(0.0, block)
            row = dict(zip(GnssWls.output_columns, est.solution(0.0), strict=True))
            got = geodetic_to_ecef(np.radians(row["lat"]), np.radians(row["lon"]),
                                   row["alt"]).ravel()
            ratios[with_sheet].append(c_en @ (got - rx)
                                      / [row["std_n"], row["std_e"], row["std_d"]])
    nse = np.mean(np.square(ratios[True]), axis=0)
    assert np.all(np.abs(nse - 1.0) < 0.3), nse
    assert np.all(np.mean(np.square(ratios[False]), axis=0)[:2] < 0.5)


def test_on_the_quickstart_drive(quickstart):
    from simulator import pipeline

    solved = pipeline.run_estimators(quickstart, {"gnss_wls": None})
    scores = pipeline.score(quickstart, solved).scores()["gnss_wls"]
    assert scores["horizontal"]["rms"] < 1.0
    assert scores["velocity"]["rms"] < 0.2
