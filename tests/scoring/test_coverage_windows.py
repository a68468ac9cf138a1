"""Coverage, outages with no rows, degraded windows and sensor errors (issue 17, "what must be
shown"): each checked against values computed by hand from the solution's construction."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from simulator import columns as col
from simulator.scoring.metrics import score_solution
from tests.scoring_helpers import events, offset_solution, quickstart_truth


@pytest.fixture(scope="module")
def truth() -> pd.DataFrame:
    return quickstart_truth()


def _ten_hz(truth: pd.DataFrame) -> pd.DataFrame:
    return offset_solution(truth.iloc[::10], dpos=(1.0, 0.0, 0.0))


def test_full_solution_covers_the_drive(truth):
    s = score_solution(truth, events((40.0, 60.0)), _ten_hz(truth))
    assert s["coverage"]["fraction"] == pytest.approx(1.0)
    assert s["coverage"]["longest_gap"] == pytest.approx(0.1, abs=1e-9)
    assert s["outages"][0]["end_horizontal"] == pytest.approx(1.0, abs=1e-5)


def test_solution_stopping_in_an_outage_gets_null_entries_and_less_coverage(truth):
    sol = _ten_hz(truth)
    t_end = float(truth["t"].iloc[-1])
    stopped = sol.loc[sol["t"] < 120.0]  # stops inside the outage 120-150 s
    s = score_solution(truth, events((40.0, 60.0), (120.0, 150.0)), stopped)
    first, second = s["outages"]
    assert first["end_horizontal"] == pytest.approx(1.0, abs=1e-5)
    assert second["max_horizontal"] is None and second["end_horizontal"] is None
    assert second["end_percent"] is None and second["duration"] == 30.0
    # the window is covered only 0.15 s past the last row at 119.9 s
    assert first["coverage"] == pytest.approx({"fraction": 1.0, "longest_gap": 0.1})
    assert second["coverage"] == pytest.approx({"fraction": 0.05 / 30.0, "longest_gap": 30.0},
                                               abs=1e-9)
    # rows every 0.1 s cover 0.15 s either side; the last row is at 119.9 s
    last = float(stopped["t"].iloc[-1])
    expected = 1.0 - (t_end - last - 0.15) / t_end
    assert s["coverage"]["fraction"] == pytest.approx(expected, abs=1e-9) and expected < 1.0
    assert s["coverage"]["longest_gap"] == pytest.approx(t_end - last, abs=1e-9)


def test_rows_missing_inside_an_outage_count_against_coverage(truth):
    sol = _ten_hz(truth)
    t = sol["t"].to_numpy()
    gap = sol.loc[(t < 120.0) | (t >= 150.0)]
    s = score_solution(truth, events((120.0, 150.0)), gap)
    t_end = float(truth["t"].iloc[-1])
    # the rows either side are 119.9 s and 150.0 s: 30.1 s apart, 0.3 s of it covered
    assert s["coverage"]["fraction"] == pytest.approx(1.0 - (30.1 - 0.3) / t_end, abs=1e-9)
    assert s["coverage"]["longest_gap"] == pytest.approx(30.1, abs=1e-9)
    assert s["outages"][0]["max_horizontal"] is None
    # the row at 119.9 s reaches 0.05 s into the window, the row at 150 s 0.15 s back into it
    assert s["outages"][0]["coverage"] == pytest.approx(
        {"fraction": 0.2 / 30.0, "longest_gap": 30.0}, abs=1e-9)


def test_solution_without_gnss_has_no_outage_scores(truth):
    s = score_solution(truth, events((40.0, 60.0)), _ten_hz(truth), uses_gnss=False)
    assert s["outages"] is None and s["degraded"] is None
    assert s["horizontal"]["rms"] == pytest.approx(1.0, abs=1e-5)


def test_nan_attitude_is_left_out_of_its_metrics_only(truth):
    sol = _ten_hz(truth)
    sol[["roll", "pitch"]] = np.nan
    s = score_solution(truth, events(), sol)
    assert s["attitude"]["roll_rms"] is None and s["attitude"]["pitch_rms"] is None
    assert s["attitude"]["yaw_rms"] == pytest.approx(0.0, abs=1e-9)  # yaw is still scored
    assert s["horizontal"]["rms"] == pytest.approx(1.0, abs=1e-5)
    assert s["rows"]["position"] == len(sol) and s["rows"]["attitude"] == 0


def test_degraded_windows_have_kind_satellites_and_drift(truth):
    sol = _ten_hz(truth)
    t = sol["t"].to_numpy()
    east = np.where((t >= 100.0) & (t < 110.0), 2.0, 0.0)
    sol = offset_solution(truth.iloc[::10], dpos=(0.0, east, 0.0))
    rows = [{"t_start": 100.0, "t_end": 110.0, "kind": "gnss_satellite_limit",
             "detail": '{"count": 3}'},
            {"t_start": 20.0, "t_end": 30.0, "kind": "zone", "detail": "downtown"},
            {"t_start": 50.0, "t_end": 55.0, "kind": "gnss_multipath", "detail": "{}"},
            {"t_start": 60.0, "t_end": 65.0, "kind": "zone", "detail": "tunnel"}]
    ev = pd.DataFrame(rows, columns=list(col.EVENTS))
    fix_t = np.arange(0.0, 190.0, 1.0)
    fix = pd.DataFrame({"t": fix_t, "num_sats": np.where((fix_t >= 100) & (fix_t < 110), 3,
                                                         np.where(fix_t < 50, 9, 7))})
    s = score_solution(truth, ev, sol, canyon_zones={"downtown"}, gnss_fix=fix)
    kinds = [(w["kind"], w["start"], w["satellites"]) for w in s["degraded"]]
    assert kinds == [("canyon", 20.0, 9.0), ("gnss_multipath", 50.0, 7.0),
                     ("gnss_satellite_limit", 100.0, 3.0)]
    limit = s["degraded"][2]
    assert limit["end_horizontal"] == pytest.approx(2.0, abs=1e-5)
    assert limit["max_horizontal"] == pytest.approx(2.0, abs=1e-5)
    assert s["degraded"][0]["max_horizontal"] == pytest.approx(0.0, abs=1e-5)
    assert s["outages"] == []


def _truth_sensors(truth: pd.DataFrame) -> pd.DataFrame:
    t = np.arange(0.0, float(truth["t"].iloc[-1]), 0.5)
    return pd.DataFrame({"t": t, "gyro_bias_z": 1e-3 + 1e-5 * t,
                         "odometer_scale_factor": 1.01 + 1e-4 * np.sin(t)})


def test_sensor_errors_of_true_values_are_zero_and_of_zeros_the_truth_rms(truth):
    sensors = _truth_sensors(truth)
    sol = _ten_hz(truth)
    t = sol["t"].to_numpy()
    inside = t <= sensors["t"].iloc[-1]
    true_gz = 1e-3 + 1e-5 * t  # linear: interpolation is exact
    sol["gyro_bias_z"] = true_gz
    exact = score_solution(truth, events(), sol, truth_sensors=sensors)["sensor_errors"]
    assert set(exact) == {"gyro_bias_z"}
    assert exact["gyro_bias_z"]["rms"] == pytest.approx(0.0, abs=1e-15)
    sol["gyro_bias_z"] = 0.0
    zeros = score_solution(truth, events(), sol, truth_sensors=sensors)["sensor_errors"]
    expected = np.sqrt(np.mean(true_gz[inside] ** 2))
    assert zeros["gyro_bias_z"]["rms"] == pytest.approx(expected, rel=1e-12)
    assert zeros["gyro_bias_z"]["final"] == pytest.approx(-true_gz[inside][-1], rel=1e-12)


def test_end_error_needs_a_row_within_one_second_of_the_end(truth):
    """The end error is the window's last row's, if it lies at most 1 s before the end; the
    row at the end itself (after GNSS returned) never stands for it."""
    every_2s = truth.iloc[::200].reset_index(drop=True)  # rows at 0, 2, 4, ... s
    t = every_2s["t"].to_numpy()
    east = np.where(t < 150.0, 0.1 * t, 0.0)  # the row at 150 s is back on the truth
    sol = offset_solution(every_2s, dpos=(0.0, east, 0.0))
    far, near, at_row = score_solution(  # the outages come sorted by their start
        truth, events((120.0, 149.0), (100.0, 111.5), (140.0, 148.0)), sol)["outages"]
    assert near["end_horizontal"] == pytest.approx(0.1 * 148.0, abs=1e-5)  # 1 s before
    assert near["max_horizontal"] == pytest.approx(0.1 * 148.0, abs=1e-5)
    assert far["end_horizontal"] is None and far["end_percent"] is None  # 1.5 s before
    assert far["max_horizontal"] == pytest.approx(0.1 * 110.0, abs=1e-5)
    assert far["coverage"]["longest_gap"] == pytest.approx(2.0, abs=1e-9)  # between rows
    # a row at 148 s, the window's end, but the window's own last row is 2 s before it
    assert at_row["end_horizontal"] is None
