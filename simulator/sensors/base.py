"""What every sensor model is: a small object built from validated parameters, with one method
that turns the exact trajectory and a random generator into stream tables.

Public names
------------
SensorModel, sample_times, integrate_over_samples.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np
import pandas as pd

from simulator.trajectory.kinematics import Kinematics

# Gauss-Legendre nodes and weights on [0, 1]: exact for polynomials up to degree 5
_GL_X, _GL_W = np.polynomial.legendre.leggauss(3)
GL_NODES = 0.5 * (_GL_X + 1.0)
GL_WEIGHTS = 0.5 * _GL_W


class SensorModel(Protocol):
    """A sensor: ``generate`` returns ``{stream_name: table}`` and records the drawn true error
    parameters in ``drawn`` (they go into the manifest's ``sensors`` block)."""

    name: str
    drawn: dict

    def generate(self, truth: Kinematics, rng: np.random.Generator) -> dict[str, pd.DataFrame]:
        ...


def sample_times(duration_s: float, rate_hz: float, first: int = 0) -> np.ndarray:
    """Sample times k / rate for k = first ... floor(duration * rate) (exact multiples)."""
    n = int(np.floor(duration_s * rate_hz + 1e-9))
    return np.arange(first, n + 1) / rate_hz


def integrate_over_samples(
    truth: Kinematics, t_end: np.ndarray, dt: float | np.ndarray,
    keys: tuple[str, ...] = ("w_body", "f_body"),
    derive: Callable[[dict[str, np.ndarray]], dict[str, np.ndarray]] | None = None,
) -> dict[str, np.ndarray]:
    """Integrals of truth vectors over each sample interval (t_end - dt, t_end].

    Three-point Gauss-Legendre quadrature of the exact kinematics (exact for polynomials up to
    degree 5): this is the anti-aliased increment an integrating IMU outputs.

    Parameters
    ----------
    truth : the exact kinematics.
    t_end : ndarray, shape (n,), interval end times, s.
    dt : interval length(s), s: a number or shape (n,).
    keys : vector quantities of ``truth.inertial`` to integrate.
    derive : optional function of the ``truth.inertial`` dict at the quadrature nodes returning
        further integrands (each shape (m, 3)), which are integrated too.
    """
    n_nodes = len(GL_NODES)
    dt = np.broadcast_to(np.asarray(dt, dtype=float), np.shape(t_end))
    lo, hi = t_end - dt, t_end
    # intervals holding a breakpoint of the piecewise kinematics are split there, so every
    # quadrature runs over a smooth stretch and stays exact
    breaks = truth.breakpoints()
    first = np.searchsorted(breaks, lo, side="right")
    last = np.searchsorted(breaks, hi, side="left")
    split = np.flatnonzero(last > first)
    starts, lengths, owner = [lo], [dt], [np.arange(len(t_end))]
    if len(split):
        starts.pop(), lengths.pop(), owner.pop()
        smooth = np.flatnonzero(last <= first)
        starts.append(lo[smooth])
        lengths.append(dt[smooth])
        owner.append(smooth)
        for i in split:
            edges = np.concatenate([[lo[i]], breaks[first[i]:last[i]], [hi[i]]])
            starts.append(edges[:-1])
            lengths.append(np.diff(edges))
            owner.append(np.full(len(edges) - 1, i))
    start, length, idx = (np.concatenate(a) for a in (starts, lengths, owner))
    nodes = (start[:, None] + length[:, None] * GL_NODES[None, :]).ravel()
    k = truth.inertial(nodes)
    if derive is not None:
        extra = derive(k)
        k.update(extra)
        keys = tuple(keys) + tuple(extra)
    out = {}
    for key in keys:
        values = k[key].reshape(len(start), n_nodes, -1)
        pieces = length[:, None] * np.einsum("j,njk->nk", GL_WEIGHTS, values)
        total = np.zeros((len(t_end), values.shape[-1]))
        np.add.at(total, idx, pieces)
        out[key] = total
    return out
