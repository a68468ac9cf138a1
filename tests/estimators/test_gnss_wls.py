"""``gnss_wls`` on epochs built from known geometry: exact pseudoranges of two systems with
their own clocks give the position to the millimetre and each clock; one faulty pseudorange is
excluded by the residual test; pseudorange errors with an ionosphere part common to the
satellites give position errors whose spread its sigmas match (a Monte Carlo); on the
quickstart dataset its error is the least-squares image of the simulated errors."""

from __future__ import annotations

import numpy as np

from estimators.builtin.gnss_wls import GnssWls, nlos_sigma
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
    """On the quickstart drive (seed 1) gnss_wls's position error is, epoch by epoch, the
    generalised least-squares image K e of the simulated pseudorange errors e (truth_gnss: the
    signal-in-space error, the ionosphere and troposphere the broadcast models miss, multipath,
    reflected path and code noise), K = (H^T W H)^-1 H^T W with H at the true antenna and W the
    inverse of its weighting model (module docstring: the reported sigmas with the C/N0's
    NLOS share and the common ionosphere part; the field's covariance enters only the reported
    sigma). The difference
    is bounded by 1 mm: the
    Gauss-Newton iteration stops below a 0.1 mm step (CONVERGED_M), and H at the truth and at
    the solution differ by |dx| / range (a few m over 2e7 m), micrometres on errors of metres.
    This holds whatever the seed's draw (the error's size over one drive is one draw of its
    drive-long terms: 0.3-2.9 m horizontal RMS over seeds 1-8). Epochs where the exclusion
    dropped a satellite are left out (none on this drive; at least 90 % must be compared)."""
    from simulator import pipeline
    from simulator.datasheet import cn0_template, iono_residual_fractions

    solved = pipeline.run_estimators(quickstart, {"gnss_wls": None})
    solution = solved["gnss_wls"][0].set_index("t")
    gnss = quickstart.manifest["datasheet"]["gnss"]
    common = iono_residual_fractions(gnss)[0]
    template = cn0_template(gnss)
    m = quickstart.read("gnss_raw").merge(quickstart.read("truth_gnss"),
                                          on=["t", "sv", "signal"], suffixes=("", "_true"))
    m = m[(m["health"] == 0) & (m["elevation"] >= np.radians(GnssWls.defaults["elevation_mask"]))]
    error = (m["sis_error"] + m["iono_true"] - m["iono"] + m["tropo_true"] - m["tropo"]
             + m["multipath"] + m["nlos_delay"] + m["code_noise"])
    differences = []
    for t, g in m.assign(error=error).groupby("t"):
        if t not in solution.index or len(g) != solution.loc[t, "num_sats"]:
            continue
        rx = g[["antenna_x", "antenna_y", "antenna_z"]].to_numpy()[0]
        rel = g[["sat_x", "sat_y", "sat_z"]].to_numpy() - rx
        h = np.column_stack([-rel / np.linalg.norm(rel, axis=1, keepdims=True), np.ones(len(g))])
        sigma = nlos_sigma(g["pseudorange_std"].to_numpy(), g["cn0"].to_numpy(),
                           g["elevation"].to_numpy(), template, GnssWls.defaults["nlos_sigma"])
        part = common * g["iono"].to_numpy()
        shared = np.outer(part, part)
        weight = np.linalg.inv(np.diag(np.maximum(sigma**2 - np.diag(shared),
                                                  (0.1 * sigma) ** 2)) + shared)
        image = np.linalg.solve(h.T @ weight @ h, h.T @ weight @ g["error"].to_numpy())[:3]
        row = solution.loc[t]
        got = geodetic_to_ecef(np.radians(row["lat"]), np.radians(row["lon"]), row["alt"]).ravel()
        differences.append(got - rx - image)
    assert len(differences) >= 0.9 * len(solution)
    assert np.max(np.linalg.norm(differences, axis=1)) < 1e-3
    assert pipeline.score(quickstart, solved).scores()["gnss_wls"]["velocity"]["rms"] < 0.2


