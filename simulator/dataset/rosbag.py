"""A dataset as a ROS 2 bag in MCAP (SPEC section 9), written with the maintained libraries:
``rosbags`` serialises the standard messages to CDR and writes the rosbag2 MCAP storage (schemas
embedded, the rosbag2 metadata record inside the file), so any MCAP reader and ``ros2 bag``
read the bag without this project.

Topics (each stamped with the UTC time of its sample: the manifest's ``utc_start`` plus ``t``,
in nanoseconds since the Unix epoch, as ROS time is):

==========================  =========================================  ==================
topic                       message                                    frame_id
==========================  =========================================  ==================
``/imu/data``               ``sensor_msgs/msg/Imu``                    ``imu_link``
``/gnss/fix``               ``sensor_msgs/msg/NavSatFix``              ``gnss_antenna``
``/gnss/raw``               ``landnav_msgs/msg/GnssEpoch`` (below)     ``gnss_antenna``
``/odometry/wheel``         ``geometry_msgs/msg/TwistWithCovarianceStamped``  ``base_link``
``/baro``                   ``sensor_msgs/msg/FluidPressure``          ``base_link``
``/mag``                    ``sensor_msgs/msg/MagneticField``          ``base_link``
``/ground_truth/odometry``  ``nav_msgs/msg/Odometry``                  ``map`` -> ``base_link``
``/solutions/LABEL/odometry``  ``nav_msgs/msg/Odometry`` (optional)    ``map`` -> ``base_link``
``/tf_static``              ``tf2_msgs/msg/TFMessage``                 ``base_link`` -> sensors
==========================  =========================================  ==================

Frames (REP 103 and REP 105): landnav's body frame is FRD at the IMU and its navigation frame
NED; ROS's body frame ``base_link`` is FLU at the same point and ``map`` is ENU, a local tangent
plane at the manifest's ``origin``. A body vector [x, y, z] FRD is [x, -y, -z] FLU; a
navigation vector [n, e, d] is [e, n, -d] ENU; an attitude C_b^n (FRD to NED) becomes
``T_ENU<-NED C_b^n T_FRD<-FLU``, with both T the diagonal-free permutations above (each its own
inverse). ``imu_link`` is ``base_link`` turned by the IMU's ``mounting`` (the unit's own axes,
FLU); ``gnss_antenna`` is at the antenna lever arm.

Covariances, from what a user knows (the manifest's ``datasheet``):

* ``Imu``: per axis the white-noise variance of one sample, ``N^2 f_s`` (N the noise density,
  f_s the rate) plus the quantisation ``q^2 / 12``; an axis the unit lacks reads 0 with
  variance ``UNKNOWN_VARIANCE``; no orientation (``orientation_covariance[0] = -1``, as the
  message's documentation asks).
* ``NavSatFix``: ``COVARIANCE_TYPE_APPROXIMATED``, east and north ``(UERE HDOP)^2 / 2``, up
  ``(UERE VDOP)^2``, with the UERE the root sum square of the receiver's error budget
  (``fix_uere_m``); ``STATUS_NO_FIX`` for epochs without a fix.
* the wheel speed: forward variance ``q^2 / 12`` of the speed's resolution and of one tick per
  sample (at least ``ODOMETER_FLOOR_M_S``^2); what the odometer does not measure
  (lateral, vertical, angular) ``UNKNOWN_VARIANCE``.
* ``FluidPressure``: the barometer's noise variance and its quantisation; ``MagneticField`` the
  magnetometer's noise variance.

The raw GNSS epoch is a message of this project's own, defined by ``GNSS_MSG_DEFINITIONS`` and
embedded in the file like every schema: one ``GnssMeasurement`` per satellite and signal, with
the columns of ``gnss_raw`` (SPEC section 5) in their units (NaN where the dataset has no such
column: ``carrier_phase`` without phase tracking).

Public names
------------
export_mcap, GNSS_MSG_DEFINITIONS, UNKNOWN_VARIANCE.
"""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from simulator.dataset.io import Dataset
from simulator.datasheet import fix_uere_m
from simulator.earth import (
    OMEGA_E_RAD_S,
    ecef_to_ned,
    euler_to_dcm,
    geodetic_to_ecef,
)
from simulator.errors import InputError, Problem
from simulator.outputs import atomic_output_dir, atomic_output_file
from simulator.timebase import parse_utc

