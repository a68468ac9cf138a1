"""The receiver's own navigation solution from its raw measurements: weighted least-squares
position and clock bias from pseudoranges, velocity and clock drift from pseudorange rates,
dilutions of precision, fix type (3D with four or more satellites; 2D with three, the height
held at the last 3D fix's; none otherwise), speed and course, the fix's own accuracy (1-sigma
per NED axis of position and velocity, as a receiver reports it); optionally the smoothed
(filtered) output of low-cost receivers.

The reported accuracy is what the receiver can know of its error, never the error itself: the
mean squared error of its weighted least squares, G E[e e^T] G^T with G = (H^T W H)^-1 H^T W
(the weights W it solved with) and E[e e^T] its model of the measurement errors' second
moments (Kaplan & Hegarty 2017, section 11.2.1; Groves 2013, section 9.4.3, with the
covariance of the errors in place of a unit-variance one), scaled up by the a-posteriori
variance factor where the residuals show more than the model (below). The model of the
errors, from what the receiver measures itself:

* each measurement's own 1-sigma (``pseudorange_std``, ``pseudorange_rate_std``: its C/N0,
  elevation and error budget), independent between satellites, but for
* the broadcast ionosphere's residual common to the epoch's satellites, c I_i (c the
  receiver's |iono_scale - 1|, ``simulator.datasheet.iono_residual_fractions``, I_i each
  satellite's broadcast delay): a rank-one term taken out of the diagonal (it goes mostly
  into the clock and the height, as in ``gnss_wls``);
* the ionosphere field's residual, f I_i (f the field's 1-sigma fraction), correlated between
  the satellites by their pierce points' separation (``simulator.datasheet.
  iono_field_covariance``), also taken out of the diagonal: signals close in the sky share it,
  so it too goes mostly into the clock and the height (taken as independent, it made the
  horizontal 1-sigma 1.5-2.4 times the rms error over twenty seeds of two open-sky drives);
* reflected (NLOS) signals, announced by their C/N0 deficit below the receiver's direct-signal
  template (``simulator.datasheet.cn0_template``): with p_i the probability that signal i is
  reflected (``simulator.datasheet.nlos_probability``) and its extra path d ~ N(mu, s^2)
  (``simulator.datasheet.nlos_delay_moments``), the delay p_i-Bernoulli times d has mean
  p_i mu and variance p_i (mu^2 + s^2) - (p_i mu)^2. The mean is kept, as a second
  rank-one term: an extra path is never negative, so reflections from the two sides of a
  street cancel across it and add up in the height (the fix sinks, as the simulated canyons'
  fixes do by 10-40 m).

The a-posteriori variance factor k = r^T W r / E[r^T W r] (the residuals' weighted sum of
squares against its expectation under the model, Koch 1999, *Parameter Estimation and
Hypothesis Testing in Linear Models*, chapter 3) scales the covariance where it exceeds 1,
as a receiver's RAIM does (the residuals' RMS that NMEA's GST sentence reports); never below
(a redundancy of a few satellites makes k a chi-square draw of few degrees of freedom, and
the residuals cannot see an error the solution absorbs). A 2D fix reports no vertical
accuracy (NaN); its held height is an equation of the variance of the last 3D fix's height.
A smoothed output reports its inputs' accuracy passed through the same first-order filter
(linear in the 1-sigma: the bound of an error correlated over the filter's time).

All epochs are solved at once: measurements are packed into (epoch, slot) arrays with a mask,
and a fixed number of Gauss-Newton iterations runs as batched 4 x 4 linear algebra.

Public functions
----------------
pack_epochs, solve_position, solve_velocity, dilution_of_precision, smooth_positions,
primary_rows, receiver_fixes, AccuracyModel, least_squares_accuracy.

References
----------
Groves 2013, section 9.4.1 (single-epoch least-squares position and velocity, eqs. 9.126-9.146,
Sagnac rotation in the range model) and section 9.4.3 (DOP from the NED geometry matrix);
Kaplan & Hegarty 2017, section 11.2.1 (weighted least squares).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from simulator import columns as col
from simulator.datasheet import (
    Cn0Template,
    cn0_template,
    iono_field_covariance,
    iono_residual_fractions,
    nlos_delay_moments,
    nlos_probability,
)
from simulator.earth import ecef_to_geodetic, ned_to_ecef_matrix
from simulator.gnss.chunks import epoch_chunks
from simulator.gnss.constants import C_M_S
from simulator.gnss.receiver import light_time_factor, rotate_to_reception_frame
from simulator.gnss.signals import PRIMARY_SIGNAL
from simulator.stochastic import ar1_filter

if TYPE_CHECKING:
    import pandas as pd

_GAUSS_NEWTON_ITERATIONS = 10  # from the Earth's centre: converged to < 1e-6 m after 7
_MAX_CONDITION = 1e12  # a normal matrix beyond this is singular in float64 (no fix)
# epochs whose accuracies are computed together: their epochs x satellites x satellites arrays
# (the ionosphere field's covariance) stay a few megabytes
FIX_CHUNK_EPOCHS = 512


def pack_epochs(epoch: np.ndarray, n_epochs: int, *values: np.ndarray
                ) -> tuple[np.ndarray, list[np.ndarray]]:
    """Scatter per-measurement values into (n_epochs, max per epoch, ...) arrays.

    Parameters
    ----------
    epoch : ndarray of int, shape (m,)
        Epoch index of each measurement, sorted ascending.
    values : ndarrays of shape (m, ...)

    Returns
    -------
    mask : ndarray of bool, shape (n_epochs, k)
    packed : list of ndarrays, shape (n_epochs, k, ...), zero where masked.
    """
    epoch = np.asarray(epoch, dtype=int)
    counts = np.bincount(epoch, minlength=n_epochs)
    k = max(int(counts.max(initial=0)), 1)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    slot = np.arange(len(epoch)) - start[epoch]
    mask = np.zeros((n_epochs, k), dtype=bool)
    mask[epoch, slot] = True
    packed = []
    for v in values:
        out = np.zeros((n_epochs, k) + v.shape[1:])
        out[epoch, slot] = v
        packed.append(out)
    return mask, packed


def _solve(normal: np.ndarray, rhs: np.ndarray, ok: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray]:
    """Batched solve of normal equations. Epochs not ``ok``, or whose system is numerically
    singular (condition number above ``_MAX_CONDITION``: satellites in a degenerate geometry,
    or an iteration gone far from the Earth), get an identity system and come back not
    solvable. Returns the solutions and the solvable flags."""
    eye = np.eye(normal.shape[-1])
    normal = np.where(ok[:, None, None], normal, eye)
    solvable = ok & (np.linalg.cond(normal) < _MAX_CONDITION)
    normal = np.where(solvable[:, None, None], normal, eye)
    return np.linalg.solve(normal, rhs[..., None])[..., 0], solvable


def _up_ecef(pos_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Ellipsoidal height and the unit up vector (ellipsoid normal) in ECEF at positions."""
    lat, lon, alt = ecef_to_geodetic(pos_m)
    up = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=-1)
    return alt, up


