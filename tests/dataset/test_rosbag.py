"""The ROS 2 bag export read back by independent readers: the ``mcap`` package with the
``mcap_ros2`` decoder (which parses the schemas embedded in the file, not this project's
definitions) and ``rosbags``' own reader of the rosbag2 folder form. Frame conversions are
checked against pymap3d and the closed-form axes of the ZYX attitude."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pymap3d
import pytest
import yaml

from simulator.cli import main
from simulator.dataset.rosbag import UNKNOWN_VARIANCE
from simulator.datasheet import fix_uere_m

mcap_reader = pytest.importorskip("mcap.reader")
mcap_ros2_decoder = pytest.importorskip("mcap_ros2.decoder")


@pytest.fixture(scope="module")
def exported(quickstart, tmp_path_factory):
    """The quickstart dataset and a 1 Hz solution (truth with std columns) as one .mcap."""
    out = tmp_path_factory.mktemp("bag")
    truth = quickstart.read("truth")
    solution = truth.iloc[::100][["t", "lat", "lon", "alt", "vn", "ve", "vd", "roll", "pitch",
                                  "yaw"]].copy()
    for i, col in enumerate(("std_n", "std_e", "std_d", "std_vn", "std_ve", "std_vd",
                             "std_roll", "std_pitch", "std_yaw")):
        solution[col] = 0.1 * (i + 1)
    solution.to_csv(out / "mine.csv", index=False)
    bag = out / "drive.mcap"
    assert main(["export", str(quickstart.path), "--mcap", str(bag), "--solution",
                 str(out / "mine.csv")]) == 0
    with open(bag, "rb") as f:
        reader = mcap_reader.make_reader(f, decoder_factories=[mcap_ros2_decoder.DecoderFactory()])
        summary = reader.get_summary()
        topics: dict[str, list] = {}
        for _, channel, message, decoded in reader.iter_decoded_messages():
            topics.setdefault(channel.topic, []).append((message.log_time, decoded))
        f.seek(0)
        metadata = [m.name for m in mcap_reader.make_reader(f).iter_metadata()]
    return quickstart, solution, summary, topics, metadata


def _stamps(dataset, t) -> np.ndarray:
    utc = pd.Timestamp(dataset.manifest["utc_start"])
    return utc.value + np.round(np.asarray(t) * 1e9).astype(np.int64)


def _header_ns(msg) -> int:
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


def test_every_topic_with_its_count_and_schema(exported):
    dataset, solution, summary, topics, metadata = exported
    schema_of = {c.topic: summary.schemas[c.schema_id] for c in summary.channels.values()}
    expected = {
        "/imu/data": ("sensor_msgs/msg/Imu", len(dataset.read("imu"))),
        "/gnss/fix": ("sensor_msgs/msg/NavSatFix", len(dataset.read("gnss_fix"))),
        "/gnss/raw": ("landnav_msgs/msg/GnssEpoch", dataset.read("gnss_raw")["t"].nunique()),
        "/odometry/wheel": ("geometry_msgs/msg/TwistWithCovarianceStamped",
                            len(dataset.read("odometer"))),
        "/baro": ("sensor_msgs/msg/FluidPressure", len(dataset.read("baro"))),
        "/ground_truth/odometry": ("nav_msgs/msg/Odometry", len(dataset.read("truth"))),
        "/solutions/mine/odometry": ("nav_msgs/msg/Odometry", len(solution)),
        "/tf_static": ("tf2_msgs/msg/TFMessage", 1),
    }
    assert set(topics) == set(expected)
    for topic, (typename, count) in expected.items():
        schema = schema_of[topic]
        assert schema.name == typename and schema.encoding == "ros2msg"
        assert len(schema.data) > 0
        assert len(topics[topic]) == count == summary.statistics.channel_message_counts[
            next(c.id for c in summary.channels.values() if c.topic == topic)]
    raw_schema = schema_of["/gnss/raw"].data.decode()
    assert "MSG: landnav_msgs/GnssMeasurement" in raw_schema
    assert "MSG: std_msgs/Header" in raw_schema
    assert "rosbag2" in metadata  # the rosbag2 metadata record that ros2 bag reads


def test_stamps_are_utc_and_frames_as_documented(exported):
    dataset, _, _, topics, _ = exported
    frames = {"/imu/data": "imu_link", "/gnss/fix": "gnss_antenna", "/gnss/raw": "gnss_antenna",
              "/odometry/wheel": "base_link", "/baro": "base_link",
              "/ground_truth/odometry": "map"}
    streams = {"/imu/data": "imu", "/gnss/fix": "gnss_fix", "/odometry/wheel": "odometer",
               "/baro": "baro", "/ground_truth/odometry": "truth"}
    for topic, frame in frames.items():
        assert {m.header.frame_id for _, m in topics[topic]} == {frame}
        log = np.array([t for t, _ in topics[topic]])
        header = np.array([_header_ns(m) for _, m in topics[topic]])
        np.testing.assert_array_equal(log, header)
        if topic in streams:
            times = dataset.read(streams[topic])["t"]
            np.testing.assert_array_equal(header, _stamps(dataset, times))
    assert all(m.child_frame_id == "base_link" for _, m in topics["/ground_truth/odometry"])
    tf = topics["/tf_static"][0][1].transforms
    assert {x.child_frame_id for x in tf} == {"imu_link", "gnss_antenna"}
    assert {x.header.frame_id for x in tf} == {"base_link"}


def test_imu_values_and_covariances(exported):
    dataset, _, _, topics, _ = exported
    imu = dataset.read("imu")
    sheet = dataset.manifest["datasheet"]["imu"]
    msgs = [m for _, m in topics["/imu/data"]]
    gyro = np.array([[m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z]
                     for m in msgs])
    accel = np.array([[m.linear_acceleration.x, m.linear_acceleration.y,
                       m.linear_acceleration.z] for m in msgs])
    # FRD -> FLU: x kept, y and z negated
    np.testing.assert_array_equal(gyro, imu[["gyro_x", "gyro_y", "gyro_z"]].to_numpy()
                                  * [1, -1, -1])
    np.testing.assert_array_equal(accel, imu[["accel_x", "accel_y", "accel_z"]].to_numpy()
                                  * [1, -1, -1])
    rate = sheet["rate"]
    for group, cov in (("gyro", msgs[0].angular_velocity_covariance),
                       ("accel", msgs[0].linear_acceleration_covariance)):
        var = sheet[group]["noise_density"] ** 2 * rate + sheet[group]["resolution"] ** 2 / 12
        np.testing.assert_allclose(np.reshape(cov, (3, 3)), np.eye(3) * var, rtol=1e-12)
    assert msgs[0].orientation_covariance[0] == -1.0


def test_fix_raw_and_wheel_speed(exported):
    dataset, _, _, topics, _ = exported
    fix = dataset.read("gnss_fix")
    msgs = [m for _, m in topics["/gnss/fix"]]
    good = fix["fix"].to_numpy() >= 1
    lat = np.array([m.latitude for m in msgs])
    np.testing.assert_array_equal(lat[good], fix["lat"].to_numpy()[good])
    assert all((m.status.status == 0) == g for m, g in zip(msgs, good, strict=True))
    uere = fix_uere_m(dataset.manifest["datasheet"]["gnss"])
    i = int(np.flatnonzero(good)[0])
    cov = np.reshape(msgs[i].position_covariance, (3, 3))
    h, v = fix["hdop"].iloc[i], fix["vdop"].iloc[i]
    np.testing.assert_allclose(np.diag(cov), [(uere * h) ** 2 / 2, (uere * h) ** 2 / 2,
                                              (uere * v) ** 2])
    assert msgs[i].position_covariance_type == 1

    raw = dataset.read("gnss_raw")
    epochs = [m for _, m in topics["/gnss/raw"]]
    assert sum(len(e.measurements) for e in epochs) == len(raw)
    first = raw[raw["t"] == raw["t"].iloc[0]]
    np.testing.assert_array_equal([x.pseudorange for x in epochs[0].measurements],
                                  first["pseudorange"].to_numpy())
    np.testing.assert_array_equal([x.sv for x in epochs[0].measurements], first["sv"].to_numpy())
    np.testing.assert_array_equal(epochs[0].measurements[0].sat_position,
                                  first[["sat_x", "sat_y", "sat_z"]].to_numpy()[0])
    assert epochs[0].gps_week == dataset.manifest["gps_time_start"]["week"]

    odo = dataset.read("odometer")
    wheel = [m for _, m in topics["/odometry/wheel"]]
    np.testing.assert_array_equal([m.twist.twist.linear.x for m in wheel], odo["speed"])
    cov = np.reshape(wheel[0].twist.covariance, (6, 6))
    assert 0 < cov[0, 0] < 1.0 and np.all(np.diag(cov)[1:] == UNKNOWN_VARIANCE)


def test_truth_in_enu_and_flu(exported):
    dataset, _, _, topics, _ = exported
    truth = dataset.read("truth").iloc[::50]
    origin = dataset.manifest["origin"]
    msgs = [m for _, m in topics["/ground_truth/odometry"]][::50]
    pos = np.array([[m.pose.pose.position.x, m.pose.pose.position.y, m.pose.pose.position.z]
                    for m in msgs])
    e, n, u = pymap3d.geodetic2enu(truth["lat"], truth["lon"], truth["alt"], origin["lat"],
                                   origin["lon"], origin["alt"])
    np.testing.assert_allclose(pos, np.column_stack([e, n, u]), atol=1e-6)
    from scipy.spatial.transform import Rotation

    quat = np.array([[m.pose.pose.orientation.x, m.pose.pose.orientation.y,
                      m.pose.pose.orientation.z, m.pose.pose.orientation.w] for m in msgs])
    rot = Rotation.from_quat(quat)
    r, p, y = (truth[c].to_numpy() for c in ("roll", "pitch", "yaw"))
    # forward (FLU x) in ENU from the ZYX angles: east sin(y)cos(p), north cos(y)cos(p), up sin(p)
    forward = np.column_stack([np.sin(y) * np.cos(p), np.cos(y) * np.cos(p), np.sin(p)])
    np.testing.assert_allclose(rot.apply([1.0, 0.0, 0.0]), forward, atol=1e-9)
    # left (FLU y) in ENU: minus the body's right axis (Groves eq. 2.22, second column) in ENU
    right_ned = np.column_stack([
        np.cos(y) * np.sin(p) * np.sin(r) - np.sin(y) * np.cos(r),
        np.sin(y) * np.sin(p) * np.sin(r) + np.cos(y) * np.cos(r),
        np.cos(p) * np.sin(r)])
    left_enu = -np.column_stack([right_ned[:, 1], right_ned[:, 0], -right_ned[:, 2]])
    np.testing.assert_allclose(rot.apply([0.0, 1.0, 0.0]), left_enu, atol=1e-9)
    # the body-frame velocity has the truth's speed, forward when the car drives on
    v_body = np.array([[m.twist.twist.linear.x, m.twist.twist.linear.y, m.twist.twist.linear.z]
                       for m in msgs])
    np.testing.assert_allclose(np.linalg.norm(v_body, axis=1),
                               np.linalg.norm(truth[["vn", "ve", "vd"]].to_numpy(), axis=1),
                               atol=1e-9)
    moving = truth["speed"].to_numpy() > 5.0
    assert np.all(v_body[moving, 0] > 0.95 * truth["speed"].to_numpy()[moving])


def test_solution_covariances(exported):
    _, solution, _, topics, _ = exported
    msg = topics["/solutions/mine/odometry"][3][1]
    cov = np.reshape(msg.pose.covariance, (6, 6))
    s = solution.iloc[3]
    np.testing.assert_allclose(np.diag(cov), [s.std_e**2, s.std_n**2, s.std_d**2,
                                              s.std_roll**2, s.std_pitch**2, s.std_yaw**2])


def test_rosbag2_folder_read_by_rosbags(quickstart, tmp_path):
    rosbags_reader = pytest.importorskip("rosbags.highlevel")
    from rosbags.typesys import Stores, get_typestore

    bag = tmp_path / "drive"
    assert main(["export", str(quickstart.path), "--mcap", str(bag)]) == 0
    meta = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert meta["storage_identifier"] == "mcap"
    counts = {t["topic_metadata"]["name"]: t["message_count"]
              for t in meta["topics_with_message_count"]}
    assert counts["/imu/data"] == len(quickstart.read("imu"))
    qos = next(t["topic_metadata"]["offered_qos_profiles"]
               for t in meta["topics_with_message_count"]
               if t["topic_metadata"]["name"] == "/tf_static")
    latched = yaml.safe_load(qos)  # rosbag2 keeps the profiles as a YAML string
    assert latched[0]["durability"] == 1 and latched[0]["depth"] == 1  # transient local
    store = get_typestore(Stores.ROS2_HUMBLE)
    with rosbags_reader.AnyReader([bag], default_typestore=store) as reader:
        assert {c.topic for c in reader.connections} >= {"/imu/data", "/gnss/raw"}
        baro = [c for c in reader.connections if c.topic == "/baro"]
        pressures = [reader.deserialize(raw, c.msgtype).fluid_pressure
                     for c, _, raw in reader.messages(connections=baro)]
    np.testing.assert_array_equal(pressures, quickstart.read("baro")["pressure"].to_numpy())
