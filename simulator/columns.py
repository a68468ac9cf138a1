"""Dataset column names and their units (SPEC section 5), defined once and imported everywhere.

Each stream is a mapping from column name to unit; the dataset writer stores the unit in the
Parquet field metadata. Extra columns a model adds must be declared here too.

Public names
------------
TRUTH, IMU, ODOMETER, GNSS_FIX, GNSS_RAW, GNSS_NAV_KEPLER, GNSS_NAV, BARO, MAG, EVENTS,
TRUTH_GNSS, STREAMS, IMU_AXES, SOLUTION, SOLUTION_STD, SOLUTION_NIS, SENSOR_ERRORS,
TRUTH_SENSORS, SOLUTION_FIX, DATASET_FORMAT, REQUIRED, TEXT_COLUMNS.
"""

from __future__ import annotations

DATASET_FORMAT = "landnav-dataset/1"

TRUTH = {
    "t": "s", "lat": "deg", "lon": "deg", "alt": "m",
    "vn": "m/s", "ve": "m/s", "vd": "m/s",
    "roll": "rad", "pitch": "rad", "yaw": "rad",
    "wx": "rad/s", "wy": "rad/s", "wz": "rad/s",
    "fx": "m/s^2", "fy": "m/s^2", "fz": "m/s^2",
    "speed": "m/s", "distance": "m", "zone": "",
}

IMU_AXES = ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")
IMU = {"t": "s", **{a: "rad/s" for a in IMU_AXES[:3]}, **{a: "m/s^2" for a in IMU_AXES[3:]}}
IMU_INCREMENT_UNITS = {**{a: "rad" for a in IMU_AXES[:3]}, **{a: "m/s" for a in IMU_AXES[3:]}}

ODOMETER = {"t": "s", "speed": "m/s", "ticks": "1", "direction": "1"}

GNSS_FIX = {
    "t": "s", "lat": "deg", "lon": "deg", "alt": "m",
    "vn": "m/s", "ve": "m/s", "vd": "m/s", "speed": "m/s", "course": "rad",
    "num_sats": "1", "hdop": "1", "vdop": "1", "fix": "1",
    # the receiver's clock solution: c dt_r and c d(dt_r)/dt
    "clock_bias": "m", "clock_drift": "m/s",
    # the receiver's own accuracy of the fix, 1-sigma per NED axis (as NMEA GST, UBX-NAV-COV):
    # what it knows of its error, not the error (simulator.gnss.fix)
    "std_n": "m", "std_e": "m", "std_d": "m", "std_vn": "m/s", "std_ve": "m/s", "std_vd": "m/s",
}

GNSS_RAW = {
    # system: the RINEX letter (G, E, C, R, J); sv is the PRN (GLONASS: slot) within it
    "t": "s", "sv": "1", "system": "", "pseudorange": "m", "pseudorange_rate": "m/s",
    "doppler": "Hz",
    "cn0": "dB-Hz", "sat_x": "m", "sat_y": "m", "sat_z": "m",
    "sat_vx": "m/s", "sat_vy": "m/s", "sat_vz": "m/s",
    "sat_clock": "m", "sat_clock_drift": "m/s", "iono": "m", "tropo": "m",
    "elevation": "rad", "azimuth": "rad",
    # the receiver's own 1-sigma estimates (as Android's ...UncertaintyMeters), for weighting
    "pseudorange_std": "m", "pseudorange_rate_std": "m/s",
    # the satellite's broadcast health (IS-GPS-200 20.3.3.3.1.4; YUMA: the almanac's 6-bit
    # code): 0 healthy; any other value is tracked and reported but not to be used
    "health": "1",
    # several signals (SPEC section 5): one row per satellite, signal and epoch
    "signal": "", "frequency": "Hz", "group_delay": "m",
    # carrier phase, RINEX sign (it grows with the range), the loss-of-lock indicator bits
    # (RINEX 3.04: 1 lost lock, 2 half-cycle ambiguity) and the time since the arc began
    "carrier_phase": "cycles", "lli": "1", "lock_time": "s",
}

