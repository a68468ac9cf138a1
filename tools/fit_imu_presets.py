"""Fit the ``bosch-bmi160`` and ``adis16448`` IMU presets to real static Allan-deviation curves.

Reads the imu_utils curves in ``shared/refdata/allan/imu_utils_real_imus/`` (2 h static logs;
gyro in deg/h with imu_utils' factor 57.3 * 3600, accelerometer in m/s^2) and fits, per axis:

* the white-noise density N, flicker bias instability B, random-walk density K and rate ramp R of
  ``simulator.stochastic.adev_model``, minimising the largest log misfit (from a least-squares
  start) over tau from 5 samples to a tenth of the record;
* on an axis that these four terms miss by more than ``MARKOV_WHEN`` (10 %) somewhere, also the
  exponentially correlated (Markov) bias of std sigma and correlation time T_c
  (``gauss_markov_sigma``, ``gauss_markov_correlation_time``: IEEE Std 952 Annex C, Markov
  noise), the six terms fitted the same way from several starting T_c. 10 % leaves room for the
  sampling error of a simulated curve (about 10 % at the longest tau compared) inside the 25 %
  the presets are held to; an axis the four terms already follow keeps the simpler model;
* the corner of the sensor's first-order output low-pass (``bandwidth``) from the one-sample
  point, where the filter lowers the white-noise Allan deviation by (1 - a) / sqrt(1 + a),
  a = exp(-2 pi f_c dt) (Allan variance of an AR(1) process at one sample).

A term whose Allan variance stays under 0.1 % of the real curve's over the fitted range is written
as 0. Prints the values to put in ``simulator/sensors/imu_presets.py`` and the largest misfit of
the fitted curve per axis.

Usage: ``PYTHONPATH=. python tools/fit_imu_presets.py``
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.optimize import brentq, least_squares, minimize

from simulator.stochastic import adev_model

DATA = Path(__file__).resolve().parents[2] / "shared" / "refdata" / "allan" / "imu_utils_real_imus"
IMU_UTILS_DEG_H = 57.3 * 3600.0  # imu_utils' rad/s -> deg/h factor
DEVICES = {"bosch-bmi160": "BMI160", "adis16448": "16448"}
NAMES = ("noise_density", "bias_instability", "random_walk", "ramp", "gauss_markov_sigma",
         "gauss_markov_correlation_time")
MARKOV_WHEN = 0.10  # largest relative misfit of the four-term fit above which T_c is fitted
MARKOV_STARTS_S = (3.0, 10.0, 30.0, 100.0, 300.0)  # starting correlation times, s
NEGLIGIBLE = 1e-3  # a term whose Allan variance stays below this share of the curve's is 0


def real_curve(device: str, group: str, axis: str) -> tuple[np.ndarray, np.ndarray]:
    """tau (s) and ADEV (rad/s or m/s^2) of one axis of one real unit."""
    tau = np.loadtxt(DATA / f"data_{device}_{group}_t.txt")
    adev = np.loadtxt(DATA / f"data_{device}_{group}_{axis}.txt")
    return tau, adev / IMU_UTILS_DEG_H if group == "gyr" else adev


def model(tau: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Allan deviation of the terms p = [N, B, K, R] or [N, B, K, R, sigma, T_c]."""
    markov = {"markov_sigma": p[4], "markov_time_s": p[5]} if len(p) > 4 else {}
    return adev_model(tau, *p[:4], **markov)


def _minimax(tau: np.ndarray, adev: np.ndarray, start: np.ndarray) -> np.ndarray:
    """Parameters minimising the largest |log(model / real)|, from a least-squares start."""

    def residual(log_p: np.ndarray) -> np.ndarray:
        return np.log(model(tau, np.exp(log_p))) - np.log(adev)

    least = least_squares(residual, np.log(start)).x
    return np.exp(minimize(lambda p: np.max(np.abs(residual(p))), least,
                           method="Nelder-Mead", options={"xatol": 1e-4, "fatol": 1e-6,
                                                          "maxiter": 1000 * len(start)}).x)


def _misfit(tau: np.ndarray, adev: np.ndarray, p: np.ndarray) -> float:
    return float(np.max(np.abs(model(tau, p) / adev - 1)))


def fit_axis(tau: np.ndarray, adev: np.ndarray) -> tuple[np.ndarray, float, float]:
    """([N, B, K, R, sigma, T_c], bandwidth in Hz, largest relative misfit) for one axis, over
    tau from 5 samples to a tenth of the record (twice the longest tau); sigma = T_c = 0 when
    the four-term model follows the curve within ``MARKOV_WHEN``."""
    use = (tau >= 4.5 * tau[0]) & (tau <= tau[-1] / 5)
    t, a = tau[use], adev[use]
    n0 = adev[np.argmin(np.abs(tau - 1.0))]
    params = _minimax(t, a, np.array([n0, a.min() / 0.664, n0 * 1e-3, n0 * 1e-5]))
    if _misfit(t, a, params) > MARKOV_WHEN:
        fits = [_minimax(t, a, np.array([n0, a.min() / 0.664 / 2, n0 * 1e-3, n0 * 1e-5,
                                         a.min(), start])) for start in MARKOV_STARTS_S]
        params = min(fits, key=lambda p: _misfit(t, a, p))
    else:
        params = np.concatenate([params, [0.0, 0.0]])
    # zero the terms that do not matter anywhere in the fitted range
    for i in (1, 2, 3, 4):
        alone = np.zeros(6)
        alone[i], alone[5] = params[i], params[5]
        if params[i] > 0 and np.all(model(t, alone) ** 2 < NEGLIGIBLE * a**2):
            params[i] = 0.0
    if params[4] == 0.0:
        params[5] = 0.0
    ratio = adev[0] / model(tau[:1], params)[0]
    f = brentq(lambda f: (1 - f) / np.sqrt(1 + f) - ratio, 0.0, 1.0 - 1e-9) if ratio < 1 else 0.0
    bandwidth = -np.log(f) / (2 * np.pi * tau[0]) if f > 0 else np.inf
    return params, bandwidth, _misfit(t, a, params)


def main() -> None:
    for preset, device in DEVICES.items():
        print(preset, "rate", round(1.0 / real_curve(device, "gyr", "x")[0][0], 2), "Hz")
        for group in ("gyr", "acc"):
            fits = [fit_axis(*real_curve(device, group, a)) for a in "xyz"]
            for i, name in enumerate(NAMES):
                if i < 4 or any(f[0][4] > 0 for f in fits):
                    print(f"  {group} {name}: [{', '.join(f'{f[0][i]:.3g}' for f in fits)}]")
            print(f"  {group} bandwidth: [{', '.join(f'{f[1]:.3g}' for f in fits)}]")
            print(f"  {group} largest misfit: [{', '.join(f'{f[2]:.1%}' for f in fits)}]")


if __name__ == "__main__":
    main()
