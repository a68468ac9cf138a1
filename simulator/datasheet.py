"""What a user of a dataset can derive from its receiver's datasheet alone (the manifest's
``datasheet["gnss"]``): one range error budget, read by the estimators (a filter's fix and
pseudorange noise) and the exporters (a ROS fix's covariance).

* ``iono_residual_fractions``: the broadcast (Klobuchar) ionosphere's residual, as fractions
  of the broadcast delay. The simulated true delay is ``iono_scale`` (1 + ``iono_residual`` g)
  times the broadcast model's, g a unit-variance field over the sky (docs/gnss-errors.md), so
  the residual is (scale - 1) + scale residual g: a part common to every satellite,
  |scale - 1|, and the field's 1-sigma, scale residual. A tightly coupled filter scales these
  by each satellite's own broadcast delay. Of the field, ``IONO_FIELD_OWN_SHARE`` of its
  1-sigma is each satellite's own and the rest common: the pierce points of one epoch's
  satellites on the 350 km shell lie up to about a thousand km apart, and the field's
  correlation is exp(-d^2 / (2 L^2)), L = 1000 km (docs/gnss-errors.md): about 0.75 at a
  typical 750 km, so sqrt(1 - 0.75) = 0.5 of it is each satellite's own.
* ``iono_field_covariance``: the field's part of one epoch's pseudorange errors as the
  covariance between the satellites, (f I_i)(f I_j) exp(-d_ij^2 / (2 L^2)), f the field's
  1-sigma fraction, I the broadcast delays, d the chord between the signals' pierce points on
  the thin shell 350 km up (the geometry the broadcast model uses; ``pierce_chord_km``) and
  L = ``IONO_CORRELATION_LENGTH_KM`` (docs/gnss-errors.md). Signals close in the sky share
  their residual, which the clock and the height then take: taken as independent, the field
  made the receiver's horizontal 1-sigma 1.5-2.4 times the rms horizontal error over twenty
  seeds of two open-sky drives (the field's independent model 2.6 m^2 north against 0.84 m^2
  realised on the quickstart, 1.2 m^2 with this covariance).
* ``range_error_budget``: a fix's user range error, split by time behaviour (Kaplan & Hegarty
  2017, section 10.2; Misra & Enge 2011, section 6.1: a fix's 1-sigma is DOP x UERE):

  - correlated over the drive (``RangeErrorBudget.correlated_m``): signal in space
    (``sis_error``), the ionosphere's residual and the troposphere's (``tropo_residual``, the
    zenith error in m, times the mapping at 30 deg elevation, 2). The ionosphere term is the
    two fractions added (not in quadrature: the common part keeps one sign over a drive and
    the field is correlated over 1000 km, so on the satellites of one fix they add; a bound)
    times ``KLOBUCHAR_NIGHT_SLANT_M``, the broadcast model's night-time vertical delay of 5 ns
    (IS-GPS-200 20.3.3.5.2.5, its smallest value) at the obliquity of 30 deg elevation, 1.77:
    the part of the day's slant delay (3.9-8.2 m, 5-95 %, on the quickstart) that is not
    absorbed by the receiver clock. Checked against the simulated fixes (the ensemble over
    seeds 1-20 of the fix error at each epoch after 60 s, per unit DOP, HDOP / sqrt(2) per
    horizontal axis): the quickstart 1.35 m north, 1.22 m east, 1.80 m down,
    ``benchmarks/consistency/open_road.yaml`` 1.21, 1.18 and 2.16 m; this budget gives 2.2 m
    for the automotive preset, on every axis. The horizontal axes do not see the common part
    |scale - 1| (0.02 m^2 north and east against 9.4 m^2 down on the quickstart), but a
    budget of the field alone at the night floor (0.95 m) was below these midday drives'
    horizontal error, and the filters that take the fix's reported accuracy beyond the budget
    as short-lived went overconfident on their seeds of large drive-long error (docs/scores.md,
    "The ionosphere field's correlation"); the budget cannot know the hour, the fix's report
    (``simulator.gnss.fix``) does.
  - code tracking noise (``tracking_noise``, lowered by the Hatch filter to 1 / sqrt(2N - 1),
    N = ``carrier_smoothing`` x ``rate`` epochs) and code multipath (``multipath``), correlated
    over the carrier-smoothing time (``RangeErrorBudget.smoothed_m``).

* ``fix_uere_m``: the root sum square of the two, the one number of a ROS fix covariance.
* ``cn0_template``: the C/N0 a direct signal has at each elevation (the receiver and antenna's
  nominal ``cn0_zenith`` and ``cn0_horizon``, ``nominal_cn0_dbhz``) and the scatter of a
  direct signal's reported C/N0 about it (``cn0_fading`` and ``cn0_noise`` in quadrature): the
  template a user calibrates on open sky, against which a reflected or diffracted signal
  shows its loss (Brunner, Hartinger & Troyer 1999, the SIGMA-Delta model).
* ``nlos_probability``: the probability that a signal is reflected (NLOS) given its C/N0
  deficit D below the template, by Bayes' rule: a direct signal's deficit N(0, s^2) (s the
  template's scatter), a reflection's N(11 dB, (4.5 dB)^2) (the reflections of
  ``scenarios/urban_canyon.yaml``, seed 1: 4-18 dB, 5-95 %, the facade and depolarisation
  losses of ``simulator.environment.sky``), and as prior the share of the epoch's signals whose
  deficit is over 3 s (which no direct signal reaches but once in 700), at least 1 %: in a
  street whose reflections show, a signal of moderate deficit is likely one too; on open sky a
  faded direct signal keeps its weight. Groves 2013, chapter 10: NLOS reception and its
  detection by C/N0. Read by the receiver's own accuracy (``simulator.gnss.fix``) and by
  ``gnss_wls``.
* ``nlos_delay_moments``: the first two moments of a signal's delay from its probability p
  of being reflected, the delay p-Bernoulli times an extra path d ~ N(mu, s^2)
  (``NLOS_EXTRA_PATH_MEAN_M``, ``NLOS_EXTRA_PATH_SIGMA_M``): mean p mu, variance
  p (mu^2 + s^2) - (p mu)^2. An extra path is never negative, so the mean matters:
  reflections from the two sides of a street cancel across it and add up in the height and
  the clock. Read by the receiver's own accuracy (``simulator.gnss.fix``) and by
  ``fgo_tc`` (``toolbox.gnss_model.nlos_delay``).

Public names
------------
iono_residual_fractions, iono_field_covariance, pierce_angle_sc, pierce_chord_km, RangeErrorBudget,
range_error_budget, fix_uere_m, Cn0Template, cn0_template, nominal_cn0_dbhz, nlos_probability,
nlos_delay_moments, NLOS_EXTRA_PATH_MEAN_M, NLOS_EXTRA_PATH_SIGMA_M, KLOBUCHAR_NIGHT_SLANT_M,
TROPO_MAPPING_30_DEG, IONO_FIELD_OWN_SHARE, IONO_CORRELATION_LENGTH_KM, IONO_SHELL_HEIGHT_KM,
EARTH_MEAN_RADIUS_KM, CN0_ELEVATION_SCALE_DEG.

References
----------
Brunner, Hartinger & Troyer, "GPS signal diffraction modelling: the stochastic SIGMA-Delta
model", Journal of Geodesy 73, 259-267, 1999.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

C_M_S = 299_792_458.0  # speed of light, m/s
KLOBUCHAR_NIGHT_SLANT_M = 5e-9 * C_M_S * 1.77  # the broadcast model's night floor at 30 deg, m
TROPO_MAPPING_30_DEG = 2.0  # slant / zenith troposphere at 30 deg elevation (1 / sin 30 deg)
IONO_FIELD_OWN_SHARE = 0.5  # the share of the field's 1-sigma that differs between satellites
IONO_CORRELATION_LENGTH_KM = 1000.0  # L of the field's correlation exp(-d^2 / (2 L^2))
IONO_SHELL_HEIGHT_KM = 350.0  # the broadcast (Klobuchar) model's thin shell
EARTH_MEAN_RADIUS_KM = 6371.0
CN0_ELEVATION_SCALE_DEG = 17.0  # e-folding elevation of the C/N0 loss towards the horizon
# a reflected signal's C/N0 deficit below the direct-signal template, dB: mean and 1-sigma
NLOS_DEFICIT_MEAN_DB = 11.0
NLOS_DEFICIT_SIGMA_DB = 4.5
CLEAR_NLOS_SIGMAS = 3.0  # a deficit over this many direct-signal scatters: clearly reflected
OPEN_SKY_NLOS_SHARE = 0.01  # the prior share of reflections in an epoch with none clear
# a receiver's model of a reflected signal's extra path, m: the extra paths of
# scenarios/urban_canyon.yaml, seed 1 (mean 15.7 m, 1-sigma 5.9 m; 8-27 m, 5-95 %), the
# spread widened to 8 m for streets of other widths
NLOS_EXTRA_PATH_MEAN_M = 15.0
NLOS_EXTRA_PATH_SIGMA_M = 8.0


def _value(gnss: Mapping[str, Any], key: str, default: float = 0.0) -> float:
    v = gnss.get(key)
    return default if v is None else float(v)


def iono_residual_fractions(gnss: Mapping[str, Any]) -> tuple[float, float]:
    """The broadcast ionosphere's residual as fractions of the broadcast delay (module
    docstring): the part common to the satellites, |scale - 1|, and the field's 1-sigma,
    scale residual; (0, 0) for a receiver block without ``iono_scale`` (the model exact)."""
    scale = _value(gnss, "iono_scale", 1.0)
    return abs(scale - 1.0), scale * _value(gnss, "iono_residual")


def pierce_angle_sc(elevation_rad: np.ndarray) -> np.ndarray:
    """Earth-centred angle (semicircles) from the receiver to a signal's ionospheric pierce
    point, the broadcast model's approximation of the thin shell ``IONO_SHELL_HEIGHT_KM`` up:
    psi = 0.0137 / (E + 0.11) - 0.022, E the elevation in semicircles (IS-GPS-200, Figure 20-4).
    The one home of the pierce-point geometry: the simulator's ionosphere, the receiver's
    accuracy and ``fgo_tc``'s field variables all read it."""
    el_sc = np.asarray(elevation_rad, dtype=float) / np.pi
    return 0.0137 / (el_sc + 0.11) - 0.022


