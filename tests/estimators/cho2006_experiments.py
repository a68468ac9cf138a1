"""The Cho & Choi 2006 experiments behind tests/estimators/test_cho2006.py and
docs/reproduction_cho2006.md: generate the shipped scenarios over seeds, run the filters and
measure each claim's figure, paired per seed.

Run ``python -m tests.estimators.cho2006_experiments [--seeds 10] [--set key=value ...]`` from
the checkout to print the table of docs/reproduction_cho2006.md (``--set`` overrides every
scenario, e.g. ``--set limits.roll_gradient=0.0071189`` (4 deg per g, landnav's default lean, in
rad s^2/m) for the leaning car; ``--dr-only`` runs only the DRM1/DRM2 comparison, whose
scenario's segment indices such overrides may name).
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import Dataset, open_dataset
from simulator.earth import radii_of_curvature, wrap_angle
from simulator.replay import run_estimator
from simulator.scenario import load_scenario

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
SEEDS = tuple(range(1, 11))
CONVERGED_DEG = 3.0  # heading RMS below this from 60 s after moving off: converged
SETTLE_S = 60.0
DR_HORIZON_S = 120.0  # stand-alone DR compared this long after GNSS is lost


def dataset(name: str, seed: int, root: Path, overrides: list[str] | None = None) -> Dataset:
    """Generate scenarios/<name>.yaml with ``seed`` under ``root`` (reused if present)."""
    out = root / f"{name}-{seed}"
    if not out.exists():
        scenario = load_scenario(SCENARIOS / f"{name}.yaml", overrides, seed)
        generate_dataset(scenario, out, show_progress=False)
    return open_dataset(out)


def run(ds: Dataset, name: str, init: dict | None = None,
        config: dict | None = None) -> pd.DataFrame:
    entry = {"name": name, "label": None, "init": init, "config": config}
    return run_estimator(ds, entry, show_progress=False)[0]


def errors(ds: Dataset, solution: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times (s), horizontal error (m) and heading error (deg, wrapped) of a solution."""
    truth = ds.read("truth")
    t = solution["t"].to_numpy()
    lat = np.interp(t, truth["t"], truth["lat"])
    lon = np.interp(t, truth["t"], truth["lon"])
    rn, re = radii_of_curvature(np.radians(lat))
    d_n = np.radians(solution["lat"].to_numpy() - lat) * rn
    d_e = np.radians(solution["lon"].to_numpy() - lon) * re * np.cos(np.radians(lat))
    yaw = np.interp(t, truth["t"], np.unwrap(truth["yaw"].to_numpy()))
    d_yaw = np.degrees(wrap_angle(solution["yaw"].to_numpy() - yaw))
    return t, np.hypot(d_n, d_e), d_yaw


def moving_off(ds: Dataset) -> float:
    truth = ds.read("truth")
    return float(truth["t"].to_numpy()[np.argmax(truth["speed"].to_numpy() > 0.1)])


_HEADING_RMS: dict[tuple[str, str, float], float] = {}  # shared by the tests of one session


def heading_rms(ds: Dataset, name: str, heading_error_deg: float) -> float:
    """Heading RMS (deg) from 60 s after moving off to the end, from ``heading_error_deg``."""
    key = (str(ds.path), name, heading_error_deg)
    if key not in _HEADING_RMS:
        t, _, d_yaw = errors(ds, run(ds, name, {"heading_error": heading_error_deg}))
        late = t >= moving_off(ds) + SETTLE_S
        _HEADING_RMS[key] = float(np.sqrt(np.mean(d_yaw[late] ** 2)))
    return _HEADING_RMS[key]


def dr_error(ds: Dataset, name: str) -> float:
    """Horizontal error (m) 120 s after the scenario's GNSS outage starts."""
    events = ds.read("events")
    start = float(events.loc[events["kind"] == "gnss_outage", "t_start"].iloc[0])
    t, horizontal, _ = errors(ds, run(ds, name))
    return float(np.interp(start + DR_HORIZON_S, t, horizontal))


def z_scale_factor_error(ds: Dataset, name: str, from_s: float = 100.0) -> float:
    """Largest |estimated - true| z-gyro scale factor from ``from_s`` to the end (situation I's
    initial errors: pitch -5 deg, heading -10 deg)."""
    sol = run(ds, name, {"attitude_error": [0.0, -5.0, -10.0]})
    true = ds.manifest["sensors"]["imu"]["gyro"]["scale_factor"][2]
    late = sol["t"].to_numpy() >= from_s
    return float(np.max(np.abs(sol["gyro_scale_factor_z"].to_numpy()[late] - true)))


def situation3_errors(ds: Dataset, name: str) -> tuple[float, float]:
    """Largest horizontal error (m) and heading error (deg) in the 75-90 s outage."""
    t, horizontal, d_yaw = errors(ds, run(ds, name, {"attitude_error": [0.0, -5.0, -10.0]}))
    span = (t >= 75.0) & (t <= 90.0)
    return float(horizontal[span].max()), float(np.abs(d_yaw[span]).max())


def _summary(values: list[float]) -> str:
    v = np.asarray(values)
    return f"median {np.median(v):.2f}, range {v.min():.2f} .. {v.max():.2f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=len(SEEDS))
    parser.add_argument("--set", dest="overrides", action="append", default=[])
    parser.add_argument("--dr-only", action="store_true",
                        help="only the DRM1/DRM2 comparison (cho2006_dr_outage.yaml)")
    args = parser.parse_args()
    seeds = range(1, args.seeds + 1)
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        print(f"seeds {seeds.start}..{seeds.stop - 1}, overrides {args.overrides or 'none'}")
        runs = [] if args.dr_only else [
            *(("dr2d_drm1_ekf", a) for a in (0.0, -45.0, -90.0)),  # beside DRM2, paper Fig. 3
            *((name, a) for a in (-45.0, -90.0, -140.0, -160.0, -175.0)
              for name in ("dr2d_drm2_ekf", "dr2d_drm2_spkf"))]
        for name, angle in runs:
            rms = [heading_rms(dataset("cho2006_situation2", s, root, args.overrides),
                               name, angle) for s in seeds]
            ok = sum(r < CONVERGED_DEG for r in rms)
            print(f"situation II {angle:+.0f} deg {name}: converged {ok}/{len(rms)}; "
                  f"heading RMS {_summary(rms)} deg")
        drm1, drm2 = [], []
        for s in seeds:
            ds = dataset("cho2006_dr_outage", s, root, args.overrides)
            drm1.append(dr_error(ds, "dr2d_drm1_ekf"))
            drm2.append(dr_error(ds, "dr2d_drm2_ekf"))
        wins = sum(b < a for a, b in zip(drm1, drm2, strict=True))
        print(f"DR 120 s after loss: DRM2 better in {wins}/{len(drm1)}; DRM1 {_summary(drm1)} m;"
              f" DRM2 {_summary(drm2)} m")
        for name in () if args.dr_only else ("dr2d_drm2_ekf", "dr2d_drm2_spkf"):
            sf = [z_scale_factor_error(dataset("cho2006_situation1", s, root, args.overrides),
                                       name) for s in seeds]
            print(f"situation I {name}: max |z-gyro scale factor error| from 100 s "
                  f"{_summary(sf)}")
            out = [situation3_errors(dataset("cho2006_situation3", s, root, args.overrides),
                                     name) for s in seeds]
            print(f"situation III {name}: max horizontal error in outage "
                  f"{_summary([o[0] for o in out])} m; max heading error "
                  f"{_summary([o[1] for o in out])} deg")


if __name__ == "__main__":
    main()
