"""The relative-positioning scores (SPEC section 8, ``rtk``) of a solution that writes the
integer-fix status ``fix_status`` (0 none, 1 float, 2 fixed; an RTKLIB ``.pos`` file's Q = 1
reads as fixed and Q = 2 as float).

* ``fix_rate``: the fraction of the solution's epochs (rows with a status) that are fixed;
* ``wrong_fix_rate``: the fraction of fixed epochs whose 3-D error exceeds ``WRONG_FIX_M``
  (10 cm: an integer off by one cycle moves the solution by a wavelength, 19 cm on L1);
* ``fixed_rms``: the 3-D RMS error over the fixed epochs;
* ``time_to_first_fix``: seconds from the solution's first epoch to its first fixed one;
* ``refix_times``: per GNSS outage (the ``gnss_outage`` events), the seconds from the outage's
  end (GNSS back) to the next fixed epoch, None when none comes before the next outage or
  the end: counted, never dropped.

Public names
------------
rtk_scores, WRONG_FIX_M, FIXED, FLOAT.
"""

from __future__ import annotations

import numpy as np

WRONG_FIX_M = 0.10
FIXED, FLOAT = 2, 1


def _value(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def rtk_scores(t: np.ndarray, error_3d: np.ndarray, fix_status: np.ndarray,
               outages: list[tuple[float, float]]) -> dict:
    """The ``rtk`` block from per-epoch times (s), 3-D errors (m) and fix status; ``outages``
    as (start, end) times, increasing."""
    t = np.asarray(t, dtype=float)
    status = np.asarray(fix_status, dtype=float)
    error = np.asarray(error_3d, dtype=float)
    known = np.isfinite(status)
    t, status, error = t[known], status[known], error[known]
    fixed = status == FIXED
    out: dict = {"epochs": int(t.size), "fixed_epochs": int(fixed.sum()),
                 "fix_rate": _value(fixed.mean()) if t.size else None,
                 "wrong_fix_rate": None, "fixed_rms": None, "time_to_first_fix": None,
                 "refix_times": []}
    if fixed.any():
        fixed_error = error[fixed]
        good = np.isfinite(fixed_error)
        out["wrong_fix_rate"] = _value(np.mean(fixed_error[good] > WRONG_FIX_M)) \
            if good.any() else None
        out["fixed_rms"] = _value(np.sqrt(np.mean(fixed_error[good] ** 2))) \
            if good.any() else None
        out["time_to_first_fix"] = float(t[fixed][0] - t[0])
    fixed_t = t[fixed]
    for i, (_, end) in enumerate(outages):
        limit = outages[i + 1][0] if i + 1 < len(outages) else np.inf
        after = fixed_t[(fixed_t >= end) & (fixed_t < limit)]
        out["refix_times"].append(float(after[0] - end) if after.size else None)
    return out
