"""What every sensor model is: a small object built from validated parameters, with one method
that turns the exact trajectory and a random generator into stream tables (column tables of
``simulator.tables``, or DataFrames for a model written with pandas, such as the GNSS receiver;
``simulator.tables.as_frame`` turns either into a DataFrame).

Public names
------------
SensorModel, sample_times, grid_index, integrate_over_samples.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from simulator.tables import Table
from simulator.trajectory.kinematics import Kinematics

# Gauss-Legendre nodes and weights on [0, 1]: exact for polynomials up to degree 5
_GL_X, _GL_W = np.polynomial.legendre.leggauss(3)
GL_NODES = 0.5 * (_GL_X + 1.0)
GL_WEIGHTS = 0.5 * _GL_W
# largest Simpson error accepted per interval before Gauss-Legendre takes over: 1e-12 rad and
# 1e-11 m/s, so that a million samples cannot add up to a measurable drift
SIMPSON_TOLERANCE = {"w_body": 1e-12, "f_body": 1e-11}


class SensorModel(Protocol):
    """A sensor: ``generate`` returns ``{stream_name: table}`` and records the drawn true error
    parameters in ``drawn`` (they go into the manifest's ``sensors`` block)."""

    name: str
    drawn: dict

    def generate(self, truth: Kinematics, rng: np.random.Generator) -> dict[str, Table]:
        ...


def sample_times(duration_s: float, rate_hz: float, first: int = 0) -> np.ndarray:
    """Sample times k / rate for k = first ... floor(duration * rate) (exact multiples)."""
    n = int(np.floor(duration_s * rate_hz + 1e-9))
    return np.arange(first, n + 1) / rate_hz


def grid_index(truth: Kinematics, t: np.ndarray) -> np.ndarray | None:
    """Indices k with t = t_grid[k] when every time lies on the truth's base grid, else None
    (then ``truth.grid_inertial()`` holds the truth at t, already evaluated)."""
    k = np.rint(np.asarray(t, dtype=float) * truth.rate_hz).astype(int)
    if (len(k) == 0 or not np.allclose(k, t * truth.rate_hz, rtol=0, atol=1e-6)
            or k.min() < 0 or k.max() >= len(truth.t_grid)):
        return None
    return k


def integrate_over_samples(truth: Kinematics, t_end: np.ndarray, dt: float,
                           keys: tuple[str, ...] = ("w_body", "f_body")) -> dict[str, np.ndarray]:
    """Integrals of truth vectors over each sample interval (t_end - dt, t_end].

    This is the anti-aliased increment an integrating IMU outputs. On the truth's own grid,
    Simpson's rule on the cached grid and midpoint evaluations is used where it is exact to
    ``SIMPSON_TOLERANCE`` (its error dt^5/2880 f'''' estimated from the fourth difference of the
    five neighbouring half-step values). Every other interval is integrated with three-point
    Gauss-Legendre (exact for polynomials up to degree 5), split at the breakpoints of the
    piecewise kinematics so each piece is smooth.
    """
    t_end = np.asarray(t_end, dtype=float)
    lo, hi = t_end - dt, t_end
    breaks = truth.breakpoints()
    first = np.searchsorted(breaks, lo, side="right")
    last = np.searchsorted(breaks, hi, side="left")
    out = {key: np.zeros((len(t_end), 3)) for key in keys}
    gauss = np.ones(len(t_end), dtype=bool)

    k_end = grid_index(truth, t_end)
    on_grid = (k_end is not None and abs(dt * truth.rate_hz - 1.0) < 1e-12
               and k_end.min() >= 1)
    if on_grid:
        grid, mid = truth.grid_inertial(), truth.grid_inertial(midpoints=True)
        k = k_end
        gauss = last > first
        for key in keys:
            g, m = grid[key], mid[key]
            out[key] = dt / 6 * (g[k - 1] + 4 * m[k - 1] + g[k])
            # half-step sequence g0 m0 g1 m1 ...: fourth difference centred on each interval
            half = np.empty((2 * len(g) - 1, 3))
            half[0::2], half[1::2] = g, m
            d4 = np.zeros_like(half)
            d4[2:-2] = half[:-4] - 4 * half[1:-3] + 6 * half[2:-2] - 4 * half[3:-1] + half[4:]
            d4[:2], d4[-2:] = np.inf, np.inf
            error = dt / 180 * np.max(np.abs(d4[2 * k - 1]), axis=1)
            gauss |= error > SIMPSON_TOLERANCE[key]
    # intervals without a breakpoint in one vectorised piece; only those holding breakpoints
    # (a few per manoeuvre) are split one by one
    smooth = np.flatnonzero(gauss & (last <= first))
    starts, lengths, owner = [lo[smooth]], [np.full(len(smooth), dt)], [smooth]
    for i in np.flatnonzero(gauss & (last > first)):
        edges = np.concatenate([[lo[i]], breaks[first[i]:last[i]], [hi[i]]])
        starts.append(edges[:-1])
        lengths.append(np.diff(edges))
        owner.append(np.full(len(edges) - 1, i))
    if not gauss.any():
        return out
    start, length, idx = (np.concatenate(a) for a in (starts, lengths, owner))
    nodes = (start[:, None] + length[:, None] * GL_NODES[None, :]).ravel()
    values = truth.inertial(nodes)
    for key in keys:
        v = values[key].reshape(len(start), len(GL_NODES), -1)
        out[key][gauss] = 0.0
        np.add.at(out[key], idx, length[:, None] * np.einsum("j,njk->nk", GL_WEIGHTS, v))
    return out
