"""Named IMU parameter sets (``sensors.imu.preset``), written as the data sheets print them.

Each preset gives values for the ``gyro`` and ``accel`` groups (SPEC section 4 names) and may set
the unit's ``rate`` and ``output``. The schema converts the unit strings to SI when it merges a
preset into the resolved scenario; keys a preset leaves out are zero (error off). Every "+-" data
sheet bound is used as the 1-sigma value (conservative). A value given as a list of three is per
axis (x, y, z).

Sources
-------
- ``bosch-smi130``: Park et al., "MEMS 3D DR/GPS Integrated System for Land Vehicle Application
  Robust to GPS Outages", IEEE Access 2019, Table 1 (zero-point offset, temperature coefficient,
  RMS noise, 20 Hz). The table gives no bias instability, scale factor, misalignment or range:
  those are the ``automotive`` values below.
- ``crossbow-imu300cc``, ``honeywell-hg1700``: Karamat et al., "Novel EKF-based vision/inertial
  system integration ..." (3D RISS/GPS), Sensors 2015, Table 1 (range, bias, scale factor, random
  walk, max data rate). The gyro range and the IMU300CC gyro bias are images missing from our copy
  of the table; they are the manufacturers' data sheet values (Crossbow IMU300CC: 100 deg/s,
  2 deg/s; Honeywell HG1700 AG17: 1000 deg/s).
- ``crossbow-dmu300cc``: the unit of Cho & Choi, ETRI J. 2006 (10 Hz dead reckoning). The paper
  prints no specification; the DMU300CC is the same Crossbow 300CC family as the IMU300CC, so its
  values are those of Karamat 2015 Table 1 for the IMU300CC, at Cho's 10 Hz.
- ``bp3010``: Tan et al. 2008: three ADXRS300 gyros and three ADXL210E accelerometers, increments at
  64 Hz. Noise density and range from the Analog Devices ADXRS300 (0.1 deg/s/sqrt(Hz), 300 deg/s)
  and ADXL210E (200 ug/sqrt(Hz), 10 g) data sheets; bias and scale factor of the calibrated unit
  are assumed (0.5 deg/s, 10 mg, 0.5 %).
- ``bosch-bmi160``, ``adis16448``: fitted to the 2 h static Allan-deviation curves of real units
  (imu_utils data, ``shared/refdata/allan/imu_utils_real_imus/``) by ``tools/fit_imu_presets.py``:
  per-axis white noise, flicker bias instability, random walk, rate ramp and output bandwidth.
  Only the noise terms are fitted: the static curves say nothing about turn-on bias or scale
  factor, which are left at zero (override them in the scenario).
- ``consumer``, ``automotive``, ``tactical``, ``navigation``: representative values inside the
  grade ranges of Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
  Systems*, 2nd ed., 2013, section 4.4 (Tables 4.1 and 4.2).
- ``ideal``: every error off; the output is the exact truth.

Public names
------------
IMU_PRESETS.
"""

from __future__ import annotations

_AUTOMOTIVE = {
    "gyro": {"bias": "0.2 deg/s", "bias_instability": "10 deg/h",
             "noise_density": "0.005 deg/s/sqrt(Hz)", "random_walk": "1e-4 deg/s^2/sqrt(Hz)",
             "scale_factor": "0.5 %", "misalignment": "1 mrad", "range": "250 deg/s",
             "resolution": "0.01 deg/s", "temperature_coefficient": "0.005 deg/s/K",
             "g_sensitivity": "0.05 deg/s/g"},
    "accel": {"bias": "10 mg", "bias_instability": "0.05 mg",
              "noise_density": "0.1 mg/sqrt(Hz)", "random_walk": "1e-3 mg/s/sqrt(Hz)",
              "scale_factor": "0.3 %", "misalignment": "1 mrad", "range": "8 g",
              "resolution": "0.25 mg", "temperature_coefficient": "0.2 mg/K"},
}