UNKNOWN_VARIANCE = 1.0e6  # variance given to what a message carries but a sensor does not measure
ODOMETER_FLOOR_M_S = 0.01  # the smallest wheel-speed 1-sigma stated, m/s
L1_HZ = 1575.42e6

GNSS_MSG_DEFINITIONS = {
    "landnav_msgs/msg/GnssMeasurement": """\
# One satellite signal of a GNSS epoch (landnav's gnss_raw row, SPEC section 5).
string system            # RINEX system letter: G GPS, E Galileo, C BeiDou, R GLONASS, J QZSS
uint16 sv                # PRN (slot for GLONASS) within the system
string signal            # RINEX 3 band-and-attribute code, e.g. 1C
float64 frequency        # carrier frequency, Hz
float64 pseudorange      # m
float64 pseudorange_rate # m/s
float64 doppler          # Hz, positive when the satellite approaches
float64 carrier_phase    # cycles, RINEX sign (decreases as the range grows); NaN if not tracked
float64 cn0              # carrier-to-noise density, dB-Hz
uint8 lli                # RINEX loss-of-lock indicator bits
float64 lock_time        # s since the carrier arc began; NaN if not tracked
float64 elevation        # rad
float64 azimuth          # rad, from north, clockwise
float64[3] sat_position  # ECEF at transmit time, in the ECEF frame of transmit time, m
float64[3] sat_velocity  # m/s
float64 sat_clock        # broadcast satellite clock correction, m
float64 sat_clock_drift  # m/s
float64 iono             # broadcast-model ionospheric delay, m
float64 tropo            # model tropospheric delay, m
float64 group_delay      # broadcast TGD/BGD/ISC term applied to the signal, m
""",
    "landnav_msgs/msg/GnssEpoch": """\
# Every measurement of one receiver epoch (landnav's gnss_raw rows of one t).
std_msgs/Header header
uint32 gps_week
float64 gps_tow                             # s of week of the measurement epoch
landnav_msgs/GnssMeasurement[] measurements
""",
}

_FLIP_BODY = np.array([1.0, -1.0, -1.0])      # FRD <-> FLU
_NED_TO_ENU = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
_IMU_AXES = ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")
_RAW_SCALARS = ("pseudorange", "pseudorange_rate", "doppler", "carrier_phase", "cn0",
                "lock_time", "elevation", "azimuth", "sat_clock", "sat_clock_drift", "iono",
                "tropo", "group_delay")


def _typestore() -> Any:
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    types: dict = {}
    for name, text in GNSS_MSG_DEFINITIONS.items():
        types.update(get_types_from_msg(text, name))
    store.register(types)
    return store


