"""Named IMU parameter sets (``sensors.imu.preset``), written as the data sheets print them.

Each preset gives values for the ``gyro`` and ``accel`` groups (SPEC section 4 names) and may set
the unit's ``rate`` and ``output``. Values are SI, written as datasheet number times unit factor
(``simulator.units``: ``0.02 * DEG_S_RT_HZ`` is 0.02 deg/s/sqrt(Hz)); temperature coefficients
are per kelvin, g-sensitivities per g (``/ G0_M_S2``), ranges in g as ``8 * G0_M_S2``. Keys a
preset leaves out are zero (off). Every "+-" data sheet bound is used as the 1-sigma value
(conservative). A value given as a list of three is per
axis (x, y, z).

Sources
-------
- ``bosch-smi130``: Park et al., "MEMS 3D DR/GPS Integrated System for Land Vehicle Application
  Robust to GPS Outages", IEEE Access 2019, Table 1 (zero-point offset, temperature coefficient,
  RMS noise, 20 Hz). The table gives no bias instability, scale factor, misalignment or range:
  those are the ``automotive`` values below. ``bosch-smi130-calibrated``: the same with Park's
  initially calibrated accelerometer bias, 10 % of the 70 mg offset (section III-B).
- ``crossbow-imu300cc``, ``honeywell-hg1700``: Karamat et al., "Novel EKF-based vision/inertial
  system integration ..." (3D RISS/GPS), Sensors 2015, Table 1 (range, bias, scale factor, random
  walk, max data rate). The gyro range and the IMU300CC gyro bias are images missing from our copy
  of the table; they are the manufacturers' data sheet values (Crossbow IMU300CC: 100 deg/s,
  2 deg/s; Honeywell HG1700 AG17: 1000 deg/s).
- ``crossbow-dmu300cc`` (``-gm``: with the in-run Gauss-Markov bias of ``crossbow-imu300cc-gm``):
  the unit of Cho & Choi, ETRI J. 2006 (10 Hz dead reckoning). The paper
  prints no specification; the DMU300CC is the same Crossbow 300CC family as the IMU300CC, so its
  values are those of Karamat 2015 Table 1 for the IMU300CC, at Cho's 10 Hz.
- ``bp3010``: Tan et al. 2008: three ADXRS300 gyros and three ADXL210E accelerometers, increments at
  64 Hz. Noise density and range from the Analog Devices ADXRS300 (0.1 deg/s/sqrt(Hz), 300 deg/s)
  and ADXL210E (200 ug/sqrt(Hz), 10 g) data sheets; bias and scale factor of the calibrated unit
  are assumed (0.5 deg/s, 10 mg, 0.5 %).
- ``bosch-bmi160``, ``adis16448``: fitted to the 2 h static Allan-deviation curves of real units
  (imu_utils data, ``shared/refdata/allan/imu_utils_real_imus/``) by ``tools/fit_imu_presets.py``:
  per-axis white noise, flicker bias instability, random walk, rate ramp and output bandwidth,
  plus a Gauss-Markov bias (``gauss_markov_sigma``, ``gauss_markov_correlation_time``) on the two
  axes these terms miss by more than 10 %: the ADIS16448 y accelerometer (its curve climbs from
  2 s to a plateau at 100-300 s; four terms: 28 % off; with sigma 4.52e-3 m/s^2, T_c 34.3 s:
  2.1 %) and the BMI160 z accelerometer (16 %; with 9.85e-4 m/s^2, 8.23 s: 8.5 %).
  Only the noise terms are fitted: the static curves say nothing about turn-on bias or scale
  factor, which are left at zero (override them in the scenario).

  Largest misfit per axis (x, y, z), analytic fit over tau from 5 samples to 524 s (ADIS16448) or
  1068 s (BMI160) / simulated curve against the real one in ``tests/sensors/test_imu_allan.py``
  (one 40 min record, tau up to 40 s; ``--runslow``: four records of twice the longest real tau,
  tau up to a tenth of them); the presets are held to 25 %:

  ============  ==========================  ====================  ======================
  unit, group   analytic fit                simulated, 40 s       simulated, full length
  ============  ==========================  ====================  ======================
  BMI160 gyro   4.5 %, 2.2 %, 2.3 %         13 %, 11 %, 10 %      17 %, 10 %, 20 %
  BMI160 accel  3.5 %, 6.0 %, 8.5 %         11 %, 8 %, 11 %       15 %, 6 %, 13 %
  ADIS gyro     6.3 %, 5.3 %, 7.1 %         9 %, 12 %, 13 %       14 %, 21 %, 13 %
  ADIS accel    9.7 %, 2.1 %, 5.7 %         14 %, 6 %, 8 %        11 %, 12 %, 14 %
  ============  ==========================  ====================  ======================
- ``consumer``, ``automotive``, ``tactical``, ``navigation``: representative values inside the
  grade ranges of Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
  Systems*, 2nd ed., 2013, section 4.4 (Tables 4.1 and 4.2).
- ``ideal``: every error off; the output is the exact truth.

Public names
------------
IMU_PRESETS.
"""

from __future__ import annotations