# the true error terms of every signal above the horizon (tracked or not), so that
# pseudorange = range + receiver_clock - sat_clock + iono_true + tropo_true + sis_error
#               + multipath + nlos_delay + code_noise
# pseudorange_rate = range_rate + receiver_clock_drift - sat_clock_drift (1 - range_rate / c)
#               + tropo_true_rate - iono_true_rate + rate_noise
# (multipath and code_noise as the receiver delivers them, after its carrier smoothing;
# code_noise then holds the smoothing's ionosphere divergence too: simulator.gnss.errors)
TRUTH_GNSS = {
    "t": "s", "sv": "1", "system": "", "tracked": "1", "los": "1", "nlos": "1",
    "elevation": "rad", "azimuth": "rad", "range": "m", "range_rate": "m/s",
    "receiver_clock": "m", "receiver_clock_drift": "m/s",
    "iono_true": "m", "tropo_true": "m", "iono_true_rate": "m/s", "tropo_true_rate": "m/s",
    "sis_error": "m", "multipath": "m", "nlos_delay": "m", "code_noise": "m",
    "rate_noise": "m/s", "antenna_x": "m", "antenna_y": "m", "antenna_z": "m",
    "signal": "", "frequency": "Hz", "group_delay": "m",
    # carrier_phase lambda = range + receiver_clock - (sat_clock + group_delay) - iono_true
    #     + tropo_true + sis_error + carrier_multipath + nlos_delay + phase_noise
    #     + lambda (ambiguity + half_cycle)
    # (the arc's integer ambiguity, the half cycle still unresolved, the integer jump at the
    # epoch a cycle slip happens, the arc's number)
    "ambiguity": "cycles", "half_cycle": "cycles", "cycle_slip": "cycles", "arc": "1",
    "carrier_multipath": "m", "phase_noise": "m",
}

# broadcast Keplerian parameters (IS-GPS-200 Table 20-III); toe and toc in seconds of week
# ``week`` of the system's time (GPS; BDT for BeiDou; toc may fall just outside [0, 604800)
# when the clock epoch is in the adjacent week)
GNSS_NAV_KEPLER = {
    "sv": "1", "week": "1", "toe": "s", "toc": "s",
    "af0": "s", "af1": "s/s", "af2": "s/s^2", "tgd": "s", "iode": "1", "health": "1",
    "sqrt_a": "m^0.5", "e": "1", "i0": "rad", "omega0": "rad", "omega": "rad", "m0": "rad",
    "delta_n": "rad/s", "omega_dot": "rad/s", "idot": "rad/s",
    "cuc": "rad", "cus": "rad", "crc": "m", "crs": "m", "cic": "rad", "cis": "rad",
}
# every system's broadcast parameters: the Keplerian ones (GPS, QZSS, Galileo, BeiDou), the
# system letter, the second group delay (Galileo BGD E5b/E1, BeiDou TGD2), Galileo's data
# source, and GLONASS's state vector at t_b (PZ-90) with its frequency channel
# (simulator.gnss.navfiles says what each holds per system)
GNSS_NAV = {
    "system": "", **GNSS_NAV_KEPLER, "tgd2": "s", "data_source": "1",
    "glo_x": "m", "glo_y": "m", "glo_z": "m", "glo_vx": "m/s", "glo_vy": "m/s", "glo_vz": "m/s",
    "glo_ax": "m/s^2", "glo_ay": "m/s^2", "glo_az": "m/s^2", "glo_channel": "1",
}

BARO = {"t": "s", "pressure": "Pa", "altitude": "m"}
MAG = {"t": "s", "mag_x": "T", "mag_y": "T", "mag_z": "T"}
EVENTS = {"t_start": "s", "t_end": "s", "kind": "", "detail": ""}

SOLUTION = {
    "t": "s", "lat": "deg", "lon": "deg", "alt": "m", "vn": "m/s", "ve": "m/s", "vd": "m/s",
    "roll": "rad", "pitch": "rad", "yaw": "rad",
}
SOLUTION_STD = {
    "std_n": "m", "std_e": "m", "std_d": "m", "std_vn": "m/s", "std_ve": "m/s", "std_vd": "m/s",
    "std_roll": "rad", "std_pitch": "rad", "std_yaw": "rad",
}
# optional: the normalised innovation squared of the GNSS update applied at a row (v^T S^-1 v)
# and its degrees of freedom (the number of measurements); NaN on rows without an update
SOLUTION_NIS = {"nis_gnss": "1", "nis_gnss_dof": "1"}
# the integer-ambiguity status of a relative (RTK) solution: 0 none, 1 float, 2 fixed
SOLUTION_FIX = {"fix_status": "1"}

