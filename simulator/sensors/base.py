"""What every sensor model is: a small object built from validated parameters, with one method
that turns the exact trajectory and a random generator into stream tables (column tables of
``simulator.tables``, or DataFrames for a model written with pandas, such as the GNSS receiver;
``simulator.tables.as_frame`` turns either into a DataFrame).

Public names
------------
SensorModel, TRUE_ERROR_RATE_HZ, TEMPERATURE_FIELD, sample_times, grid_index, grid_rows, truth_at,
integrate_over_samples, temperature_change_k.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from simulator.schema import Number, Record
from simulator.tables import Table
from simulator.trajectory.kinematics import Kinematics
from simulator.trajectory.quadrature import (
    GL_NODES,
    GL_WEIGHTS,
    LOBATTO_END_WEIGHT,
    LOBATTO_INNER_NODES,
    LOBATTO_INNER_WEIGHTS,
    cubic_interval_integrals,
    cubic_rule_error,
)

# largest error of the cubic rule accepted per interval before Gauss-Legendre takes over:
# 1e-12 rad and 1e-11 m/s, so that a million samples cannot add up to a measurable drift
CUBIC_RULE_TOLERANCE = {"w_body": 1e-12, "f_body": 1e-11}
# a breakpoint closer than this share of the sample interval to an interval's end is taken to be
# at the end (grid times and sample times ending on them differ by rounding, 1e-17 s)
BREAK_SNAP = 1e-9


class SensorModel(Protocol):
    """A sensor: ``generate`` returns ``{stream_name: table}`` and records the drawn true error
    parameters in ``drawn`` (they go into the manifest's ``sensors`` block).

    A model may also have ``prepare(duration_s, rng, pool)``, drawing the random terms that need
    no trajectory as jobs of ``pool`` before the truth exists; the dataset generator calls it
    when present (``simulator.dataset.generate``), and ``generate`` must give the same result
    whether or not it was called (the IMU, ``simulator.sensors.imu.Imu.prepare``).
    """

    name: str
    drawn: dict

    def generate(self, truth: Kinematics, rng: np.random.Generator) -> dict[str, Table]:
        ...


# rate (Hz) at which sensors keep their true error values over time (``true_errors``, written
# to truth_sensors.parquet): fast enough for a bias process seen by a 10 Hz solution, a tenth
# of the IMU file at 100 Hz
TRUE_ERROR_RATE_HZ = 10.0


# a sensor's temperature profile (the IMU's and the barometer's ``temperature`` block)
TEMPERATURE_FIELD = Record({
    "offset": Number("K", 0.0, doc="temperature at t = 0 minus calibration temperature"),
    "warmup": Number("K", 0.0, doc="temperature rise during the warm-up"),
    "warmup_time": Number("s", 600.0, gt=0, doc="time constant of the warm-up"),
}, default={})


def temperature_change_k(block: dict, t: np.ndarray) -> np.ndarray:
    """dT(t) = offset + warmup (1 - exp(-t / warmup_time)) (K from the calibration temperature),
    the profile of a resolved ``TEMPERATURE_FIELD`` block: a first-order warm-up."""
    return block["offset"] - block["warmup"] * np.expm1(-np.asarray(t) / block["warmup_time"])


def sample_times(duration_s: float, rate_hz: float, first: int = 0) -> np.ndarray:
    """Sample times k / rate for k = first ... floor(duration * rate) (exact multiples)."""
    n = int(np.floor(duration_s * rate_hz + 1e-9))
    return np.arange(first, n + 1) / rate_hz


def grid_index(truth: Kinematics, t: np.ndarray) -> np.ndarray | None:
    """Indices k with t = t_grid[k] when every time lies on the truth's base grid, else None
    (then ``truth.grid_inertial()`` holds the truth at t, already evaluated)."""
    x = np.asarray(t, dtype=float) * truth.rate_hz
    k = np.rint(x)
    if len(k) == 0 or np.abs(k - x).max() > 1e-6 or k.min() < 0 or k.max() >= len(truth.t_grid):
        return None
    return k.astype(np.intp)


def grid_rows(k: np.ndarray) -> slice | np.ndarray:
    """``k`` as a slice when it is a run of consecutive indices (rows are then a view, not a
    gathered copy), else ``k`` itself."""
    if len(k) and k[-1] - k[0] == len(k) - 1 and (np.diff(k) == 1).all():
        return slice(int(k[0]), int(k[-1]) + 1)
    return k


def truth_at(truth: Kinematics, t: np.ndarray,
             keys: tuple[str, ...] = ("w_body", "f_body")) -> dict[str, np.ndarray]:
    """``truth.inertial(t)`` (the ``keys`` of it), taken from the truth's cached grid evaluation
    when every time lies on its grid (sensors sampling at the base rate or a divisor of it)."""
    k = grid_index(truth, t)
    if k is None:
        values = truth.inertial(t)
        return {key: values[key] for key in keys}
    grid, rows = truth.grid_inertial(), grid_rows(k)
    return {key: grid[key][rows] for key in keys}


def integrate_over_samples(truth: Kinematics, t_end: np.ndarray, dt: float,
                           keys: tuple[str, ...] = ("w_body", "f_body")) -> dict[str, np.ndarray]:
    """Integrals of truth vectors over each sample interval (t_end - dt, t_end].

    This is the anti-aliased increment an integrating IMU outputs. On the truth's own grid, the
    cubic rule on the cached grid samples (``simulator.trajectory.quadrature``) is used where its
    estimated error is within ``CUBIC_RULE_TOLERANCE``; where it is not (a vibrating body), and
    no breakpoint of the piecewise kinematics lies inside the interval, four-point Gauss-Lobatto
    on the analytic kinematics, whose end nodes are the cached grid samples (two evaluations of
    the truth per interval, ``Kinematics.rates_inside``: at a fixed fraction of every grid
    interval). Every other interval (off the grid, or holding a breakpoint) is
    integrated with three-point Gauss-Legendre on the analytic kinematics, split at the
    breakpoints so each piece is smooth. Both rules are exact for polynomials up to degree 5.
    """
    t_end = np.asarray(t_end, dtype=float)
    lo, hi = t_end - dt, t_end
    breaks = truth.breakpoints()
    snap = BREAK_SNAP * dt
    first = np.searchsorted(breaks, lo + snap, side="right")
    last = np.searchsorted(breaks, hi - snap, side="left")
    out = {key: np.zeros((len(t_end), 3)) for key in keys}
    gauss = np.ones(len(t_end), dtype=bool)

    k_end = grid_index(truth, t_end)
    on_grid = (k_end is not None and abs(dt * truth.rate_hz - 1.0) < 1e-12
               and k_end.min() >= 1)
    if on_grid and len(truth.t_grid) >= 5:
        grid = truth.grid_inertial()
        gauss = last > first
        interval = grid_rows(k_end - 1)  # the grid interval [t_k-1, t_k] of each sample
        rough = np.zeros(len(t_end), dtype=bool)
        for key in keys:
            out[key] = cubic_interval_integrals(grid[key], dt)[interval]
            rough |= cubic_rule_error(grid[key], dt)[interval] > CUBIC_RULE_TOLERANCE[key]
        lobatto = np.flatnonzero(rough & ~gauss)
        if len(lobatto):
            k = k_end[lobatto]
            inner = [truth.rates_inside(k - 1, u) for u in LOBATTO_INNER_NODES]
            for key in keys:
                ends = grid[key].take(k - 1, axis=0)
                ends += grid[key].take(k, axis=0)
                ends *= LOBATTO_END_WEIGHT
                for weight, values in zip(LOBATTO_INNER_WEIGHTS, inner, strict=True):
                    ends += weight * values[key]
                ends *= dt
                out[key][lobatto] = ends
    if not gauss.any():
        return out
    # intervals without a breakpoint are one piece; one holding c breakpoints (a few per
    # manoeuvre) is split into c + 1 pieces at them
    smooth = np.flatnonzero(gauss & (last <= first))
    held = np.flatnonzero(gauss & (last > first))
    pieces = last[held] - first[held] + 1
    owner = np.repeat(held, pieces)
    piece = np.arange(len(owner)) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    ends_at = np.repeat(first[held], pieces) + piece  # the breakpoint that ends each piece
    is_last = piece == np.repeat(pieces, pieces) - 1
    piece_start = np.where(piece == 0, lo[owner], breaks[np.maximum(ends_at - 1, 0)])
    piece_end = np.where(is_last, hi[owner], breaks[np.minimum(ends_at, len(breaks) - 1)])
    start = np.concatenate([lo[smooth], piece_start])
    length = np.concatenate([np.full(len(smooth), dt), piece_end - piece_start])
    idx = np.concatenate([smooth, owner])
    nodes = (start[:, None] + length[:, None] * GL_NODES[None, :]).ravel()
    values = truth.inertial(nodes)
    for key in keys:
        v = values[key].reshape(len(start), len(GL_NODES), -1)
        out[key][gauss] = 0.0
        np.add.at(out[key], idx, length[:, None] * np.einsum("j,njk->nk", GL_WEIGHTS, v))
    return out