from simulator.earth import G0_M_S2
from simulator.units import (
    DEG_H,
    DEG_RT_H,
    DEG_S,
    DEG_S2_RT_HZ,
    DEG_S_RT_HZ,
    M_S_RT_H,
    MILLI,
    MILLI_G,
    MILLI_G_RT_HZ,
    MILLI_G_S_RT_HZ,
    PERCENT,
    PPM,
)

_AUTOMOTIVE = {
    "gyro": {"bias": 0.2 * DEG_S, "bias_instability": 10 * DEG_H,
             "noise_density": 0.005 * DEG_S_RT_HZ, "random_walk": 1e-4 * DEG_S2_RT_HZ,
             "scale_factor": 0.5 * PERCENT, "misalignment": 1 * MILLI, "range": 250 * DEG_S,
             "resolution": 0.01 * DEG_S, "temperature_coefficient": 0.005 * DEG_S,
             "g_sensitivity": 0.05 * DEG_S / G0_M_S2},
    "accel": {"bias": 10 * MILLI_G, "bias_instability": 0.05 * MILLI_G,
              "noise_density": 0.1 * MILLI_G_RT_HZ, "random_walk": 1e-3 * MILLI_G_S_RT_HZ,
              "scale_factor": 0.3 * PERCENT, "misalignment": 1 * MILLI, "range": 8 * G0_M_S2,
              "resolution": 0.25 * MILLI_G, "temperature_coefficient": 0.2 * MILLI_G},
}

