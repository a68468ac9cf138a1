"""Whether a solution knows its own error: NEES per block, per-axis normalised errors, NIS and
the average NEES over Monte Carlo runs (docs/scores.md, ``consistency``, ``nis``, ANEES).

The solution's 1-sigma columns give a diagonal covariance P (the file has no cross-covariances).
For an error e of a block of dimension m (position n/e/d, velocity, attitude roll/pitch/yaw with
wrapped angle errors; for a 2-D solution the horizontal n/e and the yaw alone):

* the per-axis normalised error squared (e_i / sigma_i)^2, whose mean ``nse`` is 1 for a
  consistent estimator (< 1 too cautious, > 1 overconfident);
* the normalised estimation error squared NEES_k = e_k^T P_k^-1 e_k at each epoch k, chi-square
  with m degrees of freedom for a consistent estimator with Gaussian errors; ``nees`` is its
  time average (expected m) and ``inside_95`` the share of epochs inside the two-sided 95 %
  chi-square band [chi2_m(0.025), chi2_m(0.975)];
* over N independent runs, the average NEES (ANEES) is chi-square with N m degrees of freedom
  divided by N: the band chi2_{Nm}(0.025) / N .. chi2_{Nm}(0.975) / N
  (Bar-Shalom, Li and Kirubarajan 2001, section 5.4.2, eqs. 5.4.2-1 to 5.4.2-5).

Everything is taken over the epochs from ``CONSISTENCY_SKIP_S`` after the solution's first row
(an estimator's start-up transient is not what consistency judges), on the rows where the
block's errors and sigmas are all finite and the sigmas positive (``with_sigma``: the share of
the block's epochs with finite errors that have them). A block is 2-D when the
solution never has a finite down error with its sigma (``horizontal`` replaces ``position``),
never a finite vertical velocity (``horizontal_velocity`` replaces ``velocity``) or never a finite
roll and pitch with their sigmas (``yaw`` replaces ``attitude``); an axis with a sigma that no
block holds then is a one-axis block of its own, named by the axis (a 2-D filter's ``pitch``).

Public names
------------
CONSISTENCY_SKIP_S, BAND_PROBABILITIES, Block, BLOCKS, PLANAR_BLOCKS, AXIS_BLOCKS, AXES, chi2_band,
normalised_errors, axis_nse, block_nees, consistency_blocks, consistency_scores, nis_scores,
anees.

References
----------
Bar-Shalom, Li, Kirubarajan, *Estimation with Applications to Tracking and Navigation*, Wiley,
2001, section 5.4 (NEES, NIS and the chi-square tests of filter consistency).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from simulator import columns as col
from simulator.scoring.align import ERR_ATT, ERR_POS, ERR_VEL, solution_errors

CONSISTENCY_SKIP_S = 60.0  # s after the solution's first row before consistency is judged
BAND_PROBABILITIES = (0.025, 0.975)  # the two-sided 95 % chi-square band
_NIS, _NIS_DOF = tuple(col.SOLUTION_NIS)

# axis name -> (error column, 1-sigma column); the names are the solution columns' suffixes
AXES = dict(zip(("n", "e", "d", "vn", "ve", "vd", "roll", "pitch", "yaw"),
                zip((*ERR_POS, *ERR_VEL, *ERR_ATT), col.SOLUTION_STD, strict=True), strict=True))


@dataclass(frozen=True)
class Block:
    """A group of axes judged together: its name in the scores and its axes (``AXES`` keys)."""

    name: str
    axes: tuple[str, ...]

    @property
    def dim(self) -> int:
        """Degrees of freedom of the block's NEES."""
        return len(self.axes)


BLOCKS = (Block("position", ("n", "e", "d")), Block("velocity", ("vn", "ve", "vd")),
          Block("attitude", ("roll", "pitch", "yaw")))
# a 2-D solution's block in place of the 3-D one of the same name in BLOCKS
PLANAR_BLOCKS = {"position": Block("horizontal", ("n", "e")),
                 "velocity": Block("horizontal_velocity", ("vn", "ve")),
                 "attitude": Block("yaw", ("yaw",))}
# the one-axis block of an axis that no block of a solution holds (``consistency_blocks``)
AXIS_BLOCKS = {axis: Block(axis, (axis,)) for axis in AXES}


