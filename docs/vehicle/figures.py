"""The figures of docs/vehicle.md: the accelerometer's power spectral density on a class B road
beside the real RAV4 log (whole, and less the part its own rotation explains), and the
distributions of speed, accelerations, yaw rate, pitch and roll of the shipped scenarios beside
two real drives.

Run from the checkout:  python docs/vehicle/figures.py [../shared]
(needs the shared reference data; SUMO scenarios need SUMO; writes docs/vehicle/*.png and prints
the figures quoted in docs/vehicle.md).
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy.io import loadmat  # noqa: E402
from scipy.signal import csd, welch  # noqa: E402

from simulator import earth  # noqa: E402
from simulator.dataset.generate import build_truth  # noqa: E402
from simulator.scenario import load_scenario, validate_data  # noqa: E402

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
COMMA = "refdata/vehicle/comma2k19_rav4_2018-08-02_seg40"
TURIN = "refdata/vehicle/navego_ekinox_turin/ref.mat"


def _cruise(vehicle: str | dict, speed: float = 15.0) -> dict:
    """Truth at 100 Hz of a minute at ``speed`` on the vehicle's road (its default class B)."""
    data = validate_data({
        "name": "cruise", "vehicle": vehicle,
        "start": {"utc": "2024-05-01T03:00:00Z", "lat": 45.0, "lon": 7.6, "alt": 240.0},
        "trajectory": {"kind": "segments", "segments": [
            {"accelerate": {"to_speed": speed, "accel": 1.5}}, {"straight": {"duration": 65}}]},
        "sensors": {"imu": {"preset": "ideal", "rate": 100}}}, "cruise")
    truth = build_truth(data).columns()
    keep = truth["t"] > truth["t"][-1] - 60.0
    return {key: np.asarray(value)[keep] for key, value in truth.items()}