IMU_PRESETS: dict[str, dict] = {
    "ideal": {},
    "consumer": {
        "gyro": {"bias": "1 deg/s", "bias_instability": "12 deg/h",
                 "noise_density": "0.007 deg/s/sqrt(Hz)", "random_walk": "2e-4 deg/s^2/sqrt(Hz)",
                 "scale_factor": "1 %", "misalignment": "5 mrad", "range": "500 deg/s",
                 "resolution": "0.015 deg/s", "temperature_coefficient": "0.015 deg/s/K",
                 "g_sensitivity": "0.1 deg/s/g"},
        "accel": {"bias": "40 mg", "bias_instability": "0.1 mg",
                  "noise_density": "0.2 mg/sqrt(Hz)", "random_walk": "4e-3 mg/s/sqrt(Hz)",
                  "scale_factor": "1 %", "misalignment": "5 mrad", "range": "16 g",
                  "resolution": "0.5 mg", "temperature_coefficient": "1 mg/K"},
    },
    "automotive": _AUTOMOTIVE,
    "tactical": {
        "gyro": {"bias": "1 deg/h", "bias_instability": "0.3 deg/h",
                 "noise_density": "0.1 deg/sqrt(h)", "random_walk": "1e-6 deg/s^2/sqrt(Hz)",
                 "scale_factor": "150 ppm", "misalignment": "0.1 mrad", "range": "1000 deg/s",
                 "g_sensitivity": "1 deg/h/g"},
        "accel": {"bias": "1 mg", "bias_instability": "0.05 mg",
                  "noise_density": "0.03 m/s/sqrt(h)", "random_walk": "1e-4 mg/s/sqrt(Hz)",
                  "scale_factor": "300 ppm", "misalignment": "0.1 mrad", "range": "50 g"},
    },
    "navigation": {
        "gyro": {"bias": "0.01 deg/h", "bias_instability": "0.003 deg/h",
                 "noise_density": "0.002 deg/sqrt(h)", "scale_factor": "5 ppm",
                 "misalignment": "0.02 mrad", "range": "500 deg/s"},
        "accel": {"bias": "0.03 mg", "bias_instability": "0.01 mg",
                  "noise_density": "0.02 mg/sqrt(Hz)", "scale_factor": "50 ppm",
                  "misalignment": "0.02 mrad", "range": "30 g"},
    },
    "bosch-smi130": {
        "rate": 20.0,
        "gyro": {**_AUTOMOTIVE["gyro"], "bias": "1 deg/s",
                 "temperature_coefficient": "0.015 deg/s/K",
                 "noise_density": "0.02 deg/s/sqrt(Hz)"},
        "accel": {**_AUTOMOTIVE["accel"], "bias": "70 mg", "temperature_coefficient": "1 mg/K",
                  "noise_density": "0.19 mg/sqrt(Hz)"},
    },
    "crossbow-imu300cc": {
        "rate": 200.0,
        "gyro": {"bias": "2 deg/s", "scale_factor": "1 %", "noise_density": "2.25 deg/sqrt(h)",
                 "range": "100 deg/s"},
        "accel": {"bias": "30 mg", "scale_factor": "1 %", "noise_density": "0.15 m/s/sqrt(h)",
                  "range": "2 g"},
    },
    "crossbow-dmu300cc": {
        "rate": 10.0,
        "gyro": {"bias": "2 deg/s", "scale_factor": "1 %", "noise_density": "2.25 deg/sqrt(h)",
                 "range": "100 deg/s"},
        "accel": {"bias": "30 mg", "scale_factor": "1 %", "noise_density": "0.15 m/s/sqrt(h)",
                  "range": "2 g"},
    },
    "honeywell-hg1700": {
        "rate": 100.0,
        "gyro": {"bias": "1 deg/h", "scale_factor": "150 ppm",
                 "noise_density": "0.125 deg/sqrt(h)", "range": "1000 deg/s"},
        "accel": {"bias": "1 mg", "scale_factor": "300 ppm", "noise_density": "0.198 m/s/sqrt(h)",
                  "range": "50 g"},
    },
    "bp3010": {
        "rate": 64.0,
        "output": "increment",
        "gyro": {"bias": "0.5 deg/s", "scale_factor": "0.5 %",
                 "noise_density": "0.1 deg/s/sqrt(Hz)", "range": "300 deg/s"},
        "accel": {"bias": "10 mg", "scale_factor": "0.5 %", "noise_density": "0.2 mg/sqrt(Hz)",
                  "range": "10 g"},
    },
    # fitted by tools/fit_imu_presets.py (SI units, per axis x, y, z)
    "bosch-bmi160": {
        "rate": 200.0,
        "gyro": {"noise_density": [8.44e-05, 7.6e-05, 7.96e-05],
                 "bias_instability": [5.68e-05, 2.77e-05, 1.85e-05],
                 "random_walk": [2.84e-06, 5.92e-07, 2.98e-06],
                 "ramp": [5.1e-08, 6.79e-08, 3.2e-08],
                 "bandwidth": [65.6, 56.9, 58.5]},
        "accel": {"noise_density": [0.00133, 0.00111, 0.00175],
                  "bias_instability": [0.000302, 0.000766, 0.000809],
                  "random_walk": [6.34e-05, 2.22e-06, 0.0],
                  "ramp": [4.06e-06, 3.07e-06, 1.37e-06],
                  "bandwidth": [79.5, 60.0, 53.2]},
    },
    "adis16448": {
        "rate": 200.0,
        "gyro": {"noise_density": [0.000159, 0.000162, 0.000159],
                 "bias_instability": [0.000119, 8.64e-05, 0.000104],
                 "random_walk": [8.23e-06, 1.41e-05, 7.44e-06],
                 "ramp": [0.0, 0.0, 3.39e-07],
                 "bandwidth": [59.5, 58.1, 63.6]},
        "accel": {"noise_density": [0.00162, 0.00141, 0.0015],
                  "bias_instability": [0.00122, 0.00291, 0.00102],
                  "random_walk": [0.00015, 0.000318, 0.000146],
                  "ramp": [5.9e-07, 0.0, 0.0],
                  "bandwidth": [65.5, 158.0, 62.3]},
    },
}