def pierce_chord_km(azimuth_rad: np.ndarray, elevation_rad: np.ndarray) -> np.ndarray:
    """Chord (km) between the pierce points of each pair of signals on the thin shell
    ``IONO_SHELL_HEIGHT_KM`` up: shape (..., k, k) for signals along the last axis. Each pierce
    point lies ``pierce_angle_sc`` psi of Earth-central angle from the receiver towards the
    signal's azimuth; the angle c between two follows from the spherical law of cosines, cos c
    = cos psi_i cos psi_j + sin psi_i sin psi_j cos(az_i - az_j), and the chord is
    2 (R + h) sin(c / 2)."""
    az = np.asarray(azimuth_rad, dtype=float)
    shell = EARTH_MEAN_RADIUS_KM + IONO_SHELL_HEIGHT_KM
    psi = np.pi * pierce_angle_sc(np.clip(np.asarray(elevation_rad, dtype=float), 0.0, None))
    cos_c = (np.cos(psi)[..., :, None] * np.cos(psi)[..., None, :]
             + np.sin(psi)[..., :, None] * np.sin(psi)[..., None, :]
             * np.cos(az[..., :, None] - az[..., None, :]))
    return 2.0 * shell * np.sin(0.5 * np.arccos(np.clip(cos_c, -1.0, 1.0)))


