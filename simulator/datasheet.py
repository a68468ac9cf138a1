"""What a user of a dataset can derive from its datasheet alone (the manifest's ``datasheet``),
written once for the estimators and the exporters.

* ``fix_uere_m``: the user equivalent range error of a receiver preset, the root sum square of
  its error budget (Misra & Enge, *Global Positioning System*, 2nd ed., section 6.1: a fix's
  1-sigma is DOP x UERE): signal in space, the ionosphere left after the broadcast
  (Klobuchar) correction, the troposphere model's error and code multipath (``tracking_noise``
  is a dimensionless scale of the C/N0-driven loop noise, which the carrier smoothing of a
  fix leaves at centimetres: not part of the budget).
  The ionosphere term: the true delay is ``iono_scale`` times the broadcast model's, varying by
  ``iono_residual`` (relative, 1-sigma), so the part left is sqrt((scale - 1)^2 + residual^2)
  of the broadcast delay, taken at ``TYPICAL_L1_SLANT_IONO_M`` (a mid-latitude daytime L1
  delay at 30 deg elevation; Klobuchar's zenith delay by day is 5-10 m, its night value 5 ns
  = 1.5 m, times an obliquity of about 1.8: Misra & Enge section 5.3).

Public names
------------
fix_uere_m, TYPICAL_L1_SLANT_IONO_M.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

TYPICAL_L1_SLANT_IONO_M = 5.0


def fix_uere_m(gnss: Mapping[str, Any], ionosphere: bool = True) -> float:
    """User equivalent range error (m, 1-sigma) of a receiver datasheet block (module
    docstring); 0 for an ideal receiver. ``ionosphere=False`` leaves the ionosphere term out:
    for the horizontal error, since slant delays that grow alike with the obliquity on every
    satellite go mostly into the clock and the height (Misra & Enge, section 5.3)."""
    def value(key: str) -> float:
        return float(gnss.get(key) or 0.0)

    iono_fraction = math.hypot(value("iono_scale") - 1.0 if gnss.get("iono_scale") else 0.0,
                               value("iono_residual"))
    terms = (value("sis_error"), iono_fraction * TYPICAL_L1_SLANT_IONO_M * ionosphere,
             value("tropo_residual"), value("multipath"))
    return math.sqrt(sum(x * x for x in terms))
