"""Plot the real barometric pressure at ARL1 against landnav's barometer there, for
``docs/odometer-and-barometer.md`` (``docs/images/baro_arl1_met.png``).

Real: the ARL1 RINEX met file of 2015-07-19 (``shared/refdata/gnss/arl1_2015-07-19_gnsstk/
arlm2000.15m``, Vaisala PTU300, PR every 15 min; sensor at 217.587 m ellipsoidal height).
landnav: a car standing 24 h at the sensor's position from 2015-07-19 00:00 UTC with the
``bosch-bmp280`` barometer at 1 Hz (its drawn bias, weather rate, noise), five seeds, generated
by ``landnav generate`` (the pipeline), shown as 15-minute means. Beside them the standard
atmosphere at the orthometric height H = h - N (EGM96, what landnav's preset follows) and at the
ellipsoidal height h (what it followed before). Prints the figures quoted in the docs.

Usage: ``PYTHONPATH=. python tools/plot_baro_arl1.py [SHARED_DIR]`` (default ``../shared``).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import yaml  # noqa: E402

from simulator.environment.atmosphere import pressure_pa  # noqa: E402
from simulator.geoid import geoid_undulation_m  # noqa: E402
from simulator.pipeline import generate, load_scenario  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
OUT = REPO / "docs" / "images" / "baro_arl1_met.png"
MET = Path("refdata/gnss/arl1_2015-07-19_gnsstk/arlm2000.15m")
# the met sensor's position (met file header: XYZ -740290.0474 -5457071.7224 3207245.4169,
# H 217.5870 m), as latitude and longitude of the RINEX observation header's station
LAT_DEG, LON_DEG, H_M = 30.383664, -97.725413, 217.587
SEEDS = range(1, 6)


def read_met(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Hours since 00:00 and PR (hPa) of a RINEX 2 meteorological file."""
    body = path.read_text().split("END OF HEADER")[1].splitlines()
    rows = [line.split() for line in body if line.strip()]
    hours = np.array([int(r[3]) + int(r[4]) / 60 + float(r[5]) / 3600 for r in rows])
    return hours, np.array([float(r[6]) for r in rows])


def landnav_pressures(seed: int, workdir: Path) -> tuple[np.ndarray, np.ndarray]:
    """Hours and 15-minute mean pressures (hPa) of the bosch-bmp280 barometer at ARL1."""
    scenario = {
        "name": "arl1-static-day", "seed": seed, "vehicle": "rigid",
        "start": {"utc": "2015-07-19T00:00:00Z", "lat": LAT_DEG, "lon": LON_DEG, "alt": H_M},
        "trajectory": {"kind": "segments", "rate": 1.0,
                       "segments": [{"stop": {"duration": 86400.0}}]},
        "sensors": {"baro": {"preset": "bosch-bmp280", "rate": 1.0}},
    }
    path = workdir / f"arl1_{seed}.yaml"
    path.write_text(yaml.safe_dump(scenario))
    baro = generate(load_scenario(path), workdir / f"ds{seed}").read("baro")
    t, p = baro["t"].to_numpy(), baro["pressure"].to_numpy()
    bins = np.floor(t / 900.0).astype(int)
    means = np.bincount(bins, p) / np.bincount(bins)
    return (np.arange(len(means)) + 0.5) * 0.25, means / 100.0


def main(shared: Path) -> None:
    hours, real = read_met(shared / MET)
    n = float(geoid_undulation_m(LAT_DEG, LON_DEG))
    p_ortho, p_ellip = pressure_pa(H_M - n) / 100.0, pressure_pa(H_M) / 100.0
    fig, ax = plt.subplots(figsize=(9, 4.5))
    ax.plot(hours, real, "k.-", lw=1.5, label="ARL1 met file (Vaisala PTU300), 2015-07-19")
    with tempfile.TemporaryDirectory() as tmp:
        for seed in SEEDS:
            h, p = landnav_pressures(seed, Path(tmp))
            ax.plot(h, p, lw=0.9, alpha=0.8, label=f"landnav bosch-bmp280, seed {seed}")
            print(f"seed {seed}: mean {p.mean():.2f} hPa, change over the day "
                  f"{p[-1] - p[0]:+.2f} hPa")
    ax.axhline(p_ortho, color="tab:blue", ls="--",
               label=f"standard atmosphere at H = h - N = {H_M - n:.1f} m ({p_ortho:.1f} hPa)")
    ax.axhline(p_ellip, color="tab:red", ls=":",
               label=f"standard atmosphere at h = {H_M:.1f} m ({p_ellip:.1f} hPa)")
    ax.set_xlabel("hours of 2015-07-19 (UTC)")
    ax.set_ylabel("pressure, hPa")
    ax.set_xlim(0, 24)
    ax.set_title(f"Barometric pressure at ARL1 (EGM96 N = {n:.2f} m)")
    ax.legend(fontsize=7, loc="lower left", ncol=2)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    OUT.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(OUT, dpi=110)
    print(f"N = {n:.3f} m, H = {H_M - n:.2f} m; standard atmosphere {p_ortho:.2f} hPa at H, "
          f"{p_ellip:.2f} hPa at h; real: mean {real.mean():.2f} hPa, range "
          f"{real.min():.1f}-{real.max():.1f} hPa; wrote {OUT}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else REPO.parent / "shared")
