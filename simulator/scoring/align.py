"""A solution against the truth: the truth at the solution times and the per-sample errors.

The truth is interpolated at each solution time and never extrapolated (solution rows outside the
truth's time span are dropped and counted):

* position linearly in ECEF, which is the same as linear interpolation in any fixed local NED
  frame (the two differ by a rotation and a translation);
* velocity (NED) linearly, component by component;
* roll, pitch and yaw linearly along the wrapped step between consecutive truth samples (the
  truth angles are unwrapped, interpolated, and the error is wrapped), so a yaw crossing +-180 deg
  interpolates through 180 deg, not through 0.

Position errors are the ECEF difference (solution minus truth) resolved in the NED frame at the
interpolated true position (C_e^n, Groves eq. 2.150); a row without a height (NaN ``alt``, e.g. a
bare NMEA GGA) is placed at the true height for its horizontal error and has a NaN down error;
velocity errors are NED differences; attitude errors are wrapped Euler-angle differences
(solution minus truth), rad. Estimated sensor errors (named as in docs/solution-format.md,
``columns.SENSOR_ERRORS``) are compared with ``truth_sensors`` interpolated linearly at the
solution times (``err_`` + the column name, solution minus truth, in the column's own unit). NaN
in a solution row propagates to the errors it feeds; the metrics skip those rows.

Public names
------------
SolutionErrors, solution_errors, sensor_error_name, local_ned, ERR_POS, ERR_VEL, ERR_ATT, ERR_H.

References
----------
Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed.,
2013, section 2.4.3 (local navigation frame) and eq. 2.150.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from simulator import columns as col
from simulator.earth import ecef_to_ned, geodetic_to_ecef, ned_to_ecef_matrix, wrap_angle

ERR_POS = ("err_n", "err_e", "err_d")  # position error, north/east/down, m
ERR_H = "err_h"  # horizontal position error, m
ERR_VEL = ("err_vn", "err_ve", "err_vd")  # velocity error, m/s
ERR_ATT = ("err_roll", "err_pitch", "err_yaw")  # attitude error, rad, wrapped to [-pi, pi)

# the solution's (and truth's) lat, lon, alt / vn, ve, vd / roll, pitch, yaw columns
_POS, _VEL, _ATT = (tuple(col.SOLUTION)[i:i + 3] for i in (1, 4, 7))
# solution rows whose errors are computed at a time: the temporaries (the rotation matrices,
# positions in ECEF) are those of one chunk, not of the whole solution
CHUNK_ROWS = 100_000


@dataclass
class SolutionErrors:
    """Per-sample errors of one solution.

    Attributes
    ----------
    errors : DataFrame
        One row per solution row inside the truth span: ``t`` (s), ``err_n, err_e, err_d`` (m),
        ``err_h`` (m), ``err_vn, err_ve, err_vd`` (m/s), ``err_roll, err_pitch, err_yaw`` (rad),
        the solution's own ``std_*`` columns, ``nis_gnss, nis_gnss_dof`` and ``fix_status``
        when it has them,
        and ``err_<name>`` for each
        sensor-error column of the solution that the truth sensors table also has.
    total_rows : int
        Rows of the solution.
    outside_truth : int
        Rows dropped because their time lies outside the truth's time span.
    """

    errors: pd.DataFrame
    total_rows: int
    outside_truth: int


def _ecef(frame: pd.DataFrame) -> np.ndarray:
    return geodetic_to_ecef(np.radians(frame["lat"].to_numpy(float)),
                            np.radians(frame["lon"].to_numpy(float)),
                            frame["alt"].to_numpy(float))


def local_ned(frame: pd.DataFrame, origin: tuple[float, float, float]) -> np.ndarray:
    """Positions of a table with ``lat, lon`` (deg) and ``alt`` (m) in the NED frame of ``origin``.

    Parameters
    ----------
    frame : DataFrame with n rows.
    origin : (lat deg, lon deg, alt m) of the frame's origin.

    Returns
    -------
    ndarray, shape (n, 3): north, east, down, m.
    """
    return ecef_to_ned(_ecef(frame), np.radians(origin[0]), np.radians(origin[1]), origin[2])


def sensor_error_name(column: str) -> str:
    """The per-sample error column of an estimated sensor-error column."""
    return f"err_{column}"


def solution_errors(truth: pd.DataFrame, solution: pd.DataFrame,
                    truth_sensors: pd.DataFrame | None = None) -> SolutionErrors:
    """Errors of a solution against the truth interpolated at the solution times.

    Parameters
    ----------
    truth : DataFrame
        ``truth.parquet`` (at least ``t, lat, lon, alt, vn, ve, vd, roll, pitch, yaw``), t
        strictly increasing.
    solution : DataFrame
        A solution table (docs/solution-format.md), t increasing.
    truth_sensors : DataFrame or None
        ``truth_sensors.parquet`` (``t`` and true sensor-error columns), or None.

    Returns
    -------
    SolutionErrors
    """
    t_truth = truth["t"].to_numpy(float)
    t_all = solution["t"].to_numpy(float)
    inside = (t_all >= t_truth[0]) & (t_all <= t_truth[-1])
    rows = None if inside.all() else np.flatnonzero(inside)

    def column(name: str) -> np.ndarray:  # the solution's rows inside (no copy when all are)
        values = solution[name].to_numpy(float)
        return values if rows is None else values[rows]

    t = column("t")
    out = {"t": t, **{name: np.empty(len(t)) for name in (*ERR_POS, ERR_H, *ERR_VEL, *ERR_ATT)}}
    truth_ecef = _ecef(truth)
    truth_lat, truth_lon = (truth[k].to_numpy(float) for k in ("lat", "lon"))  # deg
    truth_alt = truth["alt"].to_numpy(float)
    truth_vel = [truth[key].to_numpy(float) for key in _VEL]
    truth_att = [np.unwrap(truth[key].to_numpy(float)) for key in _ATT]
    for a in range(0, len(t), CHUNK_ROWS):  # the temporaries of one chunk at a time
        at = slice(a, a + CHUNK_ROWS)
        rows_at = at if rows is None else rows[at]

        def interp(values: np.ndarray, at: slice = at) -> np.ndarray:
            return np.interp(t[at], t_truth, values)

        def sol(name: str, rows_at: slice | np.ndarray = rows_at) -> np.ndarray:
            return solution[name].to_numpy(float)[rows_at]

        true_ecef = np.stack([interp(x) for x in truth_ecef.T], axis=-1)
        # the NED frame of the interpolated true position (lat/lon interpolated only for the
        # rotation)
        c_ne = ned_to_ecef_matrix(np.radians(interp(truth_lat)), np.radians(interp(truth_lon)))
        # a solution without a height (NaN alt) still has a horizontal error: its point is
        # taken at the true height for that, and its down error stays NaN
        alt = sol("alt")
        no_alt = ~np.isfinite(alt)
        sol_ecef = geodetic_to_ecef(np.radians(sol("lat")), np.radians(sol("lon")),
                                    np.where(no_alt, interp(truth_alt), alt))
        err_pos = np.einsum("kji,kj->ki", c_ne, sol_ecef - true_ecef)
        err_pos[no_alt, 2] = np.nan
        for i, name in enumerate(ERR_POS):
            out[name][at] = err_pos[:, i]
        out[ERR_H][at] = np.hypot(err_pos[:, 0], err_pos[:, 1])
        for name, key, true in zip(ERR_VEL, _VEL, truth_vel, strict=True):
            out[name][at] = sol(key) - interp(true)
        for name, key, true in zip(ERR_ATT, _ATT, truth_att, strict=True):
            out[name][at] = wrap_angle(sol(key) - interp(true))
    for name in (*col.SOLUTION_STD, *col.SOLUTION_NIS, *col.SOLUTION_FIX):
        if name in solution:
            out[name] = column(name)
    if truth_sensors is not None and len(truth_sensors):
        t_sensors = truth_sensors["t"].to_numpy(float)
        for name in col.SENSOR_ERRORS:
            if name in solution and name in truth_sensors:
                true_value = np.interp(t, t_sensors, truth_sensors[name].to_numpy(float),
                                       left=np.nan, right=np.nan)
                out[sensor_error_name(name)] = column(name) - true_value
    return SolutionErrors(pd.DataFrame(out, copy=False), len(solution),
                          int((~inside).sum()))