IMU_PRESETS: dict[str, dict] = {
    "ideal": {},
    "consumer": {
        "gyro": {"bias": 1 * DEG_S, "bias_instability": 15 * DEG_H,
                 "noise_density": 0.007 * DEG_S_RT_HZ, "random_walk": 1e-4 * DEG_S2_RT_HZ,
                 "scale_factor": 1 * PERCENT, "misalignment": 5 * MILLI, "range": 500 * DEG_S,
                 "resolution": 0.015 * DEG_S, "temperature_coefficient": 0.015 * DEG_S,
                 "g_sensitivity": 0.1 * DEG_S / G0_M_S2},
        "accel": {"bias": 40 * MILLI_G, "bias_instability": 0.1 * MILLI_G,
                  "noise_density": 0.2 * MILLI_G_RT_HZ, "random_walk": 4e-3 * MILLI_G_S_RT_HZ,
                  "scale_factor": 1 * PERCENT, "misalignment": 5 * MILLI, "range": 16 * G0_M_S2,
                  "resolution": 0.5 * MILLI_G, "temperature_coefficient": 1 * MILLI_G},
    },
    "automotive": _AUTOMOTIVE,
    "tactical": {
        "gyro": {"bias": 1 * DEG_H, "bias_instability": 0.3 * DEG_H,
                 "noise_density": 0.1 * DEG_RT_H, "random_walk": 1e-6 * DEG_S2_RT_HZ,
                 "scale_factor": 150 * PPM, "misalignment": 0.1 * MILLI, "range": 1000 * DEG_S,
                 "g_sensitivity": 1 * DEG_H / G0_M_S2},
        "accel": {"bias": 1 * MILLI_G, "bias_instability": 0.05 * MILLI_G,
                  "noise_density": 0.03 * M_S_RT_H, "random_walk": 1e-4 * MILLI_G_S_RT_HZ,
                  "scale_factor": 300 * PPM, "misalignment": 0.1 * MILLI, "range": 50 * G0_M_S2},
    },
    "navigation": {
        "gyro": {"bias": 0.01 * DEG_H, "bias_instability": 0.003 * DEG_H,
                 "noise_density": 0.002 * DEG_RT_H, "scale_factor": 5 * PPM,
                 "misalignment": 0.02 * MILLI, "range": 500 * DEG_S},
        "accel": {"bias": 0.03 * MILLI_G, "bias_instability": 0.01 * MILLI_G,
                  "noise_density": 0.02 * MILLI_G_RT_HZ, "scale_factor": 50 * PPM,
                  "misalignment": 0.02 * MILLI, "range": 30 * G0_M_S2},
    },
    "bosch-smi130": {
        "rate": 20.0,
        "gyro": {**_AUTOMOTIVE["gyro"], "bias": 1 * DEG_S,
                 "temperature_coefficient": 0.015 * DEG_S,
                 "noise_density": 0.02 * DEG_S_RT_HZ},
        "accel": {**_AUTOMOTIVE["accel"], "bias": 70 * MILLI_G,
                  "temperature_coefficient": 1 * MILLI_G, "noise_density": 0.19 * MILLI_G_RT_HZ},
    },
    "crossbow-imu300cc": {
        "rate": 200.0,
        "gyro": {"bias": 2 * DEG_S, "scale_factor": 1 * PERCENT, "noise_density": 2.25 * DEG_RT_H,
                 "range": 100 * DEG_S},
        "accel": {"bias": 30 * MILLI_G, "scale_factor": 1 * PERCENT,
                  "noise_density": 0.15 * M_S_RT_H, "range": 2 * G0_M_S2},
    },
    "honeywell-hg1700": {
        "rate": 100.0,
        "gyro": {"bias": 1 * DEG_H, "scale_factor": 150 * PPM,
                 "noise_density": 0.125 * DEG_RT_H, "range": 1000 * DEG_S},
        "accel": {"bias": 1 * MILLI_G, "scale_factor": 300 * PPM,
                  "noise_density": 0.198 * M_S_RT_H, "range": 50 * G0_M_S2},
    },
    "bp3010": {
        "rate": 64.0,
        "output": "increment",
        "gyro": {"bias": 0.5 * DEG_S, "scale_factor": 0.5 * PERCENT,
                 "noise_density": 0.1 * DEG_S_RT_HZ, "range": 300 * DEG_S},
        "accel": {"bias": 10 * MILLI_G, "scale_factor": 0.5 * PERCENT,
                  "noise_density": 0.2 * MILLI_G_RT_HZ, "range": 10 * G0_M_S2},
    },
    # fitted by tools/fit_imu_presets.py (SI units, per axis x, y, z)
    "bosch-bmi160": {
        "rate": 200.0,
        "gyro": {"noise_density": [8.44e-05, 7.6e-05, 7.96e-05],
                 "bias_instability": [5.68e-05, 2.77e-05, 1.85e-05],
                 "random_walk": [2.84e-06, 5.92e-07, 2.98e-06],
                 "ramp": [5.1e-08, 6.79e-08, 3.2e-08],
                 "bandwidth": [65.6, 56.9, 58.5]},
        "accel": {"noise_density": [0.00133, 0.00111, 0.00155],
                  "bias_instability": [0.000302, 0.000766, 0.000623],
                  "random_walk": [6.34e-05, 0.0, 0.0],
                  "ramp": [4.06e-06, 3.07e-06, 1.55e-06],
                  "gauss_markov_sigma": [0.0, 0.0, 0.000985],
                  "gauss_markov_correlation_time": [0.0, 0.0, 8.23],
                  "bandwidth": [79.5, 60.0, 69.9]},
    },
    "adis16448": {
        "rate": 200.0,
        "gyro": {"noise_density": [0.000159, 0.000162, 0.000159],
                 "bias_instability": [0.000119, 8.64e-05, 0.000104],
                 "random_walk": [8.23e-06, 1.41e-05, 7.44e-06],
                 "ramp": [0.0, 0.0, 3.39e-07],
                 "bandwidth": [59.5, 58.1, 63.6]},
        "accel": {"noise_density": [0.00162, 0.0018, 0.0015],
                  "bias_instability": [0.00122, 0.00111, 0.00102],
                  "random_walk": [0.00015, 0.000233, 0.000146],
                  "ramp": [5.9e-07, 4.28e-07, 0.0],
                  "gauss_markov_sigma": [0.0, 0.00452, 0.0],
                  "gauss_markov_correlation_time": [0.0, 34.3, 0.0],
                  "bandwidth": [65.5, 57.4, 62.3]},
    },
}
# the same Crossbow 300CC-family sensors as the IMU300CC, sampled at Cho & Choi's 10 Hz
IMU_PRESETS["crossbow-dmu300cc"] = {**IMU_PRESETS["crossbow-imu300cc"], "rate": 10.0}
# Park et al. 2019 section III-B: the SMI130 accelerometer bias "is initially corrected, and so
# that residual bias of less than 10 % has remained" [46]: 7 mg of Table 1's 70 mg zero-point
# offset; everything else as ``bosch-smi130`` (the gyro bias is left for the filter to estimate)
IMU_PRESETS["bosch-smi130-calibrated"] = {
    **IMU_PRESETS["bosch-smi130"],
    "accel": {**IMU_PRESETS["bosch-smi130"]["accel"], "bias": 7 * MILLI_G},
}
# Karamat et al. 2015 (Table 1, the IMU300CC) with an in-run first-order Gauss-Markov bias beside
# the turn-on bias: Table 1 prints none, so 1 % of the gyro's and 3 % of the accelerometers'
# turn-on bias, correlation time 300 s (assumed; docs/reproduction_karamat2015.md). Use it with
# ``axes: riss3d`` for the paper's reduced unit (vertical gyro, forward and lateral accelerometers)
IMU_PRESETS["crossbow-imu300cc-gm"] = {
    **IMU_PRESETS["crossbow-imu300cc"],
    "gyro": {**IMU_PRESETS["crossbow-imu300cc"]["gyro"],
             "gauss_markov_sigma": 0.02 * DEG_S, "gauss_markov_correlation_time": 300.0},
    "accel": {**IMU_PRESETS["crossbow-imu300cc"]["accel"],
              "gauss_markov_sigma": 1 * MILLI_G, "gauss_markov_correlation_time": 300.0},
}
# Cho & Choi's DMU300CC with the same in-run Gauss-Markov bias, at their 10 Hz (the paper's own
# scenarios use ``crossbow-dmu300cc``: its filters calibrate the gyro bias at standstill and have
# no bias state, so the in-run bias is the test of that choice)
IMU_PRESETS["crossbow-dmu300cc-gm"] = {**IMU_PRESETS["crossbow-imu300cc-gm"], "rate": 10.0}