def chi2_band(dim: int, runs: int = 1) -> tuple[float, float]:
    """The two-sided 95 % band of the average over ``runs`` independent runs of a NEES with
    ``dim`` degrees of freedom: chi2_{runs*dim}(0.025, 0.975) / runs (Bar-Shalom et al. 2001,
    eq. 5.4.2-5); ``runs`` = 1 gives one epoch's band."""
    from scipy.stats import chi2  # here: scipy.stats costs more than a second to import

    low, high = chi2.ppf(BAND_PROBABILITIES, runs * dim) / runs
    return float(low), float(high)


def _after_skip(errors: pd.DataFrame, skip_s: float) -> pd.DataFrame:
    """The rows from ``skip_s`` after the first: a slice (t increases), not a copy."""
    t = errors["t"].to_numpy(float)
    return errors.iloc[int(np.searchsorted(t, t[0] + skip_s)):] if t.size else errors


def _squares(errors: pd.DataFrame, axes: tuple[str, ...]) -> np.ndarray:
    """(e / sigma)^2 of ``axes``, shape (rows, len(axes)); NaN where an error or sigma is not
    finite, a sigma is not positive or the solution has no sigma column for the axis."""
    out = np.full((len(errors), len(axes)), np.nan)
    for i, axis in enumerate(axes):
        err, std = AXES[axis]
        if std in errors:
            e, s = errors[err].to_numpy(float), errors[std].to_numpy(float)
            ok = np.isfinite(e) & np.isfinite(s) & (s > 0)
            out[ok, i] = (e[ok] / s[ok]) ** 2
    return out


def _mean(x: np.ndarray) -> float:
    return float(np.mean(x)) if x.size else float("nan")


def axis_nse(errors: pd.DataFrame, skip_s: float = CONSISTENCY_SKIP_S) -> dict[str, float]:
    """The mean of (error / sigma)^2 per axis (``AXES`` keys) over each axis's own finite rows
    from ``skip_s`` after the first row of a per-sample error table (``align.SolutionErrors.
    errors``); NaN for an axis without a sigma column or without such a row."""
    later = _after_skip(errors, skip_s)
    squares = _squares(later, tuple(AXES))
    return {axis: _mean(squares[np.isfinite(squares[:, i]), i]) for i, axis in enumerate(AXES)}


def normalised_errors(truth: pd.DataFrame, solution: pd.DataFrame,
                      skip_s: float = CONSISTENCY_SKIP_S) -> dict[str, float]:
    """Per-axis mean normalised error squared of a solution against the truth.

    Parameters
    ----------
    truth : DataFrame, ``truth.parquet``.
    solution : DataFrame, a solution table (docs/solution-format.md) with ``std_*`` columns.
    skip_s : s after the solution's first row (inside the truth's span) before the rows count.

    Returns
    -------
    dict axis -> mean of (error / sigma)^2, axes ``n, e, d, vn, ve, vd, roll, pitch, yaw``
    (attitude errors wrapped); 1 for a consistent estimator, NaN where the solution has no
    sigma or no finite row for the axis.
    """
    return axis_nse(solution_errors(truth, solution).errors, skip_s)


def block_nees(errors: pd.DataFrame, block: Block) -> np.ndarray:
    """NEES of ``block`` at every row of a per-sample error table: the sum of its axes'
    (e / sigma)^2, NaN where any of them is missing."""
    return _squares(errors, block.axes).sum(axis=1)


def _has_any(errors: pd.DataFrame, block: Block) -> bool:
    return bool(np.isfinite(block_nees(errors, block)).any())


def consistency_blocks(errors: pd.DataFrame) -> list[Block]:
    """The blocks a solution is judged on: every one of ``BLOCKS``, the 2-D block of
    ``PLANAR_BLOCKS`` beside a 3-D block that has no epoch with every axis finite where the
    2-D one has (a 2-D solution: NaN height or roll and pitch, or no sigma for them), and the
    one-axis block of ``AXIS_BLOCKS`` of each axis with a finite epoch that none of those
    blocks with a finite epoch holds (the pitch of a filter that has no roll)."""
    out = list(BLOCKS)
    for block in BLOCKS:
        planar = PLANAR_BLOCKS[block.name]
        if not _has_any(errors, block) and _has_any(errors, planar):
            out.append(planar)
    held = {axis for block in out if _has_any(errors, block) for axis in block.axes}
    out += [AXIS_BLOCKS[axis] for axis in AXES
            if axis not in held and _has_any(errors, AXIS_BLOCKS[axis])]
    return out