# estimated sensor errors (SPEC section 7), the same names in a solution and in
# truth_sensors.parquet: IMU errors on the unit's own axes (FRD), measured minus true; scale
# factors are the dimensionless error (0 = perfect); the odometer scale factor is the ratio of
# measured to true speed (1 = perfect); the receiver clock bias c dt_r and drift c d(dt_r)/dt
SENSOR_ERRORS = {
    **{f"gyro_bias_{a}": "rad/s" for a in "xyz"},
    **{f"accel_bias_{a}": "m/s^2" for a in "xyz"},
    **{f"gyro_scale_factor_{a}": "1" for a in "xyz"},
    **{f"accel_scale_factor_{a}": "1" for a in "xyz"},
    "odometer_scale_factor": "1", "clock_bias": "m", "clock_drift": "m/s",
}
TRUTH_SENSORS = {"t": "s", **SENSOR_ERRORS}

# stream name -> (file name, columns); files whose name starts with "truth" and events.parquet
# are for scoring only and never reach an estimator.
STREAMS = {
    "truth": ("truth.parquet", TRUTH),
    "imu": ("imu.parquet", IMU),
    "odometer": ("odometer.parquet", ODOMETER),
    "gnss_fix": ("gnss_fix.parquet", GNSS_FIX),
    "gnss_raw": ("gnss_raw.parquet", GNSS_RAW),
    "gnss_nav": ("gnss_nav.parquet", GNSS_NAV),
    "baro": ("baro.parquet", BARO),
    "mag": ("mag.parquet", MAG),
    "events": ("events.parquet", EVENTS),
    "truth_gnss": ("truth_gnss.parquet", TRUTH_GNSS),
    "gnss_base_raw": ("gnss_base_raw.parquet", GNSS_RAW),
    "truth_gnss_base": ("truth_gnss_base.parquet", TRUTH_GNSS),
    "truth_sensors": ("truth_sensors.parquet", TRUTH_SENSORS),
}
SCORING_ONLY = ("truth", "truth_gnss", "truth_gnss_base", "truth_sensors", "events")

# the columns a stream must have (SPEC section 5); an IMU needs ``t`` and at least one axis
REQUIRED = {
    "truth": ("t", "lat", "lon", "alt", "vn", "ve", "vd", "roll", "pitch", "yaw", "wx", "wy",
              "wz", "fx", "fy", "fz", "speed", "distance", "zone"),
    "imu": ("t",),
    "odometer": ("t", "speed"),
    "gnss_fix": ("t", "lat", "lon", "alt", "vn", "ve", "vd", "speed", "course", "num_sats",
                 "hdop", "vdop", "fix"),
    "gnss_raw": ("t", "sv", "pseudorange", "pseudorange_rate", "doppler", "cn0", "sat_x",
                 "sat_y", "sat_z", "sat_vx", "sat_vy", "sat_vz", "sat_clock", "sat_clock_drift",
                 "iono", "tropo", "elevation", "azimuth"),
    "gnss_nav": tuple(GNSS_NAV_KEPLER),
    "baro": ("t", "pressure"),
    "mag": ("t", "mag_x", "mag_y", "mag_z"),
    "events": tuple(EVENTS),
    "truth_gnss": ("t", "sv"),
    "gnss_base_raw": ("t", "sv", "pseudorange", "pseudorange_rate", "doppler", "cn0"),
    "truth_gnss_base": ("t", "sv"),
    "truth_sensors": ("t",),
}
# where a position (latitude and longitude in degrees, ellipsoidal height in metres) can lie:
# anything else in a truth or a solution is a unit or format mistake, or no land vehicle's
POSITION_SPANS = {"lat": (-90.0, 90.0), "lon": (-180.0, 360.0), "alt": (-1e5, 1e5)}
# every other column of a stream is numeric
TEXT_COLUMNS = ("zone", "kind", "detail", "system", "signal")
