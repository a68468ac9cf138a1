"""Two datasets' streams side by side: a real recording and its twin (SPEC section 3,
``landnav compare``). Each statistic is computed the same way on both, against each dataset's
own reference or truth, and reported with the ratio second / first.

Statistics (each only where both datasets have the streams it needs):

* IMU noise and vibration while driving (speed over ``MOVING_M_S``): per sensor group the
  Welch power spectral density of each axis with its mean removed, summarised by the RMS in
  the bands 0.5-5 Hz (the body's motion) and 5 Hz to Nyquist (vibration and sensor noise).
* Odometer: the speed minus the reference's speed at the same times (mean, the scale error,
  and standard deviation) while moving.
* GNSS: satellites tracked per epoch (median), C/N0 (10th, 50th, 90th percentile; and by
  elevation band where both have elevations), the fixes' horizontal error against the
  reference (50th and 95th percentile).
* The same estimator's horizontal RMS error on both (``estimator``, when both datasets have its
  streams).

``LIKELY_CAUSE`` names, for each statistic, what in the simulator or in the recording decides
it, so that the report can name the largest mismatches with a cause to look at first.

Public names
------------
compare_datasets, write_comparison, LIKELY_CAUSE.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from simulator.dataset.io import Dataset

MOVING_M_S = 3.0
BANDS_HZ = ((0.5, 5.0), (5.0, None))
ELEVATION_BANDS_DEG = ((0, 15), (15, 30), (30, 60), (60, 90))

LIKELY_CAUSE = {
    "imu": "the IMU preset's noise density, and the car body's road and engine vibration "
           "(sensors.imu.vibration, the vehicle preset) against the real car and mounting",
    "odometer": "the odometer preset's scale factor and resolution, and the real car's wheel "
                "radius and CAN quantisation",
    "satellites": "the sky (the day's constellation against the default almanac, masks and "
                  "blockage by the surroundings, which the twin does not have)",
    "cn0": "the receiver preset's C/N0 model (zenith and horizon C/N0, fading) against the "
           "real antenna and its installation",
    "fix": "the receiver preset's error budget (signal in space, ionosphere residual, "
           "multipath, smoothing) against the real receiver and environment",
    "estimator": "everything above, through the estimator's tuning from the datasheet",
}


def _moving_times(dataset: Dataset) -> tuple[np.ndarray, np.ndarray]:
    truth = dataset.read("truth")
    return truth["t"].to_numpy(float), truth["speed"].to_numpy(float)


def _band_rms(signal: np.ndarray, rate_hz: float) -> tuple[np.ndarray, np.ndarray, list[float]]:
    from scipy.signal import welch

    freq, psd = welch(signal - signal.mean(), fs=rate_hz, nperseg=min(len(signal), 256))
    out = []
    for low, high in BANDS_HZ:
        top = freq[-1] if high is None else high
        sel = (freq >= low) & (freq <= top)
        out.append(float(math.sqrt(np.trapezoid(psd[sel], freq[sel]))) if sel.sum() > 1
                   else math.nan)
    return freq, psd, out


def _imu(dataset: Dataset) -> dict[str, Any]:
    imu = dataset.read("imu")
    t_ref, speed = _moving_times(dataset)
    t = imu["t"].to_numpy(float)
    moving = np.interp(t, t_ref, speed) > MOVING_M_S
    rate = float((len(t) - 1) / (t[-1] - t[0]))
    out: dict[str, Any] = {"psd": {}}
    for group, axes in (("gyro", ("gyro_x", "gyro_y", "gyro_z")),
                        ("accel", ("accel_x", "accel_y", "accel_z"))):
        bands = []
        for axis in axes:
            if axis not in imu or moving.sum() < 64:
                continue
            freq, psd, rms = _band_rms(imu[axis].to_numpy(float)[moving], rate)
            out["psd"][axis] = (freq, psd)
            bands.append(rms)
        if bands:
            arr = np.array(bands)
            for i, (low, high) in enumerate(BANDS_HZ):
                label = f"{low:g}-{high:g} Hz" if high else f"{low:g} Hz-Nyquist"
                out[f"imu.{group}_rms_{label}"] = float(np.sqrt(np.mean(arr[:, i] ** 2)))
    return out


def _odometer(dataset: Dataset) -> dict[str, float]:
    odo = dataset.read("odometer")
    t_ref, speed = _moving_times(dataset)
    t = odo["t"].to_numpy(float)
    ref = np.interp(t, t_ref, speed)
    moving = ref > MOVING_M_S
    err = odo["speed"].to_numpy(float)[moving] - ref[moving]
    return {"odometer.speed_error_mean_m_s": float(np.mean(err)),
            "odometer.speed_error_std_m_s": float(np.std(err))}


def _gnss(dataset: Dataset) -> dict[str, Any]:
    out: dict[str, Any] = {}
    if dataset.has("gnss_raw"):
        raw = dataset.read("gnss_raw")
        key = raw["system"].astype(str) + raw["sv"].astype(str) if "system" in raw else raw["sv"]
        per_epoch = pd.Series(key.to_numpy()).groupby(raw["t"].to_numpy()).nunique()
        out["gnss.satellites_per_epoch_median"] = float(per_epoch.median())
        cn0 = raw["cn0"].to_numpy(float)
        cn0 = cn0[np.isfinite(cn0)]
        out["cn0_values"] = cn0
        for q in (10, 50, 90):
            out[f"gnss.cn0_p{q}_dbhz"] = float(np.percentile(cn0, q)) if cn0.size else math.nan
        elevation = np.degrees(raw["elevation"].to_numpy(float))
        for low, high in ELEVATION_BANDS_DEG:
            sel = (elevation >= low) & (elevation < high) & np.isfinite(raw["cn0"])
            out[f"gnss.cn0_median_el_{low}-{high}_dbhz"] = (
                float(np.median(raw["cn0"][sel])) if sel.sum() else math.nan)
    if dataset.has("gnss_fix"):
        fix = dataset.read("gnss_fix")
        fix = fix[(fix["fix"] > 0) & np.isfinite(fix["lat"])]
        truth = dataset.read("truth")
        t = fix["t"].to_numpy(float)
        lat = np.radians(np.interp(t, truth["t"], truth["lat"]))
        d_n = np.radians(fix["lat"].to_numpy(float)) - lat
        d_e = (np.radians(fix["lon"].to_numpy(float))
               - np.radians(np.interp(t, truth["t"], truth["lon"]))) * np.cos(lat)
        error = 6.371e6 * np.hypot(d_n, d_e)
        out["fix_errors"] = error
        out["gnss.fix_error_p50_m"] = float(np.percentile(error, 50)) if error.size else math.nan
        out["gnss.fix_error_p95_m"] = float(np.percentile(error, 95)) if error.size else math.nan
    return out


def _statistics(dataset: Dataset) -> dict[str, Any]:
    stats: dict[str, Any] = {}
    if dataset.has("imu"):
        stats.update(_imu(dataset))
    if dataset.has("odometer"):
        stats.update(_odometer(dataset))
    stats.update(_gnss(dataset))
    return stats


def _estimator_rms(dataset: Dataset, name: str) -> float:
    from simulator import pipeline
    from simulator.errors import InputError

    try:
        solved = pipeline.run_estimators(dataset, [name])
    except InputError:
        return math.nan
    return float(pipeline.score(dataset, solved).scores()[name]["horizontal"]["rms"])


def compare_datasets(first: Dataset, second: Dataset,
                     estimator: str | None = "ins_odo_ekf") -> dict[str, Any]:
    """Every statistic of the module docstring on both datasets: ``rows`` (name, first,
    second, ratio), and the arrays the plots draw (``first``, ``second``)."""
    a, b = _statistics(first), _statistics(second)
    names = [k for k in a if k in b and isinstance(a[k], float)]
    if estimator is not None:
        key = f"estimator.{estimator}_horizontal_rms_m"
        a[key], b[key] = _estimator_rms(first, estimator), _estimator_rms(second, estimator)
        names.append(key)
    rows = []
    for name in names:
        x, y = a[name], b[name]
        ratio = y / x if np.isfinite(x) and np.isfinite(y) and x != 0 else math.nan
        rows.append({"statistic": name, "first": x, "second": y, "ratio": ratio})
    return {"rows": rows, "first": a, "second": b}


def _cause(statistic: str) -> str:
    group = statistic.split(".")[0]
    if group == "gnss":
        group = ("satellites" if "satellites" in statistic else "cn0" if "cn0" in statistic
                 else "fix")
    return LIKELY_CAUSE.get(group, "")


def write_comparison(result: dict[str, Any], report_dir: Path, labels: tuple[str, str]) -> None:
    """``report.md`` with the table, the largest mismatches and their likely causes, and the
    plots (IMU spectra, C/N0 and fix-error distributions) into ``report_dir``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    first, second = labels
    lines = [f"# {first} and {second}", "",
             f"Statistics of both datasets, each against its own reference or truth; ratio = "
             f"{second} / {first}.", "",
             f"| statistic | {first} | {second} | ratio |", "|---|---|---|---|"]
    for row in result["rows"]:
        lines.append(f"| {row['statistic']} | {row['first']:.4g} | {row['second']:.4g} | "
                     f"{row['ratio']:.3g} |")
    ranked = sorted((r for r in result["rows"] if np.isfinite(r["ratio"]) and r["ratio"] > 0),
                    key=lambda r: -abs(math.log(r["ratio"])))
    lines += ["", "## Largest mismatches", ""]
    for row in ranked[:5]:
        lines.append(f"- **{row['statistic']}**: ratio {row['ratio']:.3g}. Look first at "
                     f"{_cause(row['statistic'])}.")
    plots = []
    psd_a, psd_b = result["first"].get("psd", {}), result["second"].get("psd", {})
    axes = [k for k in psd_a if k in psd_b]
    if axes:
        fig, grid = plt.subplots(2, 3, figsize=(12, 6), sharex=True)
        for ax, axis in zip(grid.ravel(), axes, strict=False):
            for label, psd in ((first, psd_a), (second, psd_b)):
                ax.semilogy(*psd[axis], label=label)
            ax.set_title(axis)
            ax.set_xlabel("Hz")
        grid.ravel()[0].legend()
        fig.suptitle("IMU power spectral density while driving (units^2/Hz)")
        fig.tight_layout()
        fig.savefig(report_dir / "imu_psd.png", dpi=90)
        plt.close(fig)
        plots.append(("IMU spectra while driving", "imu_psd.png"))
    for key, title, name, xlabel in (("cn0_values", "C/N0", "cn0.png", "dB-Hz"),
                                     ("fix_errors", "Fix horizontal error", "fix_error.png",
                                      "m")):
        if key in result["first"] and key in result["second"]:
            fig, ax = plt.subplots(figsize=(6, 4))
            for label, values in ((first, result["first"][key]),
                                  (second, result["second"][key])):
                if len(values):
                    ax.plot(np.sort(values), np.linspace(0, 1, len(values)), label=label)
            ax.set_xlabel(xlabel)
            ax.set_ylabel("fraction")
            ax.set_title(f"{title}: distribution")
            ax.legend()
            fig.tight_layout()
            fig.savefig(report_dir / name, dpi=90)
            plt.close(fig)
            plots.append((title, name))
    lines.append("")
    for title, name in plots:
        lines += [f"## {title}", "", f"![{title}]({name})", ""]
    (report_dir / "report.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