def _not_from_rotation(accel: np.ndarray, gyro: np.ndarray, fs: float,
                       nperseg: int) -> tuple[np.ndarray, np.ndarray]:
    """PSD of one accelerometer axis less the part its three gyro axes explain (multiple
    coherence: S_aa - S_ag S_gg^-1 S_ga per frequency), the vibration that is not the device's
    rotation (a phone rocking on its windshield mount moves its accelerometer by the rotation
    times its lever)."""
    def cross(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return csd(x, y, fs, nperseg=nperseg)[1]

    f = csd(accel, accel, fs, nperseg=nperseg)[0]
    s_gg = np.stack([np.stack([cross(gyro[:, i], gyro[:, j]) for j in range(3)], -1)
                     for i in range(3)], -2)
    s_ga = np.stack([cross(gyro[:, i], accel) for i in range(3)], -1)
    explained = np.einsum("fi,fi->f", s_ga.conj(), np.linalg.solve(s_gg, s_ga[..., None])[..., 0])
    return f, cross(accel, accel).real - explained.real


def psd_figure(shared: Path) -> None:
    log = shared / COMMA / "processed_log"
    t = np.load(log / "IMU/accelerometer/t")
    real = np.load(log / "IMU/accelerometer/value")
    gyro = np.load(log / "IMU/gyro/value")
    real, gyro = real - real.mean(axis=0), gyro - gyro.mean(axis=0)
    fs_real = 1.0 / float(np.median(np.diff(t)))
    fig, axes = plt.subplots(1, 3, figsize=(13, 4), sharey=True)
    sims = {"automotive, class B": _cruise("automotive"),
            "automotive, class C": _cruise({"roughness": "C"}),
            "rigid (before issue 13)": _cruise("rigid")}
    for axis, name in enumerate("xyz"):
        ax = axes[axis]
        f, p = welch(real[:, axis] - real[:, axis].mean(), fs_real, nperseg=1024)
        ax.semilogy(f, p, color="k", label="comma2k19 RAV4, 8-20 m/s (real)")
        band = (f >= 5) & (f <= 50)
        print(f"real accel_{name} rms 5-50 Hz: {np.sqrt(np.trapezoid(p[band], f[band])):.3f}")
        f, p = _not_from_rotation(real[:, axis], gyro, fs_real, 256)
        ax.semilogy(f, np.maximum(p, 1e-12), color="k", linestyle="--",
                    label="the same, less what its rotation explains")
        band = (f >= 5) & (f <= 50)
        print(f"real accel_{name} less rotation rms 5-50 Hz: "
              f"{np.sqrt(np.trapezoid(p[band], f[band])):.3f}")
        for label, truth in sims.items():
            x = truth["f" + name] - truth["f" + name].mean()
            f, p = welch(x, 100.0, nperseg=1024)
            ax.semilogy(f, np.maximum(p, 1e-12), label=f"landnav {label}, 15 m/s")
            band = (f >= 5) & (f <= 50)
            print(f"{label} accel_{name} rms 5-50 Hz: "
                  f"{np.sqrt(np.trapezoid(p[band], f[band])):.3f}")
        ax.set_title(f"accelerometer {name} (FRD)")
        ax.set_xlabel("frequency, Hz")
        ax.set_ylim(1e-8, 1e0)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("PSD, (m/s^2)^2/Hz")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(HERE / "accel_psd.png", dpi=110)


def _one_hz(t: np.ndarray, speed: np.ndarray, yaw: np.ndarray, pitch: np.ndarray,
            roll: np.ndarray) -> dict[str, np.ndarray]:
    """The compared quantities on a 1 Hz grid (the Turin reference's rate), alike for every
    source: longitudinal acceleration dv/dt, yaw rate dpsi/dt, lateral acceleration v dpsi/dt."""
    grid = np.arange(t[0], t[-1], 1.0)
    v = np.interp(grid, t, speed)
    psi = np.interp(grid, t, np.unwrap(yaw))
    rate = np.gradient(psi, grid)
    return {"speed, m/s": v, "longitudinal acceleration, m/s^2": np.gradient(v, grid),
            "lateral acceleration, m/s^2": v * rate,
            "yaw rate, deg/s": np.degrees(rate),
            "pitch, deg": np.degrees(np.interp(grid, t, pitch)),
            "roll, deg": np.degrees(np.interp(grid, t, roll))}


def _comma(shared: Path) -> dict[str, np.ndarray]:
    pose = shared / COMMA / "global_pose"
    t = np.load(pose / "frame_times")
    xyz = np.load(pose / "frame_positions")
    q = np.load(pose / "frame_orientations")  # Hamilton, ECEF to the [forward, right, down] frame
    lat, lon, _ = earth.ecef_to_geodetic(xyz)
    c_eb = earth.quat_to_dcm(q)  # body to ECEF
    c_en = earth.ned_to_ecef_matrix(lat, lon)
    c_nb = np.einsum("nji,njk->nik", c_en, c_eb)
    roll, pitch, yaw = earth.dcm_to_euler(c_nb)
    log = shared / COMMA / "processed_log/CAN/speed"
    speed = np.interp(t, np.load(log / "t"), np.ravel(np.load(log / "value")))
    return _one_hz(t, speed, yaw, pitch, roll)


def _turin(shared: Path) -> dict[str, np.ndarray]:
    ref = loadmat(shared / TURIN, squeeze_me=True, struct_as_record=False)["ref"]
    speed = np.hypot(ref.vel[:, 0], ref.vel[:, 1])
    return _one_hz(ref.t - ref.t[0], speed, ref.yaw, ref.pitch, ref.roll)


def _shipped() -> dict[str, np.ndarray]:
    out: dict[str, list[np.ndarray]] = {}
    for path in sorted((REPO / "scenarios").glob("*.yaml")):
        try:
            truth = build_truth(load_scenario(path).data).columns()
        except Exception as exc:  # a SUMO scenario without SUMO: left out, and said so
            print(f"{path.name}: left out ({exc})")
            continue
        t = np.asarray(truth["t"])
        for key, value in _one_hz(t, np.abs(truth["speed"]), truth["yaw"], truth["pitch"],
                                  truth["roll"]).items():
            out.setdefault(key, []).append(value)
        print(f"{path.name}: {t[-1]:.0f} s")
    return {key: np.concatenate(values) for key, values in out.items()}


def distributions_figure(shared: Path) -> None:
    sources = {"landnav shipped scenarios": _shipped(), "Turin, Ekinox reference": _turin(shared),
               "comma2k19 RAV4 highway": _comma(shared)}
    keys = list(next(iter(sources.values())))
    fig, axes = plt.subplots(2, 3, figsize=(13, 7))  # densities on a log scale: the tails
    for ax, key in zip(axes.ravel(), keys, strict=True):
        values = np.concatenate([v[key] for v in sources.values()])
        bins = np.linspace(*np.percentile(values, [0.5, 99.5]), 40)
        for name, data in sources.items():
            ax.hist(data[key], bins=bins, density=True, histtype="step", label=name)
            print(f"{name}: {key} p5/p50/p95 = "
                  f"{' / '.join(f'{x:.2f}' for x in np.percentile(data[key], [5, 50, 95]))}")
        ax.set_xlabel(key)
        ax.set_yscale("log")
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(HERE / "distributions.png", dpi=110)


if __name__ == "__main__":
    shared_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else REPO.parent / "shared"
    psd_figure(shared_dir)
    distributions_figure(shared_dir)
