"""Scoring is exact on solutions with known errors (issue 7, "what must be shown")."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from simulator.earth import ecef_to_geodetic, geodetic_to_ecef, ned_to_ecef_matrix, wrap_angle
from simulator.scoring.metrics import score_solution
from tests.scoring_helpers import events, offset_solution, quickstart_truth

ATOL_M = 1e-5  # second-order error of the curvilinear offsets used to build the solutions


@pytest.fixture(scope="module")
def truth() -> pd.DataFrame:
    return quickstart_truth()


def test_known_offsets_score_exactly(truth):
    sol = offset_solution(truth.iloc[::10], dpos=(3.0, -4.0, 1.5), dvel=(0.3, -0.4, 1.2),
                          datt_deg=(1.0, -2.0, 20.0))
    assert np.ptp(truth["yaw"]) > np.radians(300)  # the yaw offset crosses +-180 deg
    s = score_solution(truth, events(), sol)
    for key in ("rms", "mean", "max", "cep50", "cep95"):
        assert s["horizontal"][key] == pytest.approx(5.0, abs=ATOL_M)
    assert s["vertical"]["rms"] == pytest.approx(1.5, abs=ATOL_M)
    assert s["vertical"]["max"] == pytest.approx(1.5, abs=ATOL_M)
    assert s["velocity"]["rms"] == pytest.approx(1.3, abs=1e-9)
    assert s["attitude"] == pytest.approx({"roll_rms": 1.0, "pitch_rms": 2.0, "yaw_rms": 20.0},
                                          abs=1e-9)
    assert s["outages"] == []
    assert "nees" not in s and "runtime" not in s
    n = len(sol)
    assert s["rows"] == {"total": n, "outside_truth": 0, "position": n, "velocity": n,
                         "attitude": n}


def test_error_in_one_outage_shows_only_there(truth):
    sol = truth.iloc[::10].reset_index(drop=True)
    t = sol["t"].to_numpy()
    in_second = (t >= 120.0) & (t < 150.0)
    east = np.where(in_second, 0.5 * (t - 120.0), 0.0)  # grows 0.5 m/s during outage 2
    s = score_solution(truth, events((40.0, 60.0), (120.0, 150.0)),
                       offset_solution(sol, (0.0, east, 0.0)))
    first, second = s["outages"]
    distance = truth.set_index("t")["distance"]
    assert first["start"] == 40.0 and first["duration"] == 20.0
    assert first["distance"] == pytest.approx(distance[60.0] - distance[40.0], abs=1e-9)
    assert first["max_horizontal"] == pytest.approx(0.0, abs=ATOL_M)
    assert first["end_horizontal"] == pytest.approx(0.0, abs=ATOL_M)
    assert first["end_percent"] == pytest.approx(0.0, abs=1e-6)
    expected_end = 0.5 * (149.9 - 120.0)  # last 10 Hz row before the outage end
    d2 = distance[150.0] - distance[120.0]
    assert second["start"] == 120.0 and second["duration"] == 30.0
    assert second["distance"] == pytest.approx(d2, abs=1e-9)
    assert second["max_horizontal"] == pytest.approx(expected_end, abs=ATOL_M)
    assert second["end_horizontal"] == pytest.approx(expected_end, abs=ATOL_M)
    assert second["end_percent"] == pytest.approx(100 * expected_end / d2, rel=1e-6)
    assert s["horizontal"]["max"] == pytest.approx(expected_end, abs=ATOL_M)


def _linear_truth(n: int, dt: float) -> pd.DataFrame:
    """A straight drive, linear in ECEF (so linear interpolation is exact), yaw through 180."""
    lat0, lon0, alt0 = np.radians(37.0), np.radians(127.0), 50.0
    t = np.arange(n) * dt
    ned = np.stack([3.0 * t, -4.0 * t, 0.1 * t], axis=-1)
    ecef = geodetic_to_ecef(lat0, lon0, alt0) + ned @ ned_to_ecef_matrix(lat0, lon0).T
    lat, lon, alt = ecef_to_geodetic(ecef)
    return pd.DataFrame({
        "t": t, "lat": np.degrees(lat), "lon": np.degrees(lon), "alt": alt,
        "vn": 3.0 + 0.01 * t, "ve": np.full(n, -4.0), "vd": np.full(n, 0.1),
        "roll": np.full(n, 0.02), "pitch": np.full(n, -0.01),
        "yaw": wrap_angle(np.pi - 0.05 + 0.02 * t), "distance": 5.001 * t,
    })


def test_truth_interpolated_between_samples_and_never_extrapolated():
    truth = _linear_truth(200, 0.1)
    fine = _linear_truth(399, 0.05)  # the same drive, also at the midpoints of the truth samples
    mid = fine.iloc[1::2]
    sol = offset_solution(mid, dpos=(1.0, 2.0, -2.0), datt_deg=(0.0, 0.0, 5.0))
    before, after = sol.iloc[:3].copy(), sol.iloc[-3:].copy()
    before["t"] -= 100.0
    after["t"] += 100.0
    sol = pd.concat([before, sol, after], ignore_index=True).sort_values("t")
    s = score_solution(truth, events(), sol)
    assert s["rows"]["total"] == len(mid) + 6 and s["rows"]["outside_truth"] == 6
    assert s["rows"]["position"] == len(mid)
    assert s["horizontal"]["max"] == pytest.approx(np.hypot(1, 2), abs=ATOL_M)
    assert s["horizontal"]["cep50"] == pytest.approx(np.hypot(1, 2), abs=ATOL_M)
    assert s["vertical"]["max"] == pytest.approx(2.0, abs=ATOL_M)
    assert s["velocity"]["rms"] == pytest.approx(0.0, abs=1e-12)
    assert s["attitude"]["yaw_rms"] == pytest.approx(5.0, abs=1e-9)


def test_nan_rows_are_skipped_and_counted(truth):
    sol = offset_solution(truth.iloc[::10], dpos=(3.0, -4.0, 1.5), datt_deg=(0, 0, 2.0))
    n = len(sol)
    sol.loc[5:14, "lat"] = np.nan
    sol.loc[20:22, "yaw"] = np.nan
    sol[["vn", "ve", "vd"]] = np.nan
    s = score_solution(truth, events((40.0, 60.0)), sol)
    assert s["rows"] == {"total": n, "outside_truth": 0, "position": n - 10, "velocity": 0,
                         "attitude": n - 3}
    assert s["horizontal"]["rms"] == pytest.approx(5.0, abs=ATOL_M)
    assert s["attitude"]["yaw_rms"] == pytest.approx(2.0, abs=1e-9)
    assert s["velocity"]["rms"] is None
    json.dumps(s, allow_nan=False)


def test_a_two_dimensional_solution_keeps_its_horizontal_and_yaw_scores(truth):
    """SPEC section 7: a 2-D filter writes NaN height, roll and pitch; the scorer leaves those
    cells out of their own metrics only (Cho & Choi's and Park's 2-D DR filters)."""
    sol = offset_solution(truth.iloc[::10], dpos=(3.0, -4.0, 1.5), datt_deg=(0, 0, 2.0))
    sol[["alt", "vd", "roll", "pitch"]] = np.nan
    s = score_solution(truth, events((40.0, 60.0)), sol)
    assert s["horizontal"]["rms"] == pytest.approx(5.0, abs=ATOL_M)
    assert s["outages"][0]["max_horizontal"] == pytest.approx(5.0, abs=ATOL_M)
    assert s["attitude"]["yaw_rms"] == pytest.approx(2.0, abs=1e-9)
    assert s["attitude"]["roll_rms"] is None and s["attitude"]["pitch_rms"] is None
    assert s["vertical"] == {"rms": None, "max": None}
    assert s["rows"]["position"] == len(sol) and s["rows"]["attitude"] == 0
    json.dumps(s, allow_nan=False)


def test_empirical_cep_of_a_known_spread(truth):
    sol = truth.iloc[:100]
    k = np.arange(1, 101)
    s = score_solution(truth, events(), offset_solution(sol, (0.0, 0.01 * k, 0.0)))
    h = s["horizontal"]
    assert h["mean"] == pytest.approx(0.505, abs=ATOL_M)
    assert h["rms"] == pytest.approx(0.01 * np.sqrt(101 * 201 / 6), abs=ATOL_M)
    assert h["max"] == pytest.approx(1.0, abs=ATOL_M)
    assert h["cep50"] == pytest.approx(0.505, abs=ATOL_M)  # between the 50th and 51st values
    assert h["cep95"] == pytest.approx(0.9505, abs=ATOL_M)  # 95 % of the way from 0.95 to 0.96


def test_nees_of_known_errors_and_of_a_consistent_estimator(truth):
    sol = offset_solution(truth.iloc[::10], dpos=(3.0, -4.0, 1.5))
    sol["std_n"], sol["std_e"], sol["std_d"] = 1.0, 2.0, 0.5
    nees = score_solution(truth, events(), sol)["nees"]
    assert nees == pytest.approx({"position": 9.0 + 4.0 + 9.0, "velocity": None,
                                  "attitude": None, "expected": 3.0}, abs=1e-4)

    rng = np.random.default_rng(3)
    sigma = np.array([0.5, 1.0, 2.0])
    err = rng.standard_normal((len(truth), 3)) * sigma
    sol = offset_solution(truth, dpos=tuple(err.T), dvel=(0.0, 0.0, 0.0))
    sol["std_n"], sol["std_e"], sol["std_d"] = sigma
    sol["std_vn"] = sol["std_ve"] = sol["std_vd"] = 0.1
    nees = score_solution(truth, events(), sol)["nees"]
    # mean of n chi-square(3) draws: expectation 3, standard deviation sqrt(6 / n) ~ 0.018
    assert nees["position"] == pytest.approx(3.0, abs=0.1)
    assert nees["velocity"] == pytest.approx(0.0, abs=1e-12)


def test_runtime_is_reported_when_given(truth):
    s = score_solution(truth, events(), truth.iloc[::100],
                       runtime={"runtime_s": 1.5, "realtime_factor": 129.0})
    assert s["runtime"] == {"seconds": 1.5, "realtime_factor": 129.0}


def test_outage_without_rows_or_motion_gives_nulls(truth):
    sol = offset_solution(truth.iloc[::10], dpos=(0.0, 1.0, 0.0))
    sol = sol.loc[(sol["t"] < 40.0) | (sol["t"] >= 60.0)]  # nothing during the first outage
    s = score_solution(truth, events((1.0, 5.0), (40.0, 60.0)), sol)
    standing, gap = s["outages"]
    assert standing["distance"] == 0.0  # the drive starts with a 10 s stop
    assert standing["end_horizontal"] == pytest.approx(1.0, abs=ATOL_M)
    assert standing["end_percent"] is None
    assert gap["distance"] > 0
    assert gap["max_horizontal"] is None and gap["end_horizontal"] is None
    assert gap["end_percent"] is None
    json.dumps(s, allow_nan=False)