def iono_field_covariance(field: float, iono_m: np.ndarray, azimuth_rad: np.ndarray,
                          elevation_rad: np.ndarray) -> np.ndarray:
    """The ionosphere field's part of one epoch's pseudorange errors as their covariance
    (module docstring), shape (..., k, k) for signals along the last axis: (f I_i)(f I_j)
    exp(-d_ij^2 / (2 L^2)), ``field`` f (``iono_residual_fractions``' second), ``iono_m`` I
    the broadcast delays (0 where a slot holds no signal), d ``pierce_chord_km``."""
    scaled = field * np.nan_to_num(np.asarray(iono_m, dtype=float))
    chord = pierce_chord_km(np.nan_to_num(azimuth_rad), np.nan_to_num(elevation_rad))
    correlation = np.exp(-0.5 * (chord / IONO_CORRELATION_LENGTH_KM) ** 2)
    return scaled[..., :, None] * scaled[..., None, :] * correlation


@dataclass(frozen=True)
class RangeErrorBudget:
    """A receiver's user range error, m, by time behaviour (module docstring): ``sis``,
    ``ionosphere`` and ``troposphere`` stay over a drive; ``smoothed`` (code noise after the
    Hatch filter, and multipath) is correlated over ``smoothing_s`` (0: white at the fix
    rate)."""

    sis: float
    ionosphere: float
    troposphere: float
    smoothed: float
    smoothing_s: float

    def correlated_m(self, ionosphere: bool = True) -> float:
        """The drive-long part, m; ``ionosphere=False`` without the ionosphere."""
        return math.sqrt(self.sis**2 + (self.ionosphere * ionosphere) ** 2
                         + self.troposphere**2)


def range_error_budget(gnss: Mapping[str, Any]) -> RangeErrorBudget:
    """The range error budget (module docstring) of a datasheet's ``gnss`` block; 0 for what it
    does not give (an ``ideal`` receiver)."""
    common, field = iono_residual_fractions(gnss)
    smoothing = _value(gnss, "carrier_smoothing")
    epochs = max(smoothing * _value(gnss, "rate", 1.0), 1.0)
    noise = _value(gnss, "tracking_noise") / math.sqrt(2.0 * epochs - 1.0)
    return RangeErrorBudget(sis=_value(gnss, "sis_error"),
                            ionosphere=(common + field) * KLOBUCHAR_NIGHT_SLANT_M,
                            troposphere=_value(gnss, "tropo_residual") * TROPO_MAPPING_30_DEG,
                            smoothed=math.hypot(noise, _value(gnss, "multipath")),
                            smoothing_s=smoothing)


