"""A pseudorange's error split by how it behaves in time and across the satellites, from the
receiver's datasheet (``simulator.datasheet``; docs/gnss-errors.md), for the tightly coupled
estimators that carry the drive-long parts as states or variables (Brown & Hwang, *Introduction
to Random Signals and Applied Kalman Filtering*, 4th ed.: the augmented state of coloured
measurement noise):

* the broadcast ionosphere's residual shared by an epoch's satellites: its part common to them
  and its smooth field's value and north and east gradient at the receiver's zenith pierce
  point, four quantities of unit variance with a coefficient per satellite
  (``toolbox.iono_field.residual_terms``, the ``SHARED_TERMS``);
* each satellite's own drive-long error: the signal-in-space error, the field's remainder at
  its pierce point and the troposphere's zenith residual over sin(elevation), in quadrature;
* the rest of the reported variance (code noise and multipath after the carrier smoothing),
  white, its 1-sigma inflated by the correlated-noise factor of the smoothing time
  (``gnss_model.correlated_noise_inflation``).

Read by ``fgo_tc`` (variables), ``tc_ekf``, ``tc_ukf`` and ``riss3d_tc_ekf`` (states).

Public names
------------
RangeBudget, range_budget, DEFAULT_UERE_M, PSEUDORANGE_FLOOR_M, CORRELATION_TIME_S.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from estimators.toolbox.gnss_model import RawEpoch, correlated_noise_inflation
from estimators.toolbox.iono_field import residual_terms
from simulator.datasheet import iono_residual_fractions

DEFAULT_UERE_M = 3.0  # a pseudorange's 1-sigma where the receiver reports none
PSEUDORANGE_FLOOR_M = 0.1  # white 1-sigma left of a pseudorange at least, before inflation
CORRELATION_TIME_S = 1800.0  # of the drive-long errors, as Gauss-Markov (docs/gnss-errors.md)


@dataclass(frozen=True)
class RangeBudget:
    """``iono_common`` the 1-sigma of the broadcast ionosphere's relative residual common to
    the epoch's satellites (times each satellite's broadcast delay I), ``iono_field`` that of
    its smooth field over the sky (``toolbox.iono_field``: its value and gradient at the
    receiver's zenith pierce point are shared, the rest each satellite's own), ``sis`` the
    signal-in-space error (m), ``tropo_zenith`` the troposphere's zenith residual (m), and
    ``inflation`` the factor on the rest's 1-sigma."""

    iono_common: float
    iono_field: float
    sis: float
    tropo_zenith: float
    inflation: float

    def sigmas(self, ep: RawEpoch, unreported_m: float = DEFAULT_UERE_M
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per satellite of a ``RawEpoch``: the coefficients (4, m), m, of the ``SHARED_TERMS``
        (``iono_field.residual_terms``); the 1-sigma of its own drive-long error sqrt(sis^2 +
        its share of the field + (tropo / sin(el))^2); and the white 1-sigma of the rest: the
        reported variance less those (at least ``PSEUDORANGE_FLOOR_M``), inflated; a satellite
        without a reported 1-sigma takes ``unreported_m``."""
        delay = np.nan_to_num(ep.iono) if ep.iono is not None else np.zeros(len(ep.sv))
        el = ep.elevation if ep.elevation is not None else np.full(len(ep.sv), np.nan)
        mapping = 1.0 / np.sin(np.clip(np.nan_to_num(el, nan=math.pi / 6), 0.05, None))
        shared, own_iono = residual_terms(delay, ep.elevation, ep.azimuth, self.iono_common,
                                          self.iono_field)
        bias2 = self.sis**2 + own_iono + (self.tropo_zenith * mapping) ** 2
        reported = np.where(np.isfinite(ep.pseudorange_std), ep.pseudorange_std, unreported_m)
        rest2 = reported**2 - bias2 - np.sum(shared**2, axis=0)
        white = np.sqrt(np.maximum(rest2, PSEUDORANGE_FLOOR_M**2)) * self.inflation
        return shared, np.sqrt(bias2), white

    def shared_in_use(self) -> np.ndarray:
        """Which of the ``SHARED_TERMS`` this receiver's ionosphere has (the common residual
        with iono_scale other than 1, the field's three with a residual)."""
        return np.array([self.iono_common > 0.0] + [self.iono_field > 0.0] * 3)


def range_budget(gnss: Mapping[str, Any], interval_s: float | None = None) -> RangeBudget:
    """``RangeBudget`` of a receiver datasheet block (zeros where it is silent: the reported
    1-sigma white), the inflation counted over epochs ``interval_s`` apart (the receiver's
    ``rate`` when None)."""
    common, field = iono_residual_fractions(gnss)
    if interval_s is None:
        interval_s = 1.0 / float(gnss.get("rate") or 1.0)
    return RangeBudget(
        iono_common=common, iono_field=field, sis=float(gnss.get("sis_error") or 0.0),
        tropo_zenith=float(gnss.get("tropo_residual") or 0.0),
        inflation=correlated_noise_inflation(float(gnss.get("carrier_smoothing") or 0.0),
                                             interval_s))
