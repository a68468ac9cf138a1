"""The garage comparison of Park et al. 2019 (Table 3, Fig. 19): generate the garage scenario
for a seed, run whichever of the paper's three filters are registered, and measure each over the
garage's GNSS outage against the truth.

Measured per filter (horizontal errors from latitude and longitude only, so a 2-D filter's NaN
height does not hide them):

* ``exit_horizontal``: horizontal error at the last solution row before GNSS returns, m;
* ``max_horizontal``: largest horizontal error inside the outage, m;
* ``height_change_error``: |estimated minus true height change from outage start to exit|, m
  (NaN for a filter without height);
* ``scale_at_entry``: the estimated odometer scale factor at the outage start minus the true one,
  relative (NaN for a filter without the state);
* ``rms_outside``: horizontal RMS over the rows outside every GNSS outage, m.

Run ``PYTHONPATH=. python -m tests.estimators.park2019_compare [--seeds 10] [--flat]
[--scenario FILE] [--config JSON] [--set k=v ...]`` for the tables of
docs/reproduction_park2019.md (any scenario: its longest GNSS outage is measured).

Public names
------------
PAPER_FILTERS, GARAGE, FLAT_PERFECT, registered_filters, generate_garage, garage_metrics,
compare_seeds.
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from estimators.registry import BUILTINS
from simulator.dataset.generate import generate_dataset
from simulator.dataset.io import Dataset, open_dataset
from simulator.earth import radii_of_curvature
from simulator.replay import run_estimator
from simulator.scenario import load_scenario

REPO = Path(__file__).resolve().parents[2]
GARAGE = REPO / "scenarios" / "park2019_underground_garage.yaml"
PAPER_FILTERS = ("dr2d_odo_ekf", "ins_odo_ekf", "dr3d_ekf")
# the same garage made flat (helices become level circles, ramps level straights) with a
# perfect odometer (no scale-factor error, drift, quantisation or latency)
FLAT_PERFECT = ["trajectory.segments.8.helix.rise=0", "trajectory.segments.25.helix.rise=0",
                "trajectory.segments.10.slope.grade=0", "trajectory.segments.23.slope.grade=0",
                "sensors.odometer.preset=ideal", "sensors.odometer.scale_factor=1.0"]


def registered_filters() -> list[str]:
    """The paper's filters that are registered built-ins, in the paper's order."""
    return [name for name in PAPER_FILTERS if name in BUILTINS]


def generate_garage(out_dir: Path, seed: int, overrides: list[str] | None = None,
                    scenario: Path = GARAGE) -> Dataset:
    """Generate the garage scenario (with ``--set`` style overrides) for ``seed``."""
    data = load_scenario(scenario, list(overrides or []), seed)
    generate_dataset(data, out_dir, force=True)
    return open_dataset(out_dir)


def _horizontal_error(solution: pd.DataFrame, truth: pd.DataFrame) -> np.ndarray:
    lat = np.interp(solution["t"], truth["t"], truth["lat"])
    lon = np.interp(solution["t"], truth["t"], truth["lon"])
    rn, re = radii_of_curvature(np.radians(lat))
    d_n = np.radians(solution["lat"].to_numpy() - lat) * rn
    d_e = np.radians(solution["lon"].to_numpy() - lon) * re * np.cos(np.radians(lat))
    return np.hypot(d_n, d_e)


def _true_scale(dataset: Dataset, t: float, duration: float) -> float:
    if dataset.has("truth_sensors"):
        ts = dataset.read("truth_sensors")
        if "odometer_scale_factor" in ts:
            return float(np.interp(t, ts["t"], ts["odometer_scale_factor"]))
    odo = dataset.manifest["sensors"]["odometer"]
    start = float(odo.get("scale_factor", 1.0))
    end = float(odo.get("scale_factor_end", start))
    return start + (end - start) * t / duration  # the drift's end points, linearly


def garage_metrics(dataset: Dataset, names: list[str] | None = None,
                   configs: dict[str, dict] | None = None) -> dict[str, dict[str, float]]:
    """Run ``names`` (default: the registered paper filters) on ``dataset`` and measure each
    over its longest GNSS outage (see the module docstring)."""
    truth = dataset.read("truth")
    events = dataset.read("events")
    outages = events[events["kind"] == "gnss_outage"]
    longest = outages.loc[(outages["t_end"] - outages["t_start"]).idxmax()]
    t0, t1 = float(longest["t_start"]), float(longest["t_end"])
    out = {}
    for name in names or registered_filters():
        entry = {"name": name, "label": name, "init": None,
                 "config": (configs or {}).get(name)}
        sol, info = run_estimator(dataset, entry, show_progress=False)
        err = _horizontal_error(sol, truth)
        t = sol["t"].to_numpy()
        inside = (t >= t0) & (t < t1)
        exit_row = np.flatnonzero(t < t1)[-1]
        entry_row = np.flatnonzero(t <= t0)[-1]
        outside = np.ones_like(inside)
        for _, o in outages.iterrows():
            outside &= ~((t >= o["t_start"]) & (t < o["t_end"]))
        true_dh = float(np.interp(t[exit_row], truth["t"], truth["alt"])
                        - np.interp(t[entry_row], truth["t"], truth["alt"]))
        est_dh = float(sol["alt"].iloc[exit_row] - sol["alt"].iloc[entry_row])
        scale = math.nan
        if "odometer_scale_factor" in sol:
            true_s = _true_scale(dataset, t[entry_row], float(truth["t"].iloc[-1]))
            scale = float(sol["odometer_scale_factor"].iloc[entry_row]) / true_s - 1.0
        out[name] = {"exit_horizontal": float(err[exit_row]),
                     "max_horizontal": float(err[inside].max()),
                     "height_change_error": abs(est_dh - true_dh),
                     "true_height_change": true_dh,
                     "scale_at_entry": scale,
                     "rms_outside": float(np.sqrt(np.mean(err[outside] ** 2))),
                     "realtime_factor": float(info["realtime_factor"])}
    return out


def compare_seeds(seeds: list[int], overrides: list[str] | None = None,
                  names: list[str] | None = None, configs: dict[str, dict] | None = None,
                  work: Path | None = None, scenario: Path = GARAGE
                  ) -> dict[int, dict[str, dict[str, float]]]:
    """``garage_metrics`` for each seed of ``scenario``, the dataset generated in ``work`` (a
    temporary folder when None)."""
    results = {}
    with tempfile.TemporaryDirectory(dir=work) as tmp:
        for seed in seeds:
            ds = generate_garage(Path(tmp) / f"seed{seed}", seed, overrides, scenario)
            results[seed] = garage_metrics(ds, names, configs)
    return results


def _summary(results: dict[int, dict[str, dict[str, float]]]) -> str:
    names = list(next(iter(results.values())))
    keys = list(next(iter(next(iter(results.values())).values())))
    lines = []
    for name in names:
        for key in keys:
            v = np.array([results[s][name][key] for s in results])
            lines.append(f"{name:14s} {key:20s} median {np.median(v):9.4f}  "
                         f"min {v.min():9.4f}  max {v.max():9.4f}")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument("--set", dest="overrides", action="append", default=[])
    parser.add_argument("--flat", action="store_true", help="the flat garage, perfect odometer")
    parser.add_argument("--scenario", type=Path, default=GARAGE)
    parser.add_argument("--config", type=json.loads, default=None,
                        help='per-filter config, e.g. {"dr3d_ekf": {"adaptive": false}}')
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    overrides = [*(FLAT_PERFECT if args.flat else []), *args.overrides]
    seeds = list(range(args.first_seed, args.first_seed + args.seeds))
    results = compare_seeds(seeds, overrides, configs=args.config, scenario=args.scenario)
    print(_summary(results))
    if args.json:
        args.json.write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
