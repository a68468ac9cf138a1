"""Test helpers for scoring: a real truth table and solutions built from it with known errors.

Offsets are applied with the curvilinear small-offset relations dlat = dn / (R_N + h),
dlon = de / ((R_E + h) cos lat), dh = -dd (R_N, R_E the meridian and transverse radii of
curvature), independent of the ECEF path the scorer takes; their second-order error is about
d^2 / R, below 1e-5 m for offsets of a few metres.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from simulator import columns as col
from simulator.dataset.generate import build_truth
from simulator.dataset.io import write_dataset
from simulator.earth import radii_of_curvature, wrap_angle
from simulator.outputs import atomic_output_dir
from simulator.scenario import load_scenario

QUICKSTART = Path(__file__).resolve().parents[1] / "scenarios" / "quickstart.yaml"


def quickstart_truth() -> pd.DataFrame:
    """The quickstart scenario's truth table (100 Hz, about 193 s)."""
    return build_truth(load_scenario(QUICKSTART).data).table()


def offset_solution(truth: pd.DataFrame, dpos=(0.0, 0.0, 0.0), dvel=(0.0, 0.0, 0.0),
                    datt_deg=(0.0, 0.0, 0.0)) -> pd.DataFrame:
    """A solution equal to the truth rows plus NED position offsets (m, scalars or per-row
    arrays), NED velocity offsets (m/s) and roll/pitch/yaw offsets (deg, yaw wrapped)."""
    lat = np.radians(truth["lat"].to_numpy())
    alt = truth["alt"].to_numpy()
    r_n, r_e = radii_of_curvature(lat)
    sol = truth[list(col.SOLUTION)].copy()
    sol["lat"] = np.degrees(lat + np.asarray(dpos[0]) / (r_n + alt))
    sol["lon"] = truth["lon"] + np.degrees(np.asarray(dpos[1]) / ((r_e + alt) * np.cos(lat)))
    sol["alt"] = alt - np.asarray(dpos[2])
    for key, d in zip(("vn", "ve", "vd"), dvel, strict=True):
        sol[key] = truth[key] + d
    for key, d in zip(("roll", "pitch", "yaw"), datt_deg, strict=True):
        sol[key] = wrap_angle(truth[key] + np.radians(d))
    return sol.reset_index(drop=True)


def horizontal_error(solution: pd.DataFrame, truth: pd.DataFrame) -> np.ndarray:
    """Horizontal distance, m, between a solution and the truth interpolated to its times."""
    lat = np.interp(solution["t"], truth["t"], truth["lat"])
    lon = np.interp(solution["t"], truth["t"], truth["lon"])
    rn, re = radii_of_curvature(np.radians(lat))
    return np.hypot(np.radians(solution["lat"] - lat) * rn,
                    np.radians(solution["lon"] - lon) * re * np.cos(np.radians(lat)))


def events(*outages: tuple[float, float]) -> pd.DataFrame:
    """An events table with one ``gnss_outage`` row per (t_start, t_end) and a zone row."""
    rows = [{"t_start": a, "t_end": b, "kind": "gnss_outage", "detail": ""} for a, b in outages]
    rows.append({"t_start": 0.0, "t_end": 5.0, "kind": "zone", "detail": "garage"})
    return pd.DataFrame(rows, columns=list(col.EVENTS))


def write_scoring_dataset(directory: Path, truth: pd.DataFrame,
                          outages: tuple[tuple[float, float], ...]) -> Path:
    """A minimal dataset on disk (manifest, truth, events) as ``landnav generate`` lays it out."""
    with atomic_output_dir(directory, force=False) as tmp:
        write_dataset(tmp, {"scenario": {"name": "test"}, "seed": 0},
                      {"truth": truth, "events": events(*outages)})
    return directory


@contextmanager
def saved_figures() -> Iterator[dict[str, Figure]]:
    """Every matplotlib figure saved inside the block, by the stem of the file it was saved to,
    so that a test can read a plot's axes, ticks and legend."""
    figures: dict[str, Figure] = {}
    original = Figure.savefig

    def keep(self: Figure, path, *args, **kwargs):
        figures[Path(str(path)).name.split(".png")[0].lstrip(".")] = self
        return original(self, path, *args, **kwargs)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(Figure, "savefig", keep)
        yield figures