def fix_uere_m(gnss: Mapping[str, Any], ionosphere: bool = True) -> float:
    """User equivalent range error (m, 1-sigma) of a receiver datasheet block: the budget's
    correlated and smoothed parts in quadrature (module docstring); 0 for an ideal receiver.
    ``ionosphere=False`` leaves the ionosphere out."""
    budget = range_error_budget(gnss)
    return math.hypot(budget.correlated_m(ionosphere), budget.smoothed)


def nominal_cn0_dbhz(elevation_rad: np.ndarray, zenith_dbhz: float, horizon_dbhz: float
                     ) -> np.ndarray:
    """A direct signal's carrier-to-noise density, dB-Hz, from the antenna gain pattern and the
    path through the atmosphere: zenith - (zenith - horizon) exp(-el / 17 deg) (the shape
    fitted to the ARL1 station's L1 C/N0, ``simulator.gnss.receiver.cn0_model``)."""
    el_deg = np.degrees(np.clip(elevation_rad, 0, None))
    return zenith_dbhz - (zenith_dbhz - horizon_dbhz) * np.exp(-el_deg / CN0_ELEVATION_SCALE_DEG)


@dataclass(frozen=True)
class Cn0Template:
    """A receiver's C/N0 of direct signals against elevation and their scatter about it, dB."""

    zenith_dbhz: float
    horizon_dbhz: float
    scatter_db: float

    def expected_dbhz(self, elevation_rad: np.ndarray) -> np.ndarray:
        """The C/N0 of a direct signal at ``elevation_rad``, dB-Hz."""
        return nominal_cn0_dbhz(elevation_rad, self.zenith_dbhz, self.horizon_dbhz)


def cn0_template(gnss: Mapping[str, Any]) -> Cn0Template | None:
    """The C/N0 template of a receiver block (module docstring); None when it has no
    ``cn0_zenith`` and ``cn0_horizon`` (a real recording's receiver)."""
    if gnss.get("cn0_zenith") is None or gnss.get("cn0_horizon") is None:
        return None
    return Cn0Template(float(gnss["cn0_zenith"]), float(gnss["cn0_horizon"]),
                       math.hypot(_value(gnss, "cn0_fading"), _value(gnss, "cn0_noise")))


def nlos_probability(deficit_db: np.ndarray, scatter_db: float) -> np.ndarray:
    """The probability that each signal is reflected (NLOS) given its C/N0 ``deficit_db`` below
    the direct-signal template (module docstring): Bayes' rule with a direct signal's deficit
    N(0, ``scatter_db``^2), a reflection's N(``NLOS_DEFICIT_MEAN_DB``,
    ``NLOS_DEFICIT_SIGMA_DB``^2), and the epoch's prior share of reflections: the share of its
    signals whose deficit no direct signal reaches (over ``CLEAR_NLOS_SIGMAS`` scatters), at
    least ``OPEN_SKY_NLOS_SHARE``. The last axis holds one epoch's signals (an array of shape
    (epochs, signals) gives each epoch its own prior); 0 where the deficit is not finite (no
    signal)."""
    # imported here: scipy.stats is a second of every process's start-up, only this needs it
    from scipy.stats import norm

    deficit = np.asarray(deficit_db, dtype=float)
    finite = np.isfinite(deficit)
    d = np.where(finite, deficit, 0.0)
    scatter = max(scatter_db, 0.1)
    clear = np.count_nonzero(finite & (d > CLEAR_NLOS_SIGMAS * scatter), axis=-1)
    share = clear / np.maximum(np.count_nonzero(finite, axis=-1), 1)
    prior = np.maximum(share, OPEN_SKY_NLOS_SHARE)[..., None]
    direct = (1.0 - prior) * norm.pdf(d, 0.0, scatter)
    reflected = prior * norm.pdf(d, NLOS_DEFICIT_MEAN_DB, NLOS_DEFICIT_SIGMA_DB)
    return np.where(finite, reflected / np.maximum(direct + reflected, 1e-300), 0.0)


def nlos_delay_moments(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The mean (m) and mean square (m^2) of the delay of signals reflected with probability
    ``p`` (module docstring): p-Bernoulli times an extra path N(``NLOS_EXTRA_PATH_MEAN_M``,
    ``NLOS_EXTRA_PATH_SIGMA_M``^2); its variance is the mean square minus the mean's square."""
    mean = p * NLOS_EXTRA_PATH_MEAN_M
    return mean, p * (NLOS_EXTRA_PATH_MEAN_M**2 + NLOS_EXTRA_PATH_SIGMA_M**2)