def _ned_to_enu_attitude(roll: np.ndarray, pitch: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Quaternions (x, y, z, w) of FLU ``base_link`` in ENU from FRD-in-NED Euler angles."""
    from scipy.spatial.transform import Rotation

    c_bn = euler_to_dcm(roll, pitch, yaw)
    c_flu_enu = _NED_TO_ENU @ c_bn * _FLIP_BODY  # right-multiplying by diag(1,-1,-1)
    return Rotation.from_matrix(c_flu_enu).as_quat()


def _stamps_ns(utc_start_ns: int, t: np.ndarray) -> np.ndarray:
    """ROS stamps (int64 ns since the Unix epoch, UTC) of dataset times; the start is added
    as an integer, so a stamp keeps its nanoseconds (float seconds since 1970 would not)."""
    return utc_start_ns + np.round(np.asarray(t, dtype=float) * 1e9).astype(np.int64)


class _Messages:
    """Builds the messages of one bag from a dataset (one method per topic)."""

    def __init__(self, dataset: Dataset, store: Any):
        self.dataset = dataset
        self.store = store
        self.types = store.types
        sheet = dataset.manifest.get("datasheet") or {}
        self.sheet = sheet if isinstance(sheet, dict) else {}
        utc = parse_utc(str(dataset.field("utc_start")))
        since_epoch = utc - parse_utc("1970-01-01T00:00:00Z")
        self.utc_start_ns = (since_epoch.days * 86400 + since_epoch.seconds) * 1_000_000_000 \
            + since_epoch.microseconds * 1000
        origin = dataset.field("origin")
        self.origin = (math.radians(float(origin["lat"])), math.radians(float(origin["lon"])),
                       float(origin["alt"]))

    def header(self, stamp_ns: int, frame: str) -> Any:
        t = self.types
        sec, nsec = divmod(int(stamp_ns), 1_000_000_000)
        return t["std_msgs/msg/Header"](stamp=t["builtin_interfaces/msg/Time"](
            sec=sec, nanosec=nsec), frame_id=frame)

    def vector(self, xyz: np.ndarray) -> Any:
        return self.types["geometry_msgs/msg/Vector3"](x=float(xyz[0]), y=float(xyz[1]),
                                                      z=float(xyz[2]))

    def imu(self) -> Iterator[tuple[int, Any]]:
        frame = self.dataset.read("imu")
        sheet = self.sheet.get("imu") or {}
        rate = float(sheet.get("rate") or self.dataset.manifest["streams"]["imu"]["rate_hz"])
        values = np.zeros((len(frame), 6))
        variance = np.full(6, UNKNOWN_VARIANCE)
        for i, axis in enumerate(_IMU_AXES):
            if axis in frame:
                values[:, i] = frame[axis].to_numpy()
                group = sheet.get(axis.split("_")[0]) or {}
                density = float(group.get("noise_density") or 0.0)
                step = float(group.get("resolution") or 0.0)
                variance[i] = density**2 * rate + step**2 / 12.0
        if self.dataset.manifest["streams"]["imu"].get("imu_output") == "increment":
            dt = np.diff(frame["t"].to_numpy(), prepend=np.nan)
            dt[0] = 1.0 / rate
            values = values / dt[:, None]
        values[:, :3] *= _FLIP_BODY
        values[:, 3:] *= _FLIP_BODY
        msg = self.types["sensor_msgs/msg/Imu"]
        quat = self.types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
        no_orientation = np.zeros(9)
        no_orientation[0] = -1.0
        gyro_cov = np.diag(variance[:3]).ravel()
        accel_cov = np.diag(variance[3:]).ravel()
        for stamp, row in zip(_stamps_ns(self.utc_start_ns, frame["t"]), values, strict=True):
            yield stamp, msg(header=self.header(stamp, "imu_link"), orientation=quat,
                             orientation_covariance=no_orientation,
                             angular_velocity=self.vector(row[:3]),
                             angular_velocity_covariance=gyro_cov,
                             linear_acceleration=self.vector(row[3:]),
                             linear_acceleration_covariance=accel_cov)

    def fix(self) -> Iterator[tuple[int, Any]]:
        frame = self.dataset.read("gnss_fix")
        gnss = self.sheet.get("gnss") or {}
        uere = fix_uere_m(gnss)
        systems = gnss.get("systems") or ["gps"]
        service_bits = {"gps": 1, "glonass": 2, "beidou": 4, "galileo": 8}
        service = sum(service_bits.get(s, 0) for s in systems) or 1
        status_t = self.types["sensor_msgs/msg/NavSatStatus"]
        msg = self.types["sensor_msgs/msg/NavSatFix"]
        for stamp, row in zip(_stamps_ns(self.utc_start_ns, frame["t"]),
                              frame.itertuples(index=False), strict=True):
            fixed = row.fix >= 1 and np.isfinite(row.lat)
            h = float(row.hdop) if np.isfinite(row.hdop) else np.nan
            v = float(row.vdop) if np.isfinite(row.vdop) else np.nan
            cov = np.diag([(uere * h) ** 2 / 2, (uere * h) ** 2 / 2, (uere * v) ** 2])
            yield stamp, msg(
                header=self.header(stamp, "gnss_antenna"),
                status=status_t(status=0 if fixed else -1, service=service),
                latitude=float(row.lat), longitude=float(row.lon), altitude=float(row.alt),
                position_covariance=cov.ravel(),
                position_covariance_type=1 if fixed and np.isfinite(cov).all() else 0)

    def raw(self) -> Iterator[tuple[int, Any]]:
        frame = self.dataset.read("gnss_raw")
        week0 = int(self.dataset.field("gps_time_start", "week"))
        tow0 = float(self.dataset.field("gps_time_start", "tow"))
        meas_t = self.types["landnav_msgs/msg/GnssMeasurement"]
        epoch_t = self.types["landnav_msgs/msg/GnssEpoch"]
        n = len(frame)
        column = {c: (frame[c].to_numpy(dtype=float) if c in frame else np.full(n, np.nan))
                  for c in _RAW_SCALARS}
        if "frequency" in frame:
            column["frequency"] = frame["frequency"].to_numpy(dtype=float)
        else:
            column["frequency"] = np.full(n, L1_HZ)
        system = frame["system"].astype(str).to_numpy() if "system" in frame else np.full(n, "G")
        signal = frame["signal"].astype(str).to_numpy() if "signal" in frame else np.full(n, "1C")
        lli = (frame["lli"].fillna(0).to_numpy(dtype=int) if "lli" in frame
               else np.zeros(n, dtype=int))
        sat_pos = np.ascontiguousarray(frame[["sat_x", "sat_y", "sat_z"]].to_numpy(dtype=float))
        sat_vel = np.ascontiguousarray(frame[["sat_vx", "sat_vy", "sat_vz"]].to_numpy(float))
        sv = frame["sv"].to_numpy(dtype=int)
        t = frame["t"].to_numpy(dtype=float)
        starts = np.flatnonzero(np.r_[True, np.diff(t) != 0.0])
        ends = np.r_[starts[1:], n]
        for first, last in zip(starts, ends, strict=True):
            measurements = [
                meas_t(system=str(system[i]), sv=int(sv[i]), signal=str(signal[i]),
                       frequency=float(column["frequency"][i]),
                       sat_position=sat_pos[i], sat_velocity=sat_vel[i], lli=int(lli[i]),
                       **{c: float(column[c][i]) for c in _RAW_SCALARS})
                for i in range(first, last)]
            stamp = int(_stamps_ns(self.utc_start_ns, t[first]))
            tow = tow0 + t[first]
            week = week0 + int(tow // 604800.0)
            yield stamp, epoch_t(header=self.header(stamp, "gnss_antenna"), gps_week=week,
                                 gps_tow=float(tow % 604800.0), measurements=measurements)

    def odometer(self) -> Iterator[tuple[int, Any]]:
        frame = self.dataset.read("odometer")
        sheet = self.sheet.get("odometer") or {}
        rate = float(sheet.get("rate") or self.dataset.manifest["streams"]["odometer"]["rate_hz"])
        ticks = float(sheet.get("ticks_per_meter") or 0.0)
        tick_speed = rate / ticks if ticks > 0 else 0.0  # one tick per sample, m/s
        step = float(sheet.get("speed_resolution") or 0.0)
        forward = max((tick_speed**2 + step**2) / 12.0, ODOMETER_FLOOR_M_S**2)
        cov = np.diag([forward] + [UNKNOWN_VARIANCE] * 5).ravel()
        twist_t = self.types["geometry_msgs/msg/Twist"]
        with_cov = self.types["geometry_msgs/msg/TwistWithCovariance"]
        msg = self.types["geometry_msgs/msg/TwistWithCovarianceStamped"]
        zero = np.zeros(3)
        for stamp, speed in zip(_stamps_ns(self.utc_start_ns, frame["t"]),
                                frame["speed"].to_numpy(dtype=float), strict=True):
            twist = twist_t(linear=self.vector([speed, 0.0, 0.0]), angular=self.vector(zero))
            yield stamp, msg(header=self.header(stamp, "base_link"),
                             twist=with_cov(twist=twist, covariance=cov))

    def baro(self) -> Iterator[tuple[int, Any]]:
        frame = self.dataset.read("baro")
        sheet = self.sheet.get("baro") or {}
        variance = (float(sheet.get("noise") or 0.0) ** 2
                    + float(sheet.get("resolution") or 0.0) ** 2 / 12.0)
        msg = self.types["sensor_msgs/msg/FluidPressure"]
        for stamp, p in zip(_stamps_ns(self.utc_start_ns, frame["t"]),
                            frame["pressure"].to_numpy(dtype=float), strict=True):
            yield stamp, msg(header=self.header(stamp, "base_link"), fluid_pressure=float(p),
                             variance=variance)

    def mag(self) -> Iterator[tuple[int, Any]]:
        frame = self.dataset.read("mag")
        sheet = self.sheet.get("mag") or {}
        noise = float(sheet.get("noise") or 0.0)
        cov = np.diag([noise**2] * 3).ravel()
        values = frame[["mag_x", "mag_y", "mag_z"]].to_numpy(dtype=float) * _FLIP_BODY
        msg = self.types["sensor_msgs/msg/MagneticField"]
        for stamp, row in zip(_stamps_ns(self.utc_start_ns, frame["t"]), values, strict=True):
            yield stamp, msg(header=self.header(stamp, "base_link"),
                             magnetic_field=self.vector(row), magnetic_field_covariance=cov)

    def odometry(self, frame: pd.DataFrame, with_std: bool) -> Iterator[tuple[int, Any]]:
        """``nav_msgs/Odometry`` of a trajectory (truth, or a solution with its std columns)."""
        lat0, lon0, alt0 = self.origin
        lat = np.radians(frame["lat"].to_numpy(dtype=float))
        lon = np.radians(frame["lon"].to_numpy(dtype=float))
        alt = frame["alt"].to_numpy(dtype=float)
        ned = ecef_to_ned(geodetic_to_ecef(lat, lon, alt).reshape(-1, 3), lat0, lon0, alt0)
        enu = ned @ _NED_TO_ENU.T
        roll, pitch, yaw = (frame[c].to_numpy(dtype=float) for c in ("roll", "pitch", "yaw"))
        # a 2-D solution's NaN roll and pitch are drawn level, with unknown variance
        level = ~np.isfinite(roll) | ~np.isfinite(pitch)
        quat = _ned_to_enu_attitude(np.where(level, 0.0, roll), np.where(level, 0.0, pitch),
                                    np.nan_to_num(yaw))
        v_ned = frame[["vn", "ve", "vd"]].to_numpy(dtype=float)
        c_bn = euler_to_dcm(np.where(level, 0.0, roll), np.where(level, 0.0, pitch),
                            np.nan_to_num(yaw))
        v_body = np.einsum("nji,nj->ni", c_bn, v_ned) * _FLIP_BODY
        if {"wx", "wy", "wz"} <= set(frame):  # relative to the Earth-fixed map frame
            w_ie_n = OMEGA_E_RAD_S * np.column_stack([np.cos(lat), 0 * lat, -np.sin(lat)])
            w = frame[["wx", "wy", "wz"]].to_numpy(dtype=float) - np.einsum(
                "nji,nj->ni", c_bn, w_ie_n)
            w *= _FLIP_BODY
            w_var = 0.0
        else:
            w = np.zeros_like(v_body)
            w_var = UNKNOWN_VARIANCE
        t = self.types
        pose_cov = np.zeros((len(frame), 6, 6))
        twist_cov = np.zeros((len(frame), 6, 6))
        twist_cov[:, 3:, 3:] = np.eye(3) * w_var
        if with_std:
            std = {c: (frame[c].to_numpy(dtype=float) if c in frame
                       else np.full(len(frame), np.nan))
                   for c in ("std_n", "std_e", "std_d", "std_roll", "std_pitch", "std_yaw",
                             "std_vn", "std_ve", "std_vd")}
            # ENU position: east, north, up; FLU rotations: roll, pitch, yaw (signs squared away)
            for i, key in enumerate(("std_e", "std_n", "std_d", "std_roll", "std_pitch",
                                     "std_yaw")):
                pose_cov[:, i, i] = np.where(np.isfinite(std[key]), std[key] ** 2,
                                             UNKNOWN_VARIANCE)
            # body-frame velocity variance: the NED variances' mean as an isotropic value
            v_var = np.nanmean(np.column_stack([std["std_vn"], std["std_ve"], std["std_vd"]])
                               ** 2, axis=1)
            v_var = np.where(np.isfinite(v_var), v_var, UNKNOWN_VARIANCE)
            twist_cov[:, :3, :3] = np.eye(3) * v_var[:, None, None]
            twist_cov[:, 3:, 3:] = np.eye(3) * UNKNOWN_VARIANCE
        msg = t["nav_msgs/msg/Odometry"]
        for i, stamp in enumerate(_stamps_ns(self.utc_start_ns, frame["t"])):
            pose = t["geometry_msgs/msg/Pose"](
                position=t["geometry_msgs/msg/Point"](x=float(enu[i, 0]), y=float(enu[i, 1]),
                                                      z=float(enu[i, 2])),
                orientation=t["geometry_msgs/msg/Quaternion"](
                    x=float(quat[i, 0]), y=float(quat[i, 1]), z=float(quat[i, 2]),
                    w=float(quat[i, 3])))
            twist = t["geometry_msgs/msg/Twist"](linear=self.vector(v_body[i]),
                                                 angular=self.vector(w[i]))
            yield stamp, msg(
                header=self.header(stamp, "map"), child_frame_id="base_link",
                pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=pose,
                                                                covariance=pose_cov[i].ravel()),
                twist=t["geometry_msgs/msg/TwistWithCovariance"](
                    twist=twist, covariance=twist_cov[i].ravel()))

    def tf_static(self) -> Iterator[tuple[int, Any]]:
        from scipy.spatial.transform import Rotation

        t = self.types
        imu = self.sheet.get("imu") or {}
        gnss = self.sheet.get("gnss") or {}
        mounting = np.radians(np.asarray(imu.get("mounting") or [0.0, 0.0, 0.0], dtype=float))
        c_mount = euler_to_dcm(*mounting)  # the unit's axes (FRD) in the car's (FRD)
        mount_quat = Rotation.from_matrix(np.diag(_FLIP_BODY) @ c_mount @ np.diag(_FLIP_BODY)
                                          ).as_quat()
        arm = np.asarray(gnss.get("antenna_lever_arm") or [0.0, 0.0, 0.0], float) * _FLIP_BODY
        stamp = int(_stamps_ns(self.utc_start_ns, 0.0))
        transforms = []
        for child, offset, quat in (("imu_link", np.zeros(3), mount_quat),
                                    ("gnss_antenna", arm, np.array([0.0, 0.0, 0.0, 1.0]))):
            transforms.append(t["geometry_msgs/msg/TransformStamped"](
                header=self.header(stamp, "base_link"), child_frame_id=child,
                transform=t["geometry_msgs/msg/Transform"](
                    translation=self.vector(offset),
                    rotation=t["geometry_msgs/msg/Quaternion"](
                        x=float(quat[0]), y=float(quat[1]), z=float(quat[2]),
                        w=float(quat[3])))))
        yield stamp, t["tf2_msgs/msg/TFMessage"](transforms=transforms)


def _topics(messages: _Messages, solutions: Mapping[str, pd.DataFrame]
            ) -> list[tuple[str, str, Iterator[tuple[int, Any]]]]:
    has = messages.dataset.has
    topics = [("/tf_static", "tf2_msgs/msg/TFMessage", messages.tf_static())]
    for stream, topic, typename, make in (
            ("imu", "/imu/data", "sensor_msgs/msg/Imu", messages.imu),
            ("gnss_fix", "/gnss/fix", "sensor_msgs/msg/NavSatFix", messages.fix),
            ("gnss_raw", "/gnss/raw", "landnav_msgs/msg/GnssEpoch", messages.raw),
            ("odometer", "/odometry/wheel", "geometry_msgs/msg/TwistWithCovarianceStamped",
             messages.odometer),
            ("baro", "/baro", "sensor_msgs/msg/FluidPressure", messages.baro),
            ("mag", "/mag", "sensor_msgs/msg/MagneticField", messages.mag)):
        if has(stream):
            topics.append((topic, typename, make()))
    if has("truth"):
        topics.append(("/ground_truth/odometry", "nav_msgs/msg/Odometry",
                       messages.odometry(messages.dataset.read("truth"), with_std=False)))
    for label, frame in solutions.items():
        topics.append((f"/solutions/{label}/odometry", "nav_msgs/msg/Odometry",
                       messages.odometry(frame, with_std=True)))
    return topics


def _latched_qos() -> Any:
    """Reliable, transient-local, keep last 1: what tf2's static broadcaster offers, so that
    ``ros2 bag play`` latches ``/tf_static`` for late subscribers."""
    from rosbags.interfaces import (
        Qos,
        QosDurability,
        QosHistory,
        QosLiveliness,
        QosReliability,
        QosTime,
    )

    never = QosTime(sec=2147483647, nsec=4294967295)
    return Qos(QosHistory.KEEP_LAST, 1, QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL,
               never, never, QosLiveliness.AUTOMATIC, never, False)


def _write_bag(dataset: Dataset, bag_dir: Path, solutions: Mapping[str, pd.DataFrame]) -> None:
    from rosbags.rosbag2 import StoragePlugin, Writer

    store = _typestore()
    messages = _Messages(dataset, store)
    with Writer(bag_dir, version=8, storage_plugin=StoragePlugin.MCAP) as writer:
        for topic, typename, stream in _topics(messages, solutions):
            qos = [_latched_qos()] if topic == "/tf_static" else []
            connection = writer.add_connection(topic, typename, typestore=store,
                                               offered_qos_profiles=qos)
            for stamp, msg in stream:
                writer.write(connection, int(stamp), store.serialize_cdr(msg, typename))


def export_mcap(dataset: Dataset, path: str | Path, force: bool = False,
                solutions: Mapping[str, pd.DataFrame] | None = None,
                option: str = "export_mcap") -> Path:
    """Write the dataset (and optional solutions, by label) as a ROS 2 bag in MCAP.

    ``path`` ending in ``.mcap`` is one MCAP file (the rosbag2 metadata inside it: ``ros2 bag
    info FILE.mcap`` reads it on ROS 2 Iron and later); any other ``path`` is a rosbag2 folder
    (``metadata.yaml`` beside the ``.mcap``, for every ROS 2 release that reads MCAP). The bag
    is written under a temporary name and moved into place when complete; an existing output
    is replaced only with ``force``. Returns the path written."""
    out = Path(path)
    if not dataset.has("imu") and not dataset.has("gnss_fix"):
        raise InputError([Problem(str(dataset.path), None, "", f"{option}: the dataset has "
                                  "neither an imu nor a gnss_fix stream; nothing to export")])
    solutions = dict(solutions or {})
    if out.suffix == ".mcap":
        with atomic_output_file(out, force, [dataset.path], "mcap") as tmp_file:
            with tempfile.TemporaryDirectory(dir=Path(tmp_file).parent,
                                             prefix=f".{out.stem}.bag-") as work:
                bag = Path(work) / out.stem
                _write_bag(dataset, bag, solutions)
                os.replace(bag / f"{out.stem}.mcap", tmp_file)
        return out
    with atomic_output_dir(out, force, [dataset.path]) as tmp_dir:
        bag = Path(tmp_dir) / out.name
        _write_bag(dataset, bag, solutions)
        for item in bag.iterdir():
            os.replace(item, Path(tmp_dir) / item.name)
        bag.rmdir()
    return out
