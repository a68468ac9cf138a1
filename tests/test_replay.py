"""The causal replay: message order across streams, no truth, initial state, output instants,
errors, and the solution file."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from simulator import columns as col
from simulator.dataset.io import open_dataset, write_dataset
from simulator.earth import ecef_to_ned, geodetic_to_ecef, wrap_angle
from simulator.errors import InputError
from simulator.outputs import atomic_output_dir
from simulator.replay import (
    STREAM_ORDER,
    merge_streams,
    output_times,
    read_solution,
    run_estimator,
    write_solution,
)
from tests.recording import Recorder
from tests.synthetic import write_synthetic

SHORT = [{"stop": {"duration": 2}}, {"accelerate": {"to_speed": 10.0, "accel": 2.0}},
         {"turn": {"angle": 90, "radius": 30}}, {"straight": {"duration": 3}}]


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    from tests.synthetic import scenario
    path = write_synthetic(tmp_path_factory.mktemp("replay") / "ds", scenario(SHORT))
    return open_dataset(path)


def test_merge_is_stable_for_equal_times():
    t, s, i = merge_streams([np.array([0.0, 1.0, 2.0]), np.array([1.0, 1.5]),
                             np.array([0.0, 1.0])])
    assert t.tolist() == [0.0, 0.0, 1.0, 1.0, 1.0, 1.5, 2.0]
    assert s.tolist() == [0, 2, 0, 1, 2, 1, 0]
    assert i.tolist() == [0, 0, 1, 0, 1, 1, 2]


def test_output_times_cover_grid_gnss_epochs_and_end():
    t = np.array([0.0, 0.1, 0.2, 0.25, 0.3, 0.35])
    stream = np.array([0, 0, 0, 1, 0, 0])
    times, upto = output_times(t, stream, [1], 10.0)
    assert times.tolist() == [0.0, 0.1, 0.2, 0.25, 0.3, 0.35]
    assert upto.tolist() == [1, 2, 3, 4, 5, 6]
    times, upto = output_times(np.array([0.0, 1.0, 2.0]), np.zeros(3, int), [0], 2.0)
    assert times.tolist() == [0.0, 0.5, 1.0, 1.5, 2.0]  # 2 Hz output from 1 Hz fixes
    assert upto.tolist() == [1, 1, 2, 2, 3]


def test_messages_come_in_time_order_and_never_carry_truth(dataset):
    frame, info = run_estimator(dataset, "tests.recording:Recorder", show_progress=False)
    rec = Recorder.last
    assert set(rec.columns) == {"imu", "odometer", "baro", "gnss_fix"}
    truth_only = set(col.TRUTH) - {"t", "lat", "lon", "alt", "vn", "ve", "vd", "speed"}
    for stream, cols in rec.columns.items():
        assert set(cols) <= set(dataset.read(stream).columns)
        assert not truth_only & set(cols), stream
    times = np.array([t for _, t, _ in rec.seen])
    assert np.all(np.diff(times) >= 0)
    ranks = np.array([STREAM_ORDER.index(s) for s, _, _ in rec.seen])
    same = np.diff(times) == 0
    assert np.all(np.diff(ranks)[same] > 0)  # equal times: imu, odometer, baro, gnss_fix
    for stream in rec.columns:  # every row of every stream, unchanged
        stored = dataset.read(stream)
        table = stored.drop(columns=[c for c in col.TEXT_COLUMNS if c in stored]).to_numpy(
            dtype=float)  # the numeric columns, as the replay hands them over
        rows = np.array([r for s, _, r in rec.seen if s == stream])
        np.testing.assert_array_equal(rows, table)
    # causality: at each request exactly the messages with t <= T had been handed
    for t_ask, n_seen in rec.asked:
        assert n_seen == np.searchsorted(times, t_ask, side="right")
    assert frame["t"].is_monotonic_increasing and frame["t"].is_unique
    steps = np.diff(frame["t"])
    assert np.allclose(steps[:-1], 0.1)  # 10 Hz, GNSS epochs fall on the grid
    assert frame["t"].iloc[-1] == times[-1]  # and the end of the data
    assert info["label"] == info["name"] == "tests.recording:Recorder"
    assert info["runtime_s"] > 0
    assert info["realtime_factor"] == pytest.approx(times[-1] / info["runtime_s"])


def test_initial_state_is_truth_perturbed_by_init(dataset):
    init = {"position_error": [10.0, -5.0, 2.0], "velocity_error": [0.1, 0.2, -0.3],
            "attitude_error": [1.0, -2.0, 3.0], "heading_error": 175.0}
    entry = {"name": "tests.recording:Recorder", "label": "rec", "init": init,
             "config": {"gain": 2.5}}
    _, info = run_estimator(dataset, entry, show_progress=False)
    rec = Recorder.last
    assert info["label"] == "rec" and rec.config == {"gain": 2.5, "flag": False}
    truth = dataset.read("truth")
    t0 = dataset.read("imu")["t"].iloc[0]
    row = truth[truth["t"] == t0].iloc[0]
    lat, lon, alt = rec.initial.position
    ned = ecef_to_ned(geodetic_to_ecef(lat, lon, alt), np.radians(row["lat"]),
                      np.radians(row["lon"]), row["alt"])
    np.testing.assert_allclose(ned, [10.0, -5.0, 2.0], atol=1e-6)
    np.testing.assert_allclose(rec.initial.velocity,
                               row[["vn", "ve", "vd"]].to_numpy(float) + [0.1, 0.2, -0.3])
    expected = row[["roll", "pitch", "yaw"]].to_numpy(float) + np.radians([1.0, -2.0, 178.0])
    np.testing.assert_allclose(wrap_angle(rec.initial.attitude - expected), 0.0, atol=1e-12)
    assert rec.initial.t == t0


def test_gnss_raw_epoch_is_one_message(tmp_path, dataset):
    sats = pd.DataFrame({"t": np.repeat([0.0, 1.0, 2.0], [5, 6, 4]),
                         "sv": np.r_[1:6, 1:7, 2:6].astype(float)})
    for c in col.GNSS_RAW:
        if c not in sats:
            sats[c] = 1.0
    imu = dataset.read("imu").iloc[:301]
    with atomic_output_dir(tmp_path / "raw", force=False) as tmp:
        write_dataset(tmp, {}, {"imu": imu, "gnss_raw": sats[list(col.GNSS_RAW)],
                                "truth": dataset.read("truth")})
    run_estimator(open_dataset(tmp_path / "raw"), "tests.recording:Recorder",
                  show_progress=False)
    epochs = [(t, r) for s, t, r in Recorder.last.seen if s == "gnss_raw"]
    assert [t for t, _ in epochs] == [0.0, 1.0, 2.0]
    assert [r.shape[0] for _, r in epochs] == [5, 6, 4]
    sv = Recorder.last.columns["gnss_raw"]["sv"]
    assert epochs[1][1][:, sv].tolist() == [1, 2, 3, 4, 5, 6]


def test_missing_needed_stream_names_stream_and_estimator(tmp_path):
    path = write_synthetic(tmp_path / "no_odo", streams=("imu", "gnss_fix"))
    with pytest.raises(InputError, match="'dead_reckoning'.*needs the 'odometer' stream"):
        run_estimator(open_dataset(path), "dead_reckoning", show_progress=False)


def test_scoring_only_stream_is_refused(dataset):
    with pytest.raises(InputError, match="scoring-only stream"):
        run_estimator(dataset, "tests.recording:Peeker", show_progress=False)


@pytest.mark.parametrize("config, message", [
    ({"gian": 1.0}, r"unknown config key\(s\) gian for estimator recorder; known: flag, gain"),
    ({"flag": "yes"}, "config key 'flag' of estimator recorder expects true or false"),
])
def test_bad_config_is_input_error(dataset, config, message):
    entry = {"name": "tests.recording:Recorder", "label": None, "init": None, "config": config}
    with pytest.raises(InputError, match=message):
        run_estimator(dataset, entry, show_progress=False)


def test_solution_file_round_trip_and_units(tmp_path):
    frame = pd.DataFrame({c: np.linspace(0.0, 1.0, 5) for c in col.SOLUTION})
    frame["std_n"] = 0.5
    frame["odo_scale"] = 1.01
    path = tmp_path / "sol.parquet"
    write_solution(frame, path)
    back = read_solution(path)
    pd.testing.assert_frame_equal(back, frame)
    import pyarrow.parquet as pq
    units = {f.name: f.metadata[b"unit"].decode() for f in pq.read_schema(path)}
    assert units["lat"] == "deg" and units["yaw"] == "rad" and units["std_n"] == "m"
    assert units["odo_scale"] == ""


def test_read_solution_rejects_bad_files(tmp_path):
    frame = pd.DataFrame({c: [0.0, 2.0, 1.0] for c in col.SOLUTION})
    bad_t = tmp_path / "bad_t.parquet"
    frame.to_parquet(bad_t)
    with pytest.raises(InputError, match=r"bad_t.parquet: t is not increasing: row 2"):
        read_solution(bad_t)
    no_yaw = tmp_path / "no_yaw.parquet"
    frame.assign(t=[0.0, 1.0, 2.0]).drop(columns="yaw").to_parquet(no_yaw)
    with pytest.raises(InputError, match=r"no_yaw.parquet: missing column\(s\) yaw"):
        read_solution(no_yaw)


def test_wrong_number_of_solution_values_names_the_columns(dataset):
    with pytest.raises(InputError, match=r"returned 3 values; it must return None or 9 numbers, "
                                         r"one per output column \(lat, lon"):
        run_estimator(dataset, "tests.recording:Miscounted", show_progress=False)


def test_dataset_without_truth_only_runs_self_initialising_estimators(tmp_path, dataset):
    with atomic_output_dir(tmp_path / "no_truth", force=False) as tmp:
        write_dataset(tmp, {}, {"imu": dataset.read("imu"), "gnss_fix": dataset.read("gnss_fix")})
    no_truth = open_dataset(tmp_path / "no_truth")
    with pytest.raises(InputError, match="starts from the true state.*no truth stream"):
        run_estimator(no_truth, "tests.recording:Recorder", show_progress=False)
    frame, _ = run_estimator(no_truth, "gnss_only", show_progress=False)
    assert len(frame) > 0


def test_stream_with_decreasing_time_is_refused(tmp_path, dataset):
    imu = dataset.read("imu").iloc[:50]
    imu.loc[10, "t"] = 100.0
    with atomic_output_dir(tmp_path / "bad", force=False) as tmp:
        write_dataset(tmp, {}, {"imu": imu, "truth": dataset.read("truth")})
    with pytest.raises(InputError, match=r"bad/imu.parquet: corrupt imu stream: time runs "
                                         r"backwards at row 11"):
        run_estimator(open_dataset(tmp_path / "bad"), "tests.recording:Recorder",
                      show_progress=False)


def test_replay_benchmark_dataset_runs(tmp_path):
    """The benchmark's synthetic streams (here 72 s of them) replay into its do-nothing
    estimator: 10 Hz output from the first to the last message."""
    from benchmarks.bench_replay import make_dataset
    make_dataset(tmp_path, hours=0.02)
    frame, info = run_estimator(open_dataset(tmp_path), "benchmarks.bench_replay:DoNothing",
                                show_progress=False)
    assert len(frame) == 721 and frame["t"].iloc[-1] == 72.0
    assert info["realtime_factor"] > 1.0


def test_sensor_error_priors_reach_the_initial_state():
    from conftest import scenario_data

    from simulator.dataset.generate import build_truth
    from simulator.errors import InputError
    from simulator.replay import initial_state

    segments = [{"accelerate": {"to_speed": 5.0, "accel": 1.0}}, {"straight": {"length": 20}}]
    truth = build_truth(scenario_data(segments)).table()
    drawn = {"odometer": {"scale_factor": 1.013}}
    state = initial_state(truth, 1.0, {"sensor_errors": "truth"}, drawn)
    assert state.sensor_errors == drawn
    given = {"odometer": {"scale_factor": 1.0}}
    assert initial_state(truth, 1.0, {"sensor_errors": given}, drawn).sensor_errors == given
    assert initial_state(truth, 1.0, None, drawn).sensor_errors == {}
    entry = {"name": "gnss_only", "init": {"sensor_errors": "truth"}}
    scenario_data(segments, estimators=[entry])
    with pytest.raises(InputError, match="sensor_errors"):
        scenario_data(segments, estimators=[{"name": "gnss_only",
                                             "init": {"sensor_errors": "exact"}}])


@pytest.mark.parametrize("output", ["rate", "increment"])
def test_estimator_is_told_what_the_imu_rows_hold(tmp_path, output):
    """``imu_output`` comes from the IMU stream's description in the manifest (written by the
    generator), not from the units: the estimator sees the IMU's configured output."""
    from simulator.dataset.generate import generate_dataset
    from simulator.scenario import Scenario, validate_data
    from tests.recording import Recorder

    data = validate_data({"start": {"lat": 37.5, "lon": 127.0},
                          "trajectory": {"kind": "segments",
                                         "segments": [{"stop": {"duration": 2}}]},
                          "sensors": {"imu": {"preset": "ideal", "rate": 100,
                                              "output": output}}}, "s.yaml")
    out = generate_dataset(Scenario(tmp_path / "s.yaml", data, []), tmp_path / "d",
                           show_progress=False)
    dataset = open_dataset(out)
    assert dataset.manifest["streams"]["imu"]["imu_output"] == output
    run_estimator(dataset, "tests.recording:Recorder", show_progress=False)
    assert Recorder.last.imu_output == output
