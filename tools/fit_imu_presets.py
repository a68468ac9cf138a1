"""Fit the ``bosch-bmi160`` and ``adis16448`` IMU presets to real static Allan-deviation curves.

Reads the imu_utils curves in ``shared/refdata/allan/imu_utils_real_imus/`` (2 h static logs;
gyro in deg/h with imu_utils' factor 57.3 * 3600, accelerometer in m/s^2) and fits, per axis:

* the white-noise density N, flicker bias instability B, random-walk density K and rate ramp R of
  ``simulator.sensors.noise.adev_model``, minimising the largest log misfit (from a least-squares
  start) over tau from 5 samples to a tenth of the record;
* the corner of the sensor's first-order output low-pass (``bandwidth``) from the one-sample
  point, where the filter lowers the white-noise Allan deviation by (1 - a) / sqrt(1 + a),
  a = exp(-2 pi f_c dt) (Allan variance of an AR(1) process at one sample).

Prints the values to put in ``simulator/sensors/imu_presets.py``.

Usage: ``PYTHONPATH=. python tools/fit_imu_presets.py``
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.optimize import brentq, least_squares, minimize

from simulator.sensors.noise import adev_model

DATA = Path(__file__).resolve().parents[2] / "shared" / "refdata" / "allan" / "imu_utils_real_imus"
IMU_UTILS_DEG_H = 57.3 * 3600.0  # imu_utils' rad/s -> deg/h factor
DEVICES = {"bosch-bmi160": "BMI160", "adis16448": "16448"}


def real_curve(device: str, group: str, axis: str) -> tuple[np.ndarray, np.ndarray]:
    """tau (s) and ADEV (rad/s or m/s^2) of one axis of one real unit."""
    tau = np.loadtxt(DATA / f"data_{device}_{group}_t.txt")
    adev = np.loadtxt(DATA / f"data_{device}_{group}_{axis}.txt")
    return tau, adev / IMU_UTILS_DEG_H if group == "gyr" else adev


def fit_axis(tau: np.ndarray, adev: np.ndarray) -> tuple[np.ndarray, float]:
    """([N, B, K, R], bandwidth in Hz) for one axis: least squares, then the largest log misfit
    minimised over tau from 5 samples to a tenth of the record (twice the longest tau)."""
    use = (tau >= 4.5 * tau[0]) & (tau <= tau[-1] / 5)

    def residual(log_p: np.ndarray) -> np.ndarray:
        return np.log(adev_model(tau[use], *np.exp(log_p))) - np.log(adev[use])

    n0 = adev[np.argmin(np.abs(tau - 1.0))]
    start = np.log([n0, adev.min() / 0.664, n0 * 1e-3, n0 * 1e-5])
    least = least_squares(residual, start).x
    params = np.exp(minimize(lambda p: np.max(np.abs(residual(p))), least,
                             method="Nelder-Mead", options={"xatol": 1e-4, "fatol": 1e-6,
                                                            "maxiter": 4000}).x)
    ratio = adev[0] / adev_model(tau[:1], *params)[0]
    a = brentq(lambda a: (1 - a) / np.sqrt(1 + a) - ratio, 0.0, 1.0 - 1e-9) if ratio < 1 else 0.0
    bandwidth = -np.log(a) / (2 * np.pi * tau[0]) if a > 0 else np.inf
    return params, bandwidth


def main() -> None:
    names = ("noise_density", "bias_instability", "random_walk", "ramp")
    for preset, device in DEVICES.items():
        print(preset, "rate", round(1.0 / real_curve(device, "gyr", "x")[0][0], 2), "Hz")
        for group in ("gyr", "acc"):
            fits = [fit_axis(*real_curve(device, group, a)) for a in "xyz"]
            for i, name in enumerate(names):
                print(f"  {group} {name}: [{', '.join(f'{f[0][i]:.3g}' for f in fits)}]")
            print(f"  {group} bandwidth: [{', '.join(f'{f[1]:.3g}' for f in fits)}]")


if __name__ == "__main__":
    main()
