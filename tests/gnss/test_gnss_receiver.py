"""Raw measurements and receiver fixes: closure of the noise-free model, rate/Doppler
consistency, the error budget, and the environment (tunnel, canyon)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from gnss_helpers import drive, receiver

from simulator import columns as col
from simulator.earth import ecef_to_geodetic, geodetic_to_ecef, ned_to_ecef_matrix
from simulator.gnss import chunks
from simulator.gnss.atmosphere import saastamoinen_zenith
from simulator.gnss.constants import C_M_S, LAMBDA_L1_M
from simulator.gnss.errors import iono_field_correlation, pierce_points_km
from simulator.gnss.fix import pack_epochs, receiver_fixes, solve_position
from simulator.gnss.receiver import (
    cn0_model,
    dll_sigma_m,
    multipath_sigma_m,
    rotate_to_reception_frame,
)

DRIVE = [{"stop": {"duration": 5}}, {"accelerate": {"to_speed": 15, "accel": 2.0}},
         {"turn": {"angle": 90, "radius": 50}}, {"straight": {"length": 200}}]


def _truth_by_row(raw, truth_gnss):
    merged = raw.merge(truth_gnss, on=["t", "sv"], suffixes=("", "_true"))
    assert len(merged) == len(raw)
    return merged


def test_noise_free_pseudoranges_give_antenna_position_and_clock_within_1cm():
    truth = drive(DRIVE)
    gnss = receiver(preset="ideal", clock="tcxo", antenna_lever_arm=[0.5, -0.3, -1.2])
    out = gnss.generate(truth, np.random.default_rng(3))
    raw, tg, fix = out["gnss_raw"], out["truth_gnss"], out["gnss_fix"]
    t = fix["t"].to_numpy()
    epoch = np.searchsorted(t, raw["t"].to_numpy())
    pr = (raw["pseudorange"] + raw["sat_clock"] - raw["iono"] - raw["tropo"]).to_numpy()
    mask, (pr_p, pos_p) = pack_epochs(epoch, len(t), pr,
                                      raw[["sat_x", "sat_y", "sat_z"]].to_numpy())
    pos, clock, ok = solve_position(pr_p, pos_p, mask.astype(float), mask)
    first = tg.groupby("t").first()
    antenna = first[["antenna_x", "antenna_y", "antenna_z"]].to_numpy()
    assert ok.all()
    assert np.abs(np.linalg.norm(pos - antenna, axis=1)).max() < 0.01
    assert np.abs(clock - first["receiver_clock"].to_numpy()).max() < 0.01
    # the clock is not trivial: a TCXO drawn with a 0.1 ms, 0.5 ppm spread
    assert np.abs(first["receiver_clock"]).max() > 100.0
    # the fix stream (weighted, same model) gives the same position, and the IMU-to-antenna
    # lever arm really moved the antenna away from the IMU
    lat, lon, alt = ecef_to_geodetic(antenna)
    assert np.abs(fix["lat"] - np.degrees(lat)).max() < 1e-9
    assert np.abs(fix["alt"] - alt).max() < 0.01
    imu = truth.inertial(t)
    assert np.abs(fix["alt"] - imu["alt"] - 1.2).max() < 0.05


def test_noise_free_doppler_velocity_matches_antenna_velocity():
    truth = drive(DRIVE)
    out = receiver(preset="ideal", clock="tcxo").generate(truth, np.random.default_rng(4))
    fix, tg = out["gnss_fix"], out["truth_gnss"]
    k = truth.inertial(fix["t"].to_numpy())
    v = fix[["vn", "ve", "vd"]].to_numpy()
    # the receiver does not model the rates of the atmospheric delays (mm/s, as real ones)
    assert np.abs(v - k["v_ned"]).max() < 5e-3
    drift = tg.groupby("t")["receiver_clock_drift"].first().to_numpy()
    assert np.abs(fix["clock_drift"] - drift).max() < 5e-3
    moving = k["speed"] > 1.0
    course = np.angle(np.exp(1j * (fix["course"] - k["yaw"])))[moving]
    assert (np.abs(course) < 5e-3 / k["speed"][moving]).all()
    np.testing.assert_allclose(fix["speed"][moving], k["speed"][moving], atol=5e-3)


def test_pseudorange_rate_is_the_rate_of_change_of_the_pseudorange():
    """Central differences of the noise-free pseudorange at 10 Hz against the reported rate.
    The rate is carrier-derived, so the ionosphere enters it with the opposite sign (code-
    carrier divergence): d/dt (pr - 2 iono) = rate."""
    truth = drive(DRIVE)
    gnss = receiver(preset="ideal", rate=10)
    raw = gnss.generate(truth, np.random.default_rng(5))["gnss_raw"]
    breaks = truth.breakpoints()
    checked = 0
    for _, one in raw.groupby("sv"):
        one = one.sort_values("t")
        tt = one["t"].to_numpy()
        if len(tt) < 5 or np.any(np.diff(tt) > 0.11):
            continue
        y = (one["pseudorange"] - 2.0 * one["iono"]).to_numpy()
        h = 0.1
        # fourth-order central difference (error h^4 / 30 times the fifth derivative), exact
        # where the motion is smooth: stencils straddling a jerk step of the road are left out
        fd = (-y[4:] + 8 * y[3:-1] - 8 * y[1:-3] + y[:-4]) / (12 * h)
        smooth = np.searchsorted(breaks, tt[:-4]) == np.searchsorted(breaks, tt[4:])
        np.testing.assert_allclose(fd[smooth], one["pseudorange_rate"].to_numpy()[2:-2][smooth],
                                   atol=3e-4)
        checked += smooth.sum()
    assert checked > 1000
    np.testing.assert_allclose(raw["doppler"], -raw["pseudorange_rate"] / LAMBDA_L1_M)
    # D = -rate / lambda: a satellite with a shrinking range has a positive Doppler
    assert (raw["doppler"][raw["pseudorange_rate"] < 0] > 0).all()


def test_raw_error_terms_add_up_to_the_measurement():
    truth = drive(DRIVE, zones={"c": {"sky": "canyon"}})
    out = receiver().generate(truth, np.random.default_rng(6))
    m = _truth_by_row(out["gnss_raw"], out["truth_gnss"])
    rebuilt = (m["range"] + m["receiver_clock"] - m["sat_clock"] + m["iono_true"]
               + m["tropo_true"] + m["sis_error"] + m["multipath"] + m["nlos_delay"]
               + m["code_noise"])
    np.testing.assert_allclose(m["pseudorange"], rebuilt, rtol=0, atol=1e-6)
    # the true ionosphere is iono_scale (1.5) x (1 + 0.2 x a field over the pierce points) x
    # the broadcast one (issue 19): the signals of one short drive share much of the field
    # (here the ratio is 1.60-1.79), so the mean ratio over seeds is checked in test_gnss_errors
    ratio = m["iono_true"] / m["iono"]
    assert 0.5 < ratio.min() and ratio.max() < 2.5 and ratio.std() > 0.01


def _budget_run(seed: int):
    """Static receiver, 10 min at 1 Hz, automotive errors on the raw code (no carrier smoothing,
    whose growing window at each arc's start this budget does not describe): the actual NED fix
    errors, and the covariance the configured error budget predicts for each epoch's weighted
    least squares, G R G^T with G = (H^T W H)^-1 H^T W, W the receiver's weights and R the
    configured measurement error covariance (independent terms on the diagonal; the
    troposphere residual common to every signal; the ionosphere's mean excess (iono_scale - 1) I
    along I, and its variation iono_scale iono_residual I correlated between signals i, j by the
    field's correlation at their pierce points' distance, rho_ij I_i I_j)."""
    truth = drive([{"stop": {"duration": 600}}], rate_hz=1.0)
    gnss = receiver(carrier_smoothing=0.0)
    cfg = gnss.config
    out = gnss.generate(truth, np.random.default_rng(seed))
    raw, fix = out["gnss_raw"], out["gnss_fix"]
    k = truth.inertial(fix["t"].to_numpy())
    c_ne = ned_to_ecef_matrix(k["lat"][0], k["lon"][0])
    got = geodetic_to_ecef(np.radians(fix["lat"]), np.radians(fix["lon"]), fix["alt"])
    err = (got - geodetic_to_ecef(k["lat"], k["lon"], k["alt"])) @ c_ne

    el, az = raw["elevation"].to_numpy(), raw["azimuth"].to_numpy()
    code = dll_sigma_m(raw["cn0"].to_numpy(), cfg["dll_bandwidth"], cfg["correlator_spacing"],
                       cfg["integration_time"]) * cfg["tracking_noise"]
    iono = raw["iono"].to_numpy()
    variation = cfg["iono_scale"] * cfg["iono_residual"] * iono
    own = code**2 + multipath_sigma_m(el, cfg["multipath"]) ** 2 + cfg["sis_error"] ** 2
    iono_common = (cfg["iono_scale"] - 1.0) * iono
    x, y, z = pierce_points_km(k["lat"][0], k["lon"][0], az, el)
    zenith = np.add(*saastamoinen_zenith(k["lat"][0], k["alt"][0]))
    tropo_common = cfg["tropo_residual"] * raw["tropo"].to_numpy() / zenith
    u = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)], axis=1)
    epoch = np.searchsorted(fix["t"].to_numpy(), raw["t"].to_numpy())
    mask, (u_p, w_p, own_p, si_p, st_p, sv_p, *x_p) = pack_epochs(
        epoch, len(fix), u, 1.0 / raw["pseudorange_std"].to_numpy() ** 2, own, iono_common,
        tropo_common, variation, x, y, z)
    h = np.concatenate([-u_p, np.ones(mask.shape + (1,))], axis=-1) * mask[..., None]
    hw = h * w_p[..., None]
    g = np.linalg.solve(np.einsum("nki,nkj->nij", hw, h), np.swapaxes(hw, 1, 2))
    chord = np.sqrt(sum((c[:, :, None] - c[:, None, :]) ** 2 for c in x_p))
    rho = iono_field_correlation(chord)
    r = (own_p[:, :, None] * np.eye(mask.shape[1])[None] + si_p[:, :, None] * si_p[:, None, :]
         + st_p[:, :, None] * st_p[:, None, :] + rho * sv_p[:, :, None] * sv_p[:, None, :])
    return err, np.einsum("nik,nkl,njl->nij", g, r, g)


def test_fix_errors_match_the_configured_error_budget():
    errs, covs = zip(*(_budget_run(seed) for seed in range(16)), strict=True)
    err, cov = np.concatenate(errs), np.concatenate(covs)
    horiz_rms = np.sqrt(np.mean(err[:, 0] ** 2 + err[:, 1] ** 2))
    vert_rms = np.sqrt(np.mean(err[:, 2] ** 2))
    horiz_pred = np.sqrt(np.mean(cov[:, 0, 0] + cov[:, 1, 1]))
    vert_pred = np.sqrt(np.mean(cov[:, 2, 2]))
    print(f"\nautomotive preset, static, 16 x 10 min: horizontal rms {horiz_rms:.2f} m "
          f"(budget {horiz_pred:.2f} m), vertical rms {vert_rms:.2f} m "
          f"(budget {vert_pred:.2f} m)")
    assert 0.75 < horiz_rms / horiz_pred < 1.25
    assert 0.75 < vert_rms / vert_pred < 1.25


def test_tunnel_blocks_every_satellite_and_fix():
    segments = [{"stop": {"duration": 5}}, {"accelerate": {"to_speed": 10, "accel": 2.0}},
                {"straight": {"length": 200, "zone": "tunnel"}}, {"straight": {"length": 50}}]
    truth = drive(segments, zones={"tunnel": {"sky": "none"}})
    out = receiver().generate(truth, np.random.default_rng(7))
    start, end, _ = truth.profile.zones[0]
    raw, fix, tg = out["gnss_raw"], out["gnss_fix"], out["truth_gnss"]
    inside_raw = (raw["t"] >= start) & (raw["t"] < end)
    inside_fix = (fix["t"] >= start) & (fix["t"] < end)
    assert inside_fix.sum() >= 15
    assert not inside_raw.any()
    assert (fix.loc[inside_fix, "fix"] == 0).all()
    assert fix.loc[inside_fix, ["lat", "lon", "alt"]].isna().all().all()
    assert (fix.loc[~inside_fix, "fix"] == 2).all()
    # the satellites are still up there: truth lists them as blocked
    in_tunnel = tg[(tg["t"] >= start) & (tg["t"] < end)]
    assert len(in_tunnel) > 0 and (in_tunnel["tracked"] == 0).all()


@pytest.mark.parametrize("heading", [0.0, 45.0, 90.0])
def test_canyon_has_fewer_satellites_and_worse_dop(heading):
    segments = [{"stop": {"duration": 60, "zone": "street"}}]
    start = {"lat": 37.0, "lon": 127.0, "alt": 40.0, "heading": heading}
    open_sky = drive(segments, start=start)
    # geometric optics only (no diffuse scattering, which keeps low satellites at 17-25 dB-Hz,
    # tests/environment/test_sky.py): the satellites the street's walls block are lost
    canyon = drive(segments, start=start, zones={
        "street": {"sky": "canyon", "building_height": 30.0, "street_width": 15.0,
                   "scattering_coefficient": 0.0}})
    gnss = receiver(preset="ideal")
    a = gnss.generate(open_sky, np.random.default_rng(8))
    b = gnss.generate(canyon, np.random.default_rng(8))
    fa, fb = a["gnss_fix"], b["gnss_fix"]
    inside = (fb["t"] < 60.0).to_numpy()  # the zone covers [0, 60) s
    assert (fb["num_sats"][inside] <= fa["num_sats"][inside]).all()
    assert fb["num_sats"][inside].mean() < fa["num_sats"][inside].mean()
    los_a = a["truth_gnss"].query("tracked == 1 and t < 60").groupby("t")["los"].sum()
    los_b = b["truth_gnss"].query("tracked == 1 and t < 60").groupby("t")["los"].sum()
    assert (los_b.reindex(los_a.index, fill_value=0) < los_a).all()
    hdop_b = np.where(fb["fix"] == 2, fb["hdop"], np.inf)[inside]
    assert (hdop_b >= fa["hdop"][inside] - 1e-9).all() and hdop_b.mean() > fa["hdop"].mean()
    # NLOS signals arrive late, never early, and the truth stream says which they are
    m = _truth_by_row(b["gnss_raw"], b["truth_gnss"])
    assert (m.loc[m["nlos"] == 1, "nlos_delay"] > 0).all()
    assert (m.loc[m["nlos"] == 0, "nlos_delay"] == 0).all()
    nlos = m[m["nlos"] == 1]
    cfg = gnss.config
    # they lose C/N0 (a reflection off a facade, or diffraction over its edge), never gain it
    loss = cn0_model(nlos["elevation"], cfg["cn0_zenith"], cfg["cn0_horizon"]) - nlos["cn0"]
    assert (loss > 0).all() and (nlos["cn0"] >= cfg["cn0_threshold"]).all()


def test_three_satellites_give_a_2d_fix_and_two_give_none():
    truth = drive([{"stop": {"duration": 60}}], rate_hz=1.0)
    out = receiver(preset="ideal").generate(truth, np.random.default_rng(9))
    raw = out["gnss_raw"]
    rank = raw.groupby("t").cumcount()
    t = raw["t"]
    keep = (rank < np.where((t >= 20) & (t < 30), 3, np.where((t >= 40) & (t < 45), 2, 99)))
    fix = receiver_fixes(out["gnss_fix"]["t"].to_numpy(), raw[keep])
    kind = fix["fix"].to_numpy()
    tt = fix["t"].to_numpy()
    assert (kind[(tt >= 20) & (tt < 30)] == 1).all()
    assert (kind[(tt >= 40) & (tt < 45)] == 0).all()
    assert (kind[(tt < 20) | ((tt >= 30) & (tt < 40)) | (tt >= 45)] == 2).all()
    assert fix.loc[kind == 1, "vdop"].isna().all() and (fix.loc[kind == 1, "hdop"] > 0).all()
    # the vehicle stands still, so holding the last height is exact: the 2D fix is too
    k = truth.inertial(tt)
    two_d = kind == 1
    assert np.abs(fix["lat"][two_d] - np.degrees(k["lat"][two_d])).max() < 1e-8
    assert np.abs(fix["lon"][two_d] - np.degrees(k["lon"][two_d])).max() < 1e-8
    assert fix.loc[kind == 0, ["lat", "lon", "alt", "vn"]].isna().all().all()


def test_smoothed_fixes_are_quieter_and_follow_the_motion():
    """The fix-output filter (``smoothing``) on the raw code (no carrier smoothing, which would
    already have made consecutive fixes nearly equal)."""
    static = drive([{"stop": {"duration": 300}}], rate_hz=1.0)
    raw_fix = receiver(carrier_smoothing=0.0).generate(static, np.random.default_rng(10))[
        "gnss_fix"]
    smooth = receiver(carrier_smoothing=0.0, smoothing=20.0).generate(
        static, np.random.default_rng(10))["gnss_fix"]
    jitter = [np.std(np.diff(f["lat"].to_numpy())) for f in (raw_fix, smooth)]
    assert jitter[1] < 0.5 * jitter[0]
    moving = drive(DRIVE)
    ideal = receiver(preset="ideal", smoothing=5.0).generate(moving, np.random.default_rng(1))
    fix = ideal["gnss_fix"]
    k = moving.inertial(fix["t"].to_numpy())
    c = ned_to_ecef_matrix(k["lat"][0], k["lon"][0])
    err = (geodetic_to_ecef(np.radians(fix["lat"]), np.radians(fix["lon"]), fix["alt"])
           - geodetic_to_ecef(k["lat"], k["lon"], k["alt"])) @ c
    # velocity aiding leaves no lag; what remains is the trapezoidal step's error at 1 Hz
    assert np.abs(err).max() < 0.3


def test_chunked_evaluation_with_horizon_screen_changes_nothing(monkeypatch):
    """Evaluating the signals in chunks of epochs, only for the satellites the coarse screen
    lets through, gives the same streams as evaluating every satellite at once."""
    import simulator.sensors.gnss_observables as gnss_module

    truth = drive([{"stop": {"duration": 5}}, {"accelerate": {"to_speed": 15, "accel": 2.0}},
                   {"straight": {"length": 3000}}], rate_hz=1.0)
    chunked = receiver().generate(truth, np.random.default_rng(11))
    monkeypatch.setattr(chunks, "CHUNK_EPOCHS", 10**9)
    monkeypatch.setattr(gnss_module, "BELOW_HORIZON_MARGIN_RAD", -np.pi)
    whole = receiver().generate(truth, np.random.default_rng(11))
    for name in ("gnss_raw", "gnss_fix", "truth_gnss"):
        pd.testing.assert_frame_equal(chunked[name], whole[name], rtol=1e-12)
    assert len(chunked["gnss_raw"]) > 1000


@pytest.fixture(autouse=True)
def _small_chunks(monkeypatch):
    """Every test here runs with short chunks, so chunk boundaries are crossed."""
    monkeypatch.setattr(chunks, "CHUNK_EPOCHS", 97)


def test_a_drive_entirely_without_sky_gives_empty_raw_and_no_fix():
    truth = drive([{"stop": {"duration": 20, "zone": "garage"}}],
                  zones={"garage": {"sky": "none"}}, rate_hz=1.0)
    out = receiver().generate(truth, np.random.default_rng(12))
    raw, fix = out["gnss_raw"], out["gnss_fix"]
    # zones cover [start, end): only the epoch at the very end of the drive is outside
    inside = fix["t"] < truth.duration_s
    assert (raw["t"] == truth.duration_s).all() and list(raw.columns) == list(col.GNSS_RAW)
    assert (fix.loc[inside, "fix"] == 0).all() and fix.loc[inside, "lat"].isna().all()
    assert len(out["truth_gnss"]) > 0
    assert (out["truth_gnss"].query(f"t < {truth.duration_s}")["tracked"] == 0).all()
    empty = receiver_fixes(fix["t"].to_numpy(), raw.iloc[0:0])
    assert (empty["fix"] == 0).all() and empty["lat"].isna().all()


def _fix_errors_ned(truth, fix) -> np.ndarray:
    k = truth.inertial(fix["t"].to_numpy())
    c_ne = ned_to_ecef_matrix(k["lat"][0], k["lon"][0])
    got = geodetic_to_ecef(np.radians(fix["lat"]), np.radians(fix["lon"]), fix["alt"])
    return (got - geodetic_to_ecef(k["lat"], k["lon"], k["alt"])) @ c_ne


def test_10hz_fix_errors_change_slowly_while_driving():
    """Issue 19: a 10 Hz receiver's fix errors change by under 0.2 m per second per axis (north,
    east and vertical) in open sky while driving (real: 0.036 m/s, u-blox at 17.6 m/s). The
    automotive preset smooths the code with the carrier (Hatch filter, 100 s, RTCA DO-229);
    its raw code (carrier_smoothing 0: DLL noise correlated over 0.5 s only) jumps by a metre
    and more from one second to the next, and smoothing lowers the level. Measured over
    3 x 290 s at 15 m/s (the default gps-almanac sky): per-second change 0.04 / 0.02 / 0.10 m
    north / east / down (raw code 1.0 / 0.7 / 2.0 m; session 5, before the signal-in-space
    error's steps at record changes and with other draws: 0.03 / 0.03 / 0.08 m); was 0.16 /
    0.11 / 0.38 m with the former 100 s Gauss-Markov code error.
    Averaging one second of fixes leaves the scatter as it is (real receivers: little gain; the
    white model went from 1.09 to 0.49 m)."""
    truth = drive([{"stop": {"duration": 5}}, {"accelerate": {"to_speed": 15, "accel": 2.0}},
                   {"straight": {"length": 2000}}, {"turn": {"angle": 90, "radius": 50}},
                   {"straight": {"length": 2000}}], rate_hz=10.0)
    assert receiver().config["carrier_smoothing"] == 100.0
    errors = {}
    for name, extra in (("smoothed", {}), ("raw code", {"carrier_smoothing": 0.0})):
        runs = [_fix_errors_ned(truth, receiver(rate=10, **extra).generate(
            truth, np.random.default_rng(seed))["gnss_fix"]) for seed in range(3)]
        per_second = np.concatenate([e[10:] - e[:-10] for e in runs])
        # averaging each second's ten fixes: little gain when they are correlated (issue 19)
        averaged = np.concatenate([e[:len(e) // 10 * 10].reshape(-1, 10, 3).mean(axis=1)
                                   for e in runs])
        errors[name] = (np.sqrt(np.mean(per_second**2, axis=0)),
                        np.sqrt(np.mean(np.concatenate(runs) ** 2, axis=0)),
                        np.sqrt(np.mean(averaged**2, axis=0)))
    print({name: [np.round(v, 3).tolist() for v in value] for name, value in errors.items()})
    change, level, averaged = errors["smoothed"]
    raw_change, raw_level, _ = errors["raw code"]
    assert np.all(change < 0.2), change
    assert np.all(raw_change > 0.5), raw_change
    assert np.all(level < raw_level)
    assert np.all(averaged > 0.95 * level)


def test_degenerate_geometry_gives_no_fix_rather_than_an_error():
    """Four satellites of which three sit at one place: the normal matrix is singular, so that
    epoch has no fix (NaN, not solvable), while a good epoch beside it is solved to the
    receiver's true position (found by a Chan experiment with randomly kept satellites, where
    generation stopped on numpy's LinAlgError)."""
    rx = geodetic_to_ecef(np.radians(48.0), np.radians(11.0), 500.0)
    up = rx / np.linalg.norm(rx)
    east = np.cross([0.0, 0.0, 1.0], up)
    east /= np.linalg.norm(east)
    north = np.cross(up, east)
    good = np.stack([rx + 2.2e7 * d / np.linalg.norm(d) for d in
                     (up, up + east, up - east + 0.3 * north, up + north - 0.5 * east)])
    sats = np.stack([good, np.stack([good[0], good[0], good[0], good[1]])])
    geometric = np.linalg.norm(sats - rx, axis=-1)
    pr = np.linalg.norm(rotate_to_reception_frame(sats, geometric / C_M_S) - rx, axis=-1)
    pos, _, ok = solve_position(pr, sats, np.ones((2, 4)), np.ones((2, 4), dtype=bool))
    assert ok.tolist() == [True, False]
    np.testing.assert_allclose(pos[0], rx, atol=1e-3)
    assert np.isnan(pos[1]).all()