def solve_position(pr_m: np.ndarray, sat_pos_m: np.ndarray, weight: np.ndarray,
                   mask: np.ndarray, height_m: np.ndarray | None = None,
                   start_m: np.ndarray | None = None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weighted least-squares antenna position and receiver clock from corrected pseudoranges.

    Model (Groves eq. 9.126 with 8.36): pr = |R(omega_e tau) r_s - r| + c dt_r, tau = range / c,
    with r_s at transmission in the ECEF frame of transmission. Where ``height_m`` is given
    (finite) the ellipsoidal height is held at that value by one more equation, so three
    satellites give a 2D fix (Kaplan & Hegarty section 11.2.2, altitude hold).

    Parameters
    ----------
    pr_m : ndarray, shape (n, k)
        Pseudorange + satellite clock - broadcast iono - broadcast tropo, m.
    sat_pos_m : ndarray, shape (n, k, 3)
    weight : ndarray, shape (n, k)
        1 / sigma^2 of each pseudorange (0 where masked).
    mask : ndarray of bool, shape (n, k)
    height_m : ndarray, shape (n,), optional
        Height to hold (NaN: none), m.
    start_m : ndarray, shape (n, 3), optional
        Starting positions (default: the Earth's centre; needed where a height is held).

    Returns
    -------
    pos_m : ndarray, shape (n, 3) (NaN where not solvable)
    clock_m : ndarray, shape (n,), c dt_r
    ok : ndarray of bool, shape (n,): at least 4 equations
    """
    n = pr_m.shape[0]
    held = np.zeros(n, dtype=bool) if height_m is None else np.isfinite(height_m)
    ok = mask.sum(axis=1) + held >= 4
    w = np.where(mask, weight, 0.0)
    x = np.zeros((n, 4))
    if start_m is not None:
        x[:, :3] = np.where(np.isfinite(start_m), start_m, 0.0)
    for _ in range(_GAUSS_NEWTON_ITERATIONS):
        rng, los = _geometry(sat_pos_m, x[:, :3])
        h = np.concatenate([-los, np.ones(rng.shape + (1,))], axis=-1)
        resid = np.where(mask, pr_m - rng - x[:, 3:4], 0.0)
        hw = h * w[..., None]
        normal = np.einsum("nki,nkj->nij", hw, h)
        rhs = np.einsum("nki,nk->ni", hw, resid)
        if held.any():
            alt, up = _up_ecef(x[held, :3])
            row = np.concatenate([up, np.zeros((len(up), 1))], axis=1)
            normal[held] += row[:, :, None] * row[:, None, :]
            rhs[held] += row * (height_m[held] - alt)[:, None]
        dx, ok = _solve(normal, rhs, ok)
        x = x + np.where(ok[:, None], dx, 0.0)
    pos = np.where(ok[:, None], x[:, :3], np.nan)
    return pos, np.where(ok, x[:, 3], np.nan), ok


def _geometry(sat_pos_m: np.ndarray, rx_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Range (with the Sagnac rotation) and unit line of sight from receiver to satellite."""
    rel = sat_pos_m - rx_m[:, None, :]
    tau = np.linalg.norm(rel, axis=-1) / C_M_S
    rel = rotate_to_reception_frame(sat_pos_m, tau) - rx_m[:, None, :]
    rng = np.linalg.norm(rel, axis=-1)
    return rng, rel / np.where(rng > 0, rng, 1.0)[..., None]


def solve_velocity(rate_m_s: np.ndarray, sat_pos_m: np.ndarray, sat_vel_m_s: np.ndarray,
                   pos_m: np.ndarray, weight: np.ndarray, mask: np.ndarray,
                   held: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Weighted least-squares ECEF velocity and clock drift (c d(dt_r)/dt, m/s) from pseudorange
    rates corrected for the satellite clock drift (Groves eq. 9.141):
    rate = los . (v_s - v) / f + c d(dt_r)/dt, with v_s rotated into the frame of reception and
    f = ``light_time_factor`` (the exact light-time derivative; 1 - f is about 1e-5).
    Epochs flagged ``held`` (2D fixes) add the equation "no vertical velocity"."""
    held = np.zeros(len(pos_m), dtype=bool) if held is None else held
    ok = (mask.sum(axis=1) + held >= 4) & np.isfinite(pos_m).all(axis=1)
    rx = np.where(ok[:, None], pos_m, 0.0)
    rng, los = _geometry(sat_pos_m, rx)
    vs = rotate_to_reception_frame(sat_vel_m_s, rng / C_M_S)
    factor = light_time_factor(los, sat_pos_m, vs, rng / C_M_S)
    y = np.where(mask, rate_m_s * factor - np.einsum("nki,nki->nk", los, vs), 0.0)
    h = np.concatenate([-los, factor[..., None]], axis=-1)
    hw = h * np.where(mask, weight, 0.0)[..., None]
    normal = np.einsum("nki,nkj->nij", hw, h)
    held = held & ok
    if held.any():
        _, up = _up_ecef(rx[held])
        row = np.concatenate([up, np.zeros((len(up), 1))], axis=1)
        normal[held] += row[:, :, None] * row[:, None, :]
    x, ok = _solve(normal, np.einsum("nki,nk->ni", hw, y), ok)
    x = np.where(ok[:, None], x, np.nan)
    return x[:, :3], x[:, 3]


def _ned_design(sat_pos_m: np.ndarray, pos_m: np.ndarray, mask: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """The geometry matrix in local NED, rows [-los_ned, 1] (zero where masked), and the epochs
    with a finite position."""
    ok = np.isfinite(pos_m).all(axis=1)
    rx = np.where(ok[:, None], pos_m, np.array([1.0, 0.0, 0.0]) * 6.4e6)
    _, los = _geometry(sat_pos_m, rx)
    lat, lon, _ = ecef_to_geodetic(rx)
    c_ne = ned_to_ecef_matrix(lat, lon)
    los_ned = np.einsum("nji,nkj->nki", c_ne, los)
    return np.concatenate([-los_ned, np.ones(mask.shape + (1,))], axis=-1) * mask[..., None], ok


def dilution_of_precision(sat_pos_m: np.ndarray, pos_m: np.ndarray, mask: np.ndarray,
                          held: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """HDOP and VDOP from the unweighted geometry matrix in local NED (Groves eq. 9.91).

    For 2D fixes (``held``) the held height enters as one more unit row on the down axis, and
    VDOP is NaN (there is no vertical solution)."""
    held = np.zeros(len(pos_m), dtype=bool) if held is None else held
    h, finite = _ned_design(sat_pos_m, pos_m, mask)
    ok = (mask.sum(axis=1) + held >= 4) & finite
    normal = np.einsum("nki,nkj->nij", h, h)
    normal[:, 2, 2] += held
    normal = np.where(ok[:, None, None], normal, np.eye(4))
    g = np.linalg.inv(normal)
    hdop = np.sqrt(g[:, 0, 0] + g[:, 1, 1])
    vdop = np.sqrt(g[:, 2, 2])
    return np.where(ok, hdop, np.nan), np.where(ok & ~held, vdop, np.nan)


@dataclass(frozen=True)
class AccuracyModel:
    """What a receiver knows of its measurements' errors beyond each one's reported 1-sigma
    (module docstring): its C/N0 template for direct signals (None: no reflection is
    recognised) and the share of each broadcast ionosphere delay common to an epoch."""

    template: Cn0Template | None = None
    iono_common: float = 0.0
    iono_field: float = 0.0

    @classmethod
    def of_receiver(cls, receiver: Mapping[str, Any] | None) -> AccuracyModel:
        """The model of a receiver's configuration block (``sensors.gnss``, or the datasheet's
        ``gnss``); None: the reported 1-sigmas alone."""
        if not receiver:
            return cls()
        return cls(cn0_template(receiver), *iono_residual_fractions(receiver))

    def range_errors(self, sigma_m: np.ndarray, cn0_dbhz: np.ndarray, elevation_rad: np.ndarray,
                     azimuth_rad: np.ndarray, iono_m: np.ndarray, mask: np.ndarray
                     ) -> tuple[np.ndarray, list[np.ndarray], np.ndarray | None]:
        """The second moments of the pseudorange errors of (epoch, slot) arrays as a diagonal
        (the independent variances), rank-one terms c c^T (the common ionosphere, the
        reflections' mean delay) and the ionosphere field's covariance between the slots
        (epoch, slot, slot; None without a field), module docstring."""
        iono = np.where(mask, np.nan_to_num(iono_m), 0.0)
        common = self.iono_common * iono
        field = None
        if self.iono_field > 0:
            field = iono_field_covariance(self.iono_field, iono, azimuth_rad, elevation_rad)
        own_field = (self.iono_field * iono) ** 2
        variance = np.maximum(sigma_m**2 - common**2 - own_field, 0.0)
        terms = [common]
        if self.template is not None:
            deficit = np.where(mask, self.template.expected_dbhz(elevation_rad) - cn0_dbhz,
                               np.nan)
            p = nlos_probability(deficit, self.template.scatter_db)
            mean, mean_square = nlos_delay_moments(p)
            variance = variance + mean_square - mean**2
            terms.append(mean)
        return np.where(mask, variance, 0.0), terms, field


def least_squares_accuracy(h: np.ndarray, weight: np.ndarray, variance: np.ndarray,
                           common: list[np.ndarray], residual: np.ndarray,
                           correlated: np.ndarray | None = None
                           ) -> tuple[np.ndarray, np.ndarray]:
    """Per epoch, the mean squared error of the weighted least-squares estimate and the
    a-posteriori variance factor (module docstring).

    Parameters
    ----------
    h : ndarray, shape (n, k, p)
        Geometry matrix (zero rows where masked).
    weight : ndarray, shape (n, k)
        The weights solved with (0 where masked).
    variance, common : ndarray, shape (n, k); list of them
        The errors' second moments diag(variance) + sum c c^T (+ ``correlated``).
    residual : ndarray, shape (n, k)
        Post-fit residuals.
    correlated : ndarray, shape (n, k, k), optional
        A further covariance between the measurements (the ionosphere field's).

    Returns
    -------
    cov : ndarray, shape (n, p, p)
        G (diag(variance) + sum c c^T + correlated) G^T, G = (H^T W H)^-1 H^T W; identity
        where H^T W H is singular.
    factor : ndarray, shape (n,)
        r^T W r / E[r^T W r] (1 without redundancy).
    """
    n, k, p = h.shape
    normal = np.einsum("nki,nk,nkj->nij", h, weight, h)
    solvable = np.linalg.cond(normal) < _MAX_CONDITION
    inverse = np.linalg.inv(np.where(solvable[:, None, None], normal, np.eye(p)))
    gain = np.einsum("nij,nkj,nk->nik", inverse, h, weight)
    cov = np.einsum("nik,nk,njk->nij", gain, variance, gain)
    to_residual = np.eye(k) - np.einsum("nki,nij->nkj", h, gain)  # r = (I - H G) e
    expected = np.einsum("nk,nka,na->n", weight, to_residual**2, variance)
    for c in common:
        b = np.einsum("nik,nk->ni", gain, c)
        cov += b[:, :, None] * b[:, None, :]
        expected += np.einsum("nk,nk->n", weight, np.einsum("nka,na->nk", to_residual, c) ** 2)
    if correlated is not None:
        cov += np.einsum("nik,nkl,njl->nij", gain, correlated, gain)
        expected += np.einsum("nk,nka,nab,nkb->n", weight, to_residual, correlated, to_residual)
    observed = np.einsum("nk,nk->n", weight, residual**2)
    redundant = (weight > 0).sum(axis=1) > p
    factor = np.where(redundant & (expected > 0), observed / np.where(expected > 0, expected, 1),
                      1.0)
    return np.where(solvable[:, None, None], cov, np.eye(p)), factor


def _stretches(valid: np.ndarray) -> list[tuple[int, int]]:
    """[start, stop) of each run of True in ``valid``."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], valid.astype(int), [0]])))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True))


def smooth_positions(pos_m: np.ndarray, vel_m_s: np.ndarray, dt_s: float,
                     time_constant_s: float) -> np.ndarray:
    """Velocity-aided first-order smoothing of fixes, as low-cost receivers filter their output:
    p_k = q_k + alpha (z_k - q_k) with the prediction q_k = p_{k-1} + (v_{k-1} + v_k) dt / 2
    (trapezoidal, so a turn or an acceleration does not make the output lag) and
    alpha = dt / (time_constant + dt); the filter restarts after every epoch without a fix."""
    alpha = dt_s / (time_constant_s + dt_s)
    out = np.full_like(pos_m, np.nan)
    valid = np.isfinite(pos_m).all(axis=1) & np.isfinite(vel_m_s).all(axis=1)
    for start, stop in _stretches(valid):  # one pass per fix stretch
        z = pos_m[start:stop]
        v = vel_m_s[start:stop]
        step = np.concatenate([np.zeros((1, 3)), 0.5 * (v[1:] + v[:-1]) * dt_s])
        # p_k - (1 - alpha) p_{k-1} = alpha z_k + (1 - alpha) step_k, started at the first fix
        drive = alpha * z + (1.0 - alpha) * step
        drive[0] = z[0]
        out[start:stop] = ar1_filter(drive, 1.0 - alpha)
    return out


def smooth_accuracy(std: np.ndarray, dt_s: float, time_constant_s: float) -> np.ndarray:
    """The 1-sigma of ``smooth_positions``' output (columns of ``std``, restarted where a
    column is not finite): the same first-order filter on the 1-sigma, s_k = (1 - alpha)
    s_{k-1} + alpha sigma_k, the accuracy of an average of errors that are fully correlated
    (a bound: the filter lowers independent errors further)."""
    alpha = dt_s / (time_constant_s + dt_s)
    out = np.full_like(std, np.nan)
    for j in range(std.shape[1]):  # one pass per axis and stretch
        for start, stop in _stretches(np.isfinite(std[:, j])):
            drive = alpha * std[start:stop, j]
            drive[0] = std[start, j]
            out[start:stop, j] = ar1_filter(drive, 1.0 - alpha)
    return out


def primary_rows(raw: pd.DataFrame) -> pd.DataFrame:
    """The rows of each system's primary signal (all rows of a stream without ``signal``)."""
    if "signal" not in raw or "system" not in raw:
        return raw
    primary = raw["system"].map(PRIMARY_SIGNAL)
    return raw[(raw["signal"] == primary).to_numpy()]


def receiver_fixes(t: np.ndarray, raw: pd.DataFrame, smoothing_time_constant_s: float = 0.0,
                   dop_mask: float = np.inf, receiver: Mapping[str, Any] | None = None
                   ) -> pd.DataFrame:
    """The fix stream (``simulator.columns.GNSS_FIX``) at epochs t from the raw measurements.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Fix epochs, s; every raw row's ``t`` must be one of them.
    raw : pandas.DataFrame
        Rows of ``gnss_raw`` (with ``pseudorange_std`` and ``pseudorange_rate_std``); rows whose
        ``health`` is not 0 are left out, and with several signals only each system's primary
        one (``simulator.gnss.signals.PRIMARY_SIGNAL``: a single-frequency fix) is used.
    smoothing_time_constant_s : float
        0 for raw single-epoch fixes, else the time constant of ``smooth_positions``.
    dop_mask : float
        Largest HDOP a fix is given with, as receivers' DOP masks do (a receiver with three
        satellites near the zenith reports no fix rather than one hundreds of metres off).
    receiver : mapping, optional
        The receiver's configuration (``sensors.gnss``), for the model of its errors that its
        reported accuracy reads (``AccuracyModel.of_receiver``).
    """
    import pandas as pd

    n = len(t)
    if "health" in raw:  # an unhealthy satellite is tracked and reported, never used
        raw = raw[raw["health"].to_numpy() == 0]
    raw = primary_rows(raw)
    raw = raw.sort_values(["t", "sv"], kind="stable")
    epoch = np.searchsorted(t, raw["t"].to_numpy())
    sat_pos = raw[["sat_x", "sat_y", "sat_z"]].to_numpy()
    sat_vel = raw[["sat_vx", "sat_vy", "sat_vz"]].to_numpy()
    pr = (raw["pseudorange"] + raw["sat_clock"] - raw["iono"] - raw["tropo"]).to_numpy()
    rate = (raw["pseudorange_rate"] + raw["sat_clock_drift"]).to_numpy()
    sigma_pr = raw["pseudorange_std"].to_numpy()
    sigma_rate = raw["pseudorange_rate_std"].to_numpy()
    mask, (pr_p, pos_p, vel_p, rate_p, sigma_pr_p, sigma_rate_p, cn0_p, el_p, az_p, iono_p) = \
        pack_epochs(epoch, n, pr, sat_pos, sat_vel, rate, sigma_pr, sigma_rate,
                    raw["cn0"].to_numpy(), raw["elevation"].to_numpy(),
                    raw["azimuth"].to_numpy(), raw["iono"].to_numpy())
    w_pr_p = np.where(mask, 1.0 / np.where(mask, sigma_pr_p, 1.0) ** 2, 0.0)
    w_rate_p = np.where(mask, 1.0 / np.where(mask, sigma_rate_p, 1.0) ** 2, 0.0)
    pos, clock, ok = solve_position(pr_p, pos_p, w_pr_p, mask)
    # 2D fixes: three satellites, the height held at the last 3D fix's (causal)
    last = pd.DataFrame(np.where(ok[:, None], pos, np.nan)).ffill().to_numpy()
    last_alt = np.full(n, np.nan)
    known = np.isfinite(last).all(axis=1)
    last_alt[known] = ecef_to_geodetic(last[known])[2]
    held = (mask.sum(axis=1) == 3) & known
    if held.any():
        pos2, clock2, ok2 = solve_position(pr_p[held], pos_p[held], w_pr_p[held], mask[held],
                                           last_alt[held], last[held])
        pos[held], clock[held] = pos2, clock2
        held[held] = ok2
    vel, drift = solve_velocity(rate_p, pos_p, vel_p, pos, w_rate_p, mask, held)
    hdop, vdop = dilution_of_precision(pos_p, pos, mask, held)
    fix_type = np.where(ok, 2, np.where(held, 1, 0))
    fix_type[~(hdop <= dop_mask)] = 0
    ok = fix_type > 0
    model = AccuracyModel.of_receiver(receiver)

    def errors(epochs: slice | np.ndarray) -> tuple[np.ndarray, list[np.ndarray],
                                                   np.ndarray | None]:
        return model.range_errors(sigma_pr_p[epochs], cn0_p[epochs], el_p[epochs],
                                  az_p[epochs], iono_p[epochs], mask[epochs])

    std_pos, std_vel = _fix_accuracy(pos, clock, vel, drift, (pos_p, vel_p, pr_p, rate_p),
                                     (w_pr_p, w_rate_p), errors, mask, held, last_alt)
    if smoothing_time_constant_s > 0 and n > 1:
        dt_s = float(t[1] - t[0])
        pos = smooth_positions(pos, vel, dt_s, smoothing_time_constant_s)
        std_pos = smooth_accuracy(std_pos, dt_s, smoothing_time_constant_s)
    lat, lon, alt = ecef_to_geodetic(np.where(ok[:, None], pos, [6.4e6, 0.0, 0.0]))
    v_ned = np.einsum("nji,nj->ni", ned_to_ecef_matrix(lat, lon), np.nan_to_num(vel))
    nan = np.where(ok, 1.0, np.nan)
    v_ned = v_ned * nan[:, None]
    std_pos, std_vel = std_pos * nan[:, None], std_vel * nan[:, None]
    return pd.DataFrame({
        "t": t, "lat": np.degrees(lat) * nan, "lon": np.degrees(lon) * nan, "alt": alt * nan,
        "vn": v_ned[:, 0], "ve": v_ned[:, 1], "vd": v_ned[:, 2],
        "speed": np.hypot(v_ned[:, 0], v_ned[:, 1]),
        "course": np.mod(np.arctan2(v_ned[:, 1], v_ned[:, 0]), 2.0 * np.pi),
        "num_sats": mask.sum(axis=1), "hdop": hdop, "vdop": vdop,
        "fix": fix_type, "clock_bias": clock, "clock_drift": drift,
        "std_n": std_pos[:, 0], "std_e": std_pos[:, 1], "std_d": std_pos[:, 2],
        "std_vn": std_vel[:, 0], "std_ve": std_vel[:, 1], "std_vd": std_vel[:, 2],
    }, columns=list(col.GNSS_FIX))


def _fix_accuracy(pos: np.ndarray, clock: np.ndarray, vel: np.ndarray, drift: np.ndarray,
                  packed: tuple[np.ndarray, ...], weights: tuple[np.ndarray, np.ndarray],
                  errors: Callable[[slice | np.ndarray],
                                   tuple[np.ndarray, list[np.ndarray], np.ndarray | None]],
                  mask: np.ndarray,
                  held: np.ndarray, held_alt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The NED 1-sigma of each epoch's position and velocity (module docstring). A 2D fix's
    held height is one more equation of unit weight, as it was solved, whose error has the
    variance of the last 3D fix's height; its vertical accuracies are NaN. ``errors`` gives
    ``AccuracyModel.range_errors`` of some epochs: the accuracies are computed
    ``FIX_CHUNK_EPOCHS`` epochs at a time (``simulator.gnss.chunks``), since the ionosphere
    field's covariance and the residuals' map are epochs x satellites x satellites."""
    sat_pos, sat_vel, pr, rate = packed
    w_pr, w_rate = weights
    n = len(pos)
    h, finite = _ned_design(sat_pos, pos, mask)
    rx = np.where(finite[:, None], pos, 0.0)
    rng, los = _geometry(sat_pos, rx)
    alt = ecef_to_geodetic(np.where(finite[:, None], pos, [6.4e6, 0.0, 0.0]))[2]
    # the held height: one more row, on the down axis
    h = np.concatenate([h, np.zeros((n, 1, 4))], axis=1)
    h[held, -1, 2] = 1.0
    hold_weight = held.astype(float)[:, None]
    pr_residual = np.concatenate([np.where(mask, pr - rng - clock[:, None], 0.0),
                                  np.where(held, held_alt - alt, 0.0)[:, None]], axis=1)
    weight = np.concatenate([w_pr, hold_weight], axis=1)

    def position_sigma(epochs: slice | np.ndarray, hold_variance: np.ndarray) -> np.ndarray:
        variance, common, field = errors(epochs)
        hold = hold_variance[:, None]
        variance = np.concatenate([variance, hold], axis=1)
        common = [np.concatenate([c, np.zeros_like(hold)], axis=1) for c in common]
        if field is not None:  # the held height's row is correlated with no range
            field = np.pad(field, ((0, 0), (0, 1), (0, 1)))
        cov, factor = least_squares_accuracy(h[epochs], weight[epochs], variance, common,
                                             pr_residual[epochs], field)
        return _scaled_sigma(cov, factor)

    std_pos = np.empty((n, 3))
    for epochs in epoch_chunks(n, FIX_CHUNK_EPOCHS):  # one pass per chunk of epochs
        std_pos[epochs] = position_sigma(epochs, np.zeros(epochs.stop - epochs.start))
    if held.any():  # again with the held height's variance: the last 3D fix's
        import pandas as pd

        vertical = pd.Series(np.where(held, np.nan, std_pos[:, 2] ** 2)).ffill().to_numpy()
        at = np.flatnonzero(held)
        for part in epoch_chunks(len(at), FIX_CHUNK_EPOCHS):  # one pass per chunk of them
            epochs = at[part]
            std_pos[epochs] = position_sigma(epochs, np.nan_to_num(vertical[epochs]))
        std_pos[held, 2] = np.nan
    # velocity: y = rate f - los . v_s = -los . v + f drift (``solve_velocity``), f within
    # 1e-5 of 1 in the geometry
    vs = rotate_to_reception_frame(sat_vel, rng / C_M_S)
    f = light_time_factor(los, sat_pos, vs, rng / C_M_S)
    rate_residual = rate * f - np.einsum("nki,nki->nk", los, vs - np.nan_to_num(vel)[:, None])
    rate_residual = np.where(mask, rate_residual - f * drift[:, None], 0.0)
    rate_variance = np.where(mask, 1.0 / np.where(mask, w_rate, 1.0), 0.0)
    no_hold = np.zeros((n, 1))
    rate_weight = np.concatenate([w_rate, hold_weight], axis=1)
    rate_variance = np.concatenate([rate_variance, no_hold], axis=1)
    rate_residual = np.concatenate([rate_residual, no_hold], axis=1)
    std_vel = np.empty((n, 3))
    for epochs in epoch_chunks(n, FIX_CHUNK_EPOCHS):  # one pass per chunk of epochs
        cov, factor = least_squares_accuracy(h[epochs], rate_weight[epochs],
                                             rate_variance[epochs], [], rate_residual[epochs])
        std_vel[epochs] = _scaled_sigma(cov, factor)
    std_vel[held, 2] = np.nan
    return std_pos, std_vel


def _scaled_sigma(cov: np.ndarray, factor: np.ndarray) -> np.ndarray:
    """The 1-sigma of the first three axes of ``cov``, scaled by the variance factor where it
    exceeds 1."""
    diag = np.stack([cov[:, i, i] for i in range(3)], axis=1)
    return np.sqrt(diag * np.maximum(factor, 1.0)[:, None])