def _with_elevation(block: np.ndarray) -> np.ndarray:
    """The epoch with an elevation column, 15 to 80 deg (what the C/N0 template reads)."""
    return np.column_stack([block, np.radians(np.linspace(15.0, 80.0, len(block)))])


def _position_errors(blocks: list[np.ndarray], rx: np.ndarray, datasheet: dict | None,
                     columns: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Per epoch, the NED position error (m) and the reported sigmas."""
    lat, lon, _ = ecef_to_geodetic(rx)
    c_en = ned_to_ecef_matrix(lat, lon).T
    errors, sigmas = [], []
    for block in blocks:
        est = GnssWls({"elevation_mask": 0.0, "nlos_sigma": 20.0}, None,
                      {"gnss_raw": {c: i for i, c in enumerate(columns)}}, {"gnss_raw": {}},
                      datasheet=datasheet)
        est.on_gnss_raw(0.0, block)
        row = dict(zip(GnssWls.output_columns, est.solution(0.0), strict=True))
        got = geodetic_to_ecef(np.radians(row["lat"]), np.radians(row["lon"]),
                               row["alt"]).ravel()
        errors.append(c_en @ (got - rx))
        sigmas.append([row["std_n"], row["std_e"], row["std_d"]])
    return np.array(errors), np.array(sigmas)


def test_reflected_signals_announced_by_their_cn0_are_weighted_down():
    """A street canyon in miniature, 200 epochs of 12 satellites: each satellite's C/N0 is the
    receiver's template at its elevation (simulator.datasheet.cn0_template) plus its scatter
    (2 dB fading, 1 dB noise); in each epoch four of them, at random, are reflections: 12 dB
    weaker and late by an extra path of 10-40 m that the reported sigma (1 m) does not hold.
    With the template each axis's mean (error / sigma)^2 is between 0.3 and 3 (the goal of
    docs/scores.md), and the horizontal RMS error is under 0.8 times the one without the
    template (no datasheet: the reflections weighted as direct signals, which the exclusion
    and the variance factor alone keep consistent, at a larger error)."""
    from simulator.datasheet import cn0_template

    rx = geodetic_to_ecef(np.radians(48.0), np.radians(11.0), 500.0).ravel()
    clean = _with_elevation(_epoch(rx, {ord("G"): 0.0, ord("E"): 0.0}))
    columns = (*COLUMNS, "elevation")
    sheet = {"gnss": {"cn0_zenith": 46.5, "cn0_horizon": 18.0, "cn0_fading": 2.0,
                      "cn0_noise": 1.0}}
    template = cn0_template(sheet["gnss"])
    expected = template.expected_dbhz(clean[:, -1])
    rng = np.random.default_rng(11)
    blocks = []
    for _ in range(200):
        block = clean.copy()
        block[:, COLUMNS.index("cn0")] = expected + template.scatter_db * rng.normal(size=12)
        block[:, COLUMNS.index("pseudorange")] += rng.normal(size=12)
        reflected = rng.choice(12, size=4, replace=False)
        block[reflected, COLUMNS.index("cn0")] -= 12.0
        block[reflected, COLUMNS.index("pseudorange")] += rng.uniform(10.0, 40.0, size=4)
        blocks.append(block)
    modelled, sigma = _position_errors(blocks, rx, sheet, columns)
    trusted, _ = _position_errors(blocks, rx, None, columns)
    nse = np.mean((modelled / sigma) ** 2, axis=0)
    assert np.all((nse > 0.3) & (nse < 3.0)), nse

    def horizontal_rms(e: np.ndarray) -> float:
        return float(np.sqrt(np.mean(np.sum(e[:, :2] ** 2, axis=1))))

    assert horizontal_rms(modelled) < 0.8 * horizontal_rms(trusted)


def test_the_variance_factor_scales_the_sigmas_to_unmodelled_noise():
    """Pseudorange errors three times the reported sigma (1 m), independent, 500 epochs of 12
    satellites and two clocks (7 degrees of freedom). Without the a-posteriori variance factor
    the mean (error / sigma)^2 would be 9. With it (the covariance times max(s0^2, 1), s0^2 =
    r^T W r / 7 = 9 chi2_7 / 7, independent of the position error in least squares) its
    expectation is 9 E[1 / max(9 X / 7, 1)], X ~ chi2_7, computed here by quadrature; the mean
    of 500 epochs is within 25 % of it (about 2.5 of its standard deviations)."""
    from scipy import integrate
    from scipy.stats import chi2 as chi2_dist

    rx = geodetic_to_ecef(np.radians(48.0), np.radians(11.0), 500.0).ravel()
    clean = _epoch(rx, {ord("G"): 0.0, ord("E"): 0.0})
    rng = np.random.default_rng(5)
    blocks = []
    for _ in range(500):
        block = clean.copy()
        block[:, COLUMNS.index("pseudorange")] += 3.0 * rng.normal(size=len(block))
        blocks.append(block)
    errors, sigma = _position_errors(blocks, rx, None, COLUMNS)
    nse = np.mean((errors / sigma) ** 2, axis=0)
    knee = 7.0 / 9.0  # where the factor leaves its floor
    expected = 9.0 * (chi2_dist.cdf(knee, 7) + integrate.quad(
        lambda x: chi2_dist.pdf(x, 7) * knee / x, knee, np.inf)[0])
    assert 1.2 < expected < 1.6  # 7 / 5 = 1.4 but for the factor's floor at 1
    np.testing.assert_allclose(nse, expected, rtol=0.25)


def test_pope_tau_critical_values():
    """Pope's tau lies within +-sqrt(r); its critical value tends to the normal quantile as the
    redundancy grows (3.29 at a two-sided 1e-3) and stays below sqrt(r)."""
    from estimators.builtin.gnss_wls import tau_critical

    assert abs(tau_critical(10_000, 1e-3) - 3.2905) < 2e-3
    for r in (2, 3, 5, 8):
        assert 0.0 < tau_critical(r, 1e-3) < np.sqrt(r)


def test_the_nlos_probability_is_calibrated():
    """The probability of reflection given the C/N0 deficit, on epochs drawn from the model's
    own two populations (direct: deficit N(0, 2.24^2) dB; reflected: N(11, 4.5^2) dB, a third of
    an epoch's 12 signals): among the signals given a probability in each band (0-0.2, ...,
    0.8-1) the share that are reflected lies within 0.12 of the band's mean probability (the
    prior is taken from the epoch, so this is not exact). On open sky (no reflection) the mean
    probability is under 1 % and under 0.5 % of the signals get over 0.5 (a direct signal
    faded by over 3 scatters, 0.13 % of them, looks reflected)."""
    from simulator.datasheet import nlos_probability

    rng = np.random.default_rng(3)
    scatter = 2.24
    p_all, reflected_all = [], []
    for _ in range(400):
        reflected = np.zeros(12, dtype=bool)
        reflected[rng.choice(12, size=4, replace=False)] = True
        deficit = np.where(reflected, rng.normal(11.0, 4.5, 12), rng.normal(0.0, scatter, 12))
        p_all.append(nlos_probability(deficit, scatter))
        reflected_all.append(reflected)
    p, truth = np.concatenate(p_all), np.concatenate(reflected_all)
    for low in np.arange(0.0, 1.0, 0.2):
        band = (p >= low) & (p < low + 0.2)
        if band.sum() >= 50:
            assert abs(truth[band].mean() - p[band].mean()) < 0.12, (low, band.sum())
    open_sky = np.concatenate([nlos_probability(rng.normal(0.0, scatter, 12), scatter)
                               for _ in range(400)])
    assert open_sky.mean() < 0.01 and np.mean(open_sky > 0.5) < 0.005
    assert nlos_probability(np.array([np.nan, 20.0]), scatter)[0] == 0.0
