"""comma2k19 segments (comma.ai, "A Commute in Data: The comma2k19 Dataset", 2018): a car's
phone-grade IMU, CAN speed, u-blox raw GNSS and fixes, and comma's pose solution.

A segment folder holds ``processed_log/`` and ``global_pose/``; every array is a NumPy file
without extension, each stream a ``t`` (device boot time, s) and a ``value`` array (the
dataset's README). Mapped as follows (nothing is resampled: every stream keeps its own
timestamps):

* time: the pose's ``frame_times`` (boot time) and ``frame_gps_times`` ([week, TOW]) give the
  boot-to-GPS offset by a least-squares line (slope 1 within its fit, checked); ``t = 0`` is the
  first sample of any stream. GNSS measurements are stamped with their own GPS time (the raw
  epoch's TOW, the fix's UTC milliseconds), not with the log time at which they arrived
  (about 0.2 s later).
* ``imu``: ``IMU/accelerometer`` (m/s^2, the specific force: -9.8 on the down axis at rest) and
  ``IMU/gyro`` (rad/s, the phone's bias-calibrated output, what Android hands an application),
  axes [forward, right, down] = FRD. The magnetometer (``IMU/magnetometer``, uT) becomes
  ``mag`` in tesla.
* ``odometer``: ``CAN/speed`` (m/s), the car's speed from its wheel sensors.
* ``gnss_fix``: ``GNSS/live_gnss_ublox`` [lat, lon, speed, UTC ms, alt, bearing (deg)]: the
  altitude is ellipsoidal (it agrees with the pose to 2 m, where the geoid lies 32 m below
  the ellipsoid); the NED velocity from speed and bearing, its down component unknown (NaN);
  satellite count and DOP are not logged (NaN).
* ``gnss_raw``: ``GNSS/raw_gnss_ublox`` [NMEA id (1-32 GPS, 65-96 GLONASS slot + 64), week,
  TOW, GLONASS channel, pseudorange (m), its std, pseudorange rate (m/s), its std, C/N0 (dB-Hz),
  carrier phase (cycles)]; Doppler -rate f / c on each signal's frequency (GLONASS FDMA:
  1602 + 0.5625 k MHz). The segment carries no broadcast ephemeris: satellite positions,
  velocities and clocks, and the model delays, are NaN, and the manifest says so (``lacks``).
* ``truth``: ``global_pose`` (20 Hz, comma's tightly coupled INS/GNSS/vision solution): ECEF
  position and velocity and the quaternion (scalar first) of the camera frame [forward, right,
  down], which rotates camera vectors into ECEF (the ECEF velocity turned by its inverse is
  forward). landnav's body frame is taken as that camera frame: the phone's IMU axes are
  aligned with it (both FRD of the same device), which the pitch of the pose's body velocity
  (a few degrees: the device looks slightly down) shows is not the car's own frame.

Public names
------------
read_comma2k19.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from simulator.errors import InputError, Problem
from simulator.recordings.common import Recording, reference_truth
from simulator.timebase import SECONDS_PER_WEEK, leap_seconds, utc_to_gps

C_M_S = 299792458.0
GPS_L1_HZ = 1575.42e6
GLONASS_G1_HZ = 1602.0e6
GLONASS_G1_STEP_HZ = 0.5625e6
NOT_ON_RECORD = ("satellite positions, velocities and clocks and the model delays "
                 "(sat_*, iono, tropo, elevation, azimuth): the segment has no broadcast "
                 "ephemeris")


def _load(root: Path, *parts: str) -> np.ndarray:
    path = root.joinpath(*parts)
    if not path.is_file():
        raise InputError([Problem(str(root), None, "/".join(parts),
                                  "missing: a comma2k19 segment has processed_log/ and "
                                  "global_pose/ with t and value arrays")])
    try:
        return np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise InputError([Problem(str(path), None, "", f"not a NumPy array: {exc}")]
                         ) from None


def _median_rate(t: np.ndarray) -> float:
    return float(round(1.0 / np.median(np.diff(t)), 1))


def read_comma2k19(sources: list[str]) -> Recording:
    """Read one comma2k19 segment folder (see the module docstring)."""
    if len(sources) != 1:
        raise InputError([Problem("landnav import comma2k19", None, "SOURCE",
                                  "give one segment folder (the one holding processed_log/ "
                                  "and global_pose/)")])
    root = Path(sources[0])
    log = ("processed_log",)
    frame_t = _load(root, "global_pose", "frame_times")
    frame_gps = _load(root, "global_pose", "frame_gps_times")
    slope, offset = np.polyfit(frame_t, frame_gps[:, 1], 1)
    if abs(slope - 1.0) > 1e-6:
        raise InputError([Problem(str(root), None, "global_pose/frame_gps_times",
                                  f"boot time and GPS time do not run at one rate "
                                  f"(slope {slope:.9f})")])
    offset = float(np.median(frame_gps[:, 1] - frame_t))  # GPS TOW = boot time + offset
    week = int(frame_gps[0, 0])

    imu_t = _load(root, *log, "IMU", "accelerometer", "t")
    gyro_t = _load(root, *log, "IMU", "gyro", "t")
    accel = _load(root, *log, "IMU", "accelerometer", "value")
    gyro = _load(root, *log, "IMU", "gyro", "value")
    if not np.array_equal(imu_t, gyro_t):
        raise InputError([Problem(str(root), None, "processed_log/IMU/gyro/t",
                                  "the gyro and accelerometer samples are not simultaneous; "
                                  "this importer does not resample")])
    speed_t = _load(root, *log, "CAN", "speed", "t")
    speed = _load(root, *log, "CAN", "speed", "value").reshape(-1)
    fix = _load(root, *log, "GNSS", "live_gnss_ublox", "value")
    raw = _load(root, *log, "GNSS", "raw_gnss_ublox", "value")
    mag_path = root.joinpath(*log, "IMU", "magnetometer", "t")

    # GPS TOW of every sample; t = 0 at the first of them
    fix_utc = [pd.Timestamp(ms, unit="ms").to_pydatetime() for ms in fix[:, 3]]
    fix_gps = np.array([utc_to_gps(u)[1] + (utc_to_gps(u)[0] - week) * SECONDS_PER_WEEK
                        for u in fix_utc])
    raw_gps = raw[:, 2] + (raw[:, 1] - week) * SECONDS_PER_WEEK
    starts = [frame_t[0] + offset, imu_t[0] + offset, speed_t[0] + offset, fix_gps[0],
              raw_gps[0]]
    mag = None
    if mag_path.is_file():
        mag_t = _load(root, *log, "IMU", "magnetometer", "t")
        mag = (mag_t, _load(root, *log, "IMU", "magnetometer", "value"))
        starts.append(mag_t[0] + offset)
    tow0 = float(min(starts))

    def since_start(boot_t: np.ndarray) -> np.ndarray:
        return boot_t + offset - tow0

    streams: dict[str, pd.DataFrame] = {}
    streams["imu"] = pd.DataFrame({
        "t": since_start(imu_t), "gyro_x": gyro[:, 0], "gyro_y": gyro[:, 1],
        "gyro_z": gyro[:, 2], "accel_x": accel[:, 0], "accel_y": accel[:, 1],
        "accel_z": accel[:, 2]})
    streams["odometer"] = pd.DataFrame({"t": since_start(speed_t), "speed": speed})
    if mag is not None:
        streams["mag"] = pd.DataFrame({"t": since_start(mag[0]), "mag_x": mag[1][:, 0] * 1e-6,
                                       "mag_y": mag[1][:, 1] * 1e-6,
                                       "mag_z": mag[1][:, 2] * 1e-6})
    bearing = np.radians(fix[:, 5])
    nan = np.full(len(fix), np.nan)
    fixed = np.isfinite(fix[:, [0, 1, 4]]).all(axis=1)
    streams["gnss_fix"] = pd.DataFrame({
        "t": fix_gps - tow0, "lat": fix[:, 0], "lon": fix[:, 1], "alt": fix[:, 4],
        "vn": fix[:, 2] * np.cos(bearing), "ve": fix[:, 2] * np.sin(bearing), "vd": nan,
        "speed": fix[:, 2], "course": bearing, "num_sats": nan, "hdop": nan, "vdop": nan,
        "fix": np.where(fixed, 2, 0)})

    nmea_id = raw[:, 0].astype(int)
    glonass = nmea_id >= 65
    freq = np.where(glonass, GLONASS_G1_HZ + GLONASS_G1_STEP_HZ * np.nan_to_num(raw[:, 3]),
                    GPS_L1_HZ)
    rows = len(raw)
    unknown = np.full(rows, np.nan)
    gnss_raw = pd.DataFrame({
        "t": raw_gps - tow0, "sv": np.where(glonass, nmea_id - 64, nmea_id),
        "pseudorange": raw[:, 4], "pseudorange_rate": raw[:, 6],
        "doppler": -raw[:, 6] * freq / C_M_S, "cn0": raw[:, 8],
        **{c: unknown for c in ("sat_x", "sat_y", "sat_z", "sat_vx", "sat_vy", "sat_vz",
                                "sat_clock", "sat_clock_drift", "iono", "tropo", "elevation",
                                "azimuth")},
        "pseudorange_std": raw[:, 5], "pseudorange_rate_std": raw[:, 7],
        "system": np.where(glonass, "R", "G"), "signal": "1C", "frequency": freq,
        "carrier_phase": raw[:, 9]})
    streams["gnss_raw"] = gnss_raw.sort_values(["t", "system", "sv"], kind="stable")

    from scipy.spatial.transform import Rotation

    quat = _load(root, "global_pose", "frame_orientations")
    c_b_e = Rotation.from_quat(quat[:, [1, 2, 3, 0]]).as_matrix()
    streams["truth"] = reference_truth(
        since_start(frame_t), _load(root, "global_pose", "frame_positions"),
        _load(root, "global_pose", "frame_velocities"), c_b_e)

    utc0 = pd.Timestamp(fix[0, 3], unit="ms").to_pydatetime()
    sensors = {
        "imu": {"preset": "consumer", "rate": _median_rate(imu_t), "output": "rate"},
        "odometer": {"preset": "abs-wheel-speed", "rate": _median_rate(speed_t)},
        "gnss": {"preset": "automotive", "rate": _median_rate(fix_gps),
                 "outputs": ["fix", "raw"]},
    }
    if mag is not None:
        sensors["mag"] = {"preset": "automotive", "rate": _median_rate(mag[0])}
    return Recording(
        kind="comma2k19", sources=[str(root)], gps_week=week, gps_tow=tow0, streams=streams,
        reference="comma2k19 global_pose: comma.ai's tightly coupled INS/GNSS/vision pose "
                  "(20 Hz), body = the device's camera frame (FRD)",
        sensors=sensors,
        lacks={"gnss_raw": NOT_ON_RECORD},
        notes=[f"boot time + {offset:.6f} s = GPS time of week {week}",
               f"GPS - UTC = {leap_seconds(utc0)} s",
               "gyro: the phone's bias-calibrated output (IMU/gyro)",
               "gnss_fix vd unknown (NaN); num_sats, hdop, vdop not logged (NaN)",
               "sensor presets are the nearest landnav presets (consumer IMU, u-blox-class "
               "automotive receiver, ABS wheel speed), not the devices' own datasheets"])