def _errors_finite(errors: pd.DataFrame, axes: tuple[str, ...]) -> np.ndarray:
    """The rows where every error of ``axes`` is finite (a sigma or not)."""
    finite = np.ones(len(errors), dtype=bool)
    for axis in axes:
        finite &= np.isfinite(errors[AXES[axis][0]].to_numpy(float))
    return finite


def _block_scores(errors: pd.DataFrame, block: Block) -> dict | None:
    squares = _squares(errors, block.axes)
    squares = squares[np.isfinite(squares).all(axis=1)]
    if not len(squares):
        return None
    nees = squares.sum(axis=1)
    low, high = chi2_band(block.dim)
    with_error = int(_errors_finite(errors, block.axes).sum())  # >= len(nees) > 0
    return {"nees": float(nees.mean()), "nees_expected": float(block.dim),
            "inside_95": float(np.mean((nees >= low) & (nees <= high))),
            "epochs": len(nees),
            "with_sigma": len(nees) / with_error,
            "nse": {axis: float(squares[:, i].mean()) for i, axis in enumerate(block.axes)}}


def consistency_scores(errors: pd.DataFrame, skip_s: float = CONSISTENCY_SKIP_S
                       ) -> dict[str, dict | None] | None:
    """``consistency`` of a per-sample error table: per block (``consistency_blocks``)
    {nees, nees_expected, inside_95, epochs, with_sigma, nse {axis: mean (e/sigma)^2}} over
    the epochs from ``skip_s`` after the first row, None for a block without such an epoch;
    None when the solution has no ``std_*`` column. ``with_sigma`` is the share of the
    block's epochs with finite errors that carry finite positive sigmas too: the NEES is taken
    over those alone, so a solution that writes NaN or 0 as the sigma of its worst epochs
    leaves them out of its NEES and shows it here (1 for a solution with a sigma at every
    epoch)."""
    if not any(std in errors for std in col.SOLUTION_STD):
        return None
    later = _after_skip(errors, skip_s)
    return {block.name: _block_scores(later, block) for block in consistency_blocks(errors)}


def nis_scores(errors: pd.DataFrame, skip_s: float = CONSISTENCY_SKIP_S) -> dict | None:
    """``nis`` {mean, expected, updates} of a per-sample error table with the solution's
    ``nis_gnss`` and ``nis_gnss_dof`` columns: the mean NIS of the GNSS updates from ``skip_s``
    after the first row and the mean of their degrees of freedom (its value for a consistent
    filter, Bar-Shalom et al. 2001, section 5.4.2); None without the columns, mean None
    without an update."""
    if _NIS not in errors or _NIS_DOF not in errors:
        return None
    later = _after_skip(errors, skip_s)
    nis, dof = later[_NIS].to_numpy(float), later[_NIS_DOF].to_numpy(float)
    ok = np.isfinite(nis) & np.isfinite(dof) & (dof > 0)
    if not ok.any():
        return {"mean": None, "expected": None, "updates": 0}
    return {"mean": float(nis[ok].mean()), "expected": float(dof[ok].mean()),
            "updates": int(ok.sum())}


def anees(nees_per_run: np.ndarray, dim: int) -> dict:
    """The average NEES over Monte Carlo runs and its chi-square 95 % band.

    Parameters
    ----------
    nees_per_run : each run's time-averaged NEES of one block (NaN for a run without one).
    dim : the block's dimension.

    Returns
    -------
    {anees, expected, lower, upper, runs, missing}: the mean over the N runs that have a value,
    ``dim``, the band ``chi2_band(dim, N)``, N, and the runs without a value (None for the
    numbers when N = 0).
    """
    values = np.asarray(nees_per_run, dtype=float)
    ok = values[np.isfinite(values)]
    missing = int(values.size - ok.size)
    if not ok.size:
        return {"anees": None, "expected": float(dim), "lower": None, "upper": None, "runs": 0,
                "missing": missing}
    low, high = chi2_band(dim, ok.size)
    return {"anees": float(ok.mean()), "expected": float(dim), "lower": low, "upper": high,
            "runs": int(ok.size), "missing": missing}
