"""``gnss_wls``: epoch-by-epoch weighted least squares on the raw pseudoranges and pseudorange
rates, the snapshot baseline of every pseudorange method (Misra & Enge, *Global Positioning
System*, 2nd ed., sections 6.1-6.2; Groves 2013, section 9.4.1).

Each epoch's corrected pseudoranges (``toolbox.gnss_model.raw_epoch``: broadcast satellite
clock, ionosphere and troposphere applied) give the antenna's ECEF position and one receiver
clock bias per satellite system and frequency band (the inter-system offsets, GLONASS's and
BeiDou's time systems, and a receiver's delay between bands) by Gauss-Newton iterations of the
linearised model rho = |R r_s - r| + cb_sys (``gnss_model.predict``, with the Sagnac
rotation), from the last solution or, at the first epoch, from the Earth's centre; while the
weighted residuals fail the chi-square test (false alarm 1e-3) the worst is excluded (fault
detection and exclusion). The pseudorange rates then give the velocity and one clock
drift. Weights: the receiver's reported 1-sigma where the stream carries it
(``pseudorange_std``, ``pseudorange_rate_std``), else a C/N0 model, sigma^2 = a^2 + b^2
10^(-C/N0 / 10) with a = 0.5 m and b = 300 m (dB-Hz; the form of RTKLIB's and of Android's
uncertainty models); satellites below ``elevation_mask`` (deg, where the stream has the
elevation) or unhealthy are left out, and an epoch needs four plus one per extra system.

The pseudoranges' errors are not independent: the broadcast ionosphere's residual is partly
common to an epoch's satellites. The simulated true delay is ``iono_scale`` (1 + ``iono_residual``
g) times the broadcast model's (``simulator.datasheet.iono_residual_fractions``), so c I_i,
c = |scale - 1|, is exactly common to them, each scaled by its own broadcast delay I_i; the
field's part f g_i I_i (f = scale residual) is correlated between the satellites by their
pierce points' separation, the covariance F = (f I_i)(f I_j) exp(-d_ij^2 / (2 L^2))
(``simulator.datasheet.iono_field_covariance``, as the receiver's own fix accuracy takes it).
Their covariance is R = diag(sigma_i^2 - a_i^2 - F_ii) + a a^T + F, a_i = c I_i. The
solution is generalised least squares with the common part only, W = R0^-1, R0 = diag(sigma_i^2
- a_i^2) + a a^T (Aitken 1935; an error shared by the satellites is mostly taken by the clock
and the height), and its covariance is that of this estimate under the whole R, G R G^T with
G = (H^T W H)^-1 H^T W. Weighted by the whole R (F in the weights too), a real receiver's hour
(GEONET 0759, ``tests/recordings/test_import.py``) went from 2.41 to 4.19 m horizontal RMS and
from a mean (error / sigma)^2 of 0.37 to 4.9 north: the field's correlation describes the
simulator's ionosphere, and a real sky's is not known well enough to weight by; the
covariance G R G^T only says how large the estimate's error is. With the reported variances as
independent the horizontal sigma was 3-20 times the error on open sky (mean (error / sigma)^2
north 0.002-0.07 on four drives); with the field's common part (sqrt(0.75) of it) in a as a
rank-one term, the quickstart's east axis reached 22 (seeds 1-10: mean 5.7): a field that
changes across the sky is not one common fraction. Without the stream's azimuths and
elevations the field stays with each satellite's own errors. The fault test is r^T W r
against chi-square (false alarm 1e-3); when it fails, the measurement excluded is the one
whose Pope tau statistic (Baarda's normalised residual over the a-posteriori sigma_0, Pope
1976) is the largest and over its critical value at 1e-3: one outlier among good
measurements stands out and goes; errors spread over every satellite (a variance the model
understates) exclude none, and are left to the variance factor below (with the w-test, which
takes sigma_0 as 1, they stripped good satellites one by one).

Reflected signals (NLOS). In a street canyon a satellite behind a building is often tracked by
its reflection off a facade: an extra path of tens of metres that the receiver's reported
sigma does not hold, and that the chi-square exclusion cannot remove when several satellites
are reflected at once. What announces it is the signal's C/N0: a reflection loses power, so
its C/N0 falls well below what a direct signal has at its elevation. The receiver's template
(``simulator.datasheet.cn0_template``: the nominal C/N0 against elevation, and the scatter s
of a direct signal's C/N0 about it from fading and estimation noise) gives each signal's
deficit D; its variance becomes sigma^2 + p(D) sigma_NLOS^2, p the probability that it is
reflected by Bayes' rule (``simulator.datasheet.nlos_probability``, the receiver's own fix
accuracy reads it too: a direct signal's deficit N(0, s^2), a reflection's N(11 dB,
(4.5 dB)^2), and as prior the share of the epoch's signals whose deficit is over 3 s, at
least 1 %). sigma_NLOS is the ``nlos_sigma``
config key (20 m: the extra path of a reflection off the facade across a 20-35 m street).
This is the elevation- and C/N0-dependent weighting of Groves 2013
(chapter 9: a measurement's weight from its C/N0 and elevation; chapter 10: NLOS reception and
its detection by C/N0), with the deficit against a template of the SIGMA-Delta
model (Brunner, Hartinger & Troyer 1999); without a template (a recording's receiver without
``cn0_zenith``) no deficit is taken. Measured (docs/scores.md): the street canyons' position
axes went from mean (error / sigma)^2 of 14-106 to means of 0.5-2.2 over ten seeds (no seed
above 3.7), the open drives' stayed as they were.
Then the a-posteriori variance factor (the variance of unit weight, Koch 1999, *Parameter
Estimation and Hypothesis Testing in Linear Models*, chapter 3; Groves 2013, chapter 17):
sigma_0^2 = r^T W r / (m - n) after the exclusion; where it exceeds 1 the residuals show errors
larger than the model's and the position's covariance is scaled by it (never scaled down).
The std columns are the square roots of the diagonal of sigma_0^2 (H^T W H)^-1 rotated to NED.
Roll, pitch and yaw are NaN (a receiver does not know them).
``clock_bias`` is GPS's clock bias (m; of its lowest band, else of the first system
tracked), ``clock_drift`` the drift (m/s).

Public names
------------
GnssWls (``nlos_sigma`` is ``toolbox.gnss_model``'s, ``nlos_probability``
``simulator.datasheet``'s).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.stats import chi2
from scipy.stats import t as student_t

from estimators.base import Estimator
from estimators.toolbox.gnss_model import NLOS_SIGMA_M, nlos_sigma, predict, raw_epoch
from simulator.datasheet import cn0_template, iono_field_covariance, iono_residual_fractions
from simulator.earth import ecef_to_geodetic, ned_to_ecef_matrix

C_N0_FLOOR_M = 0.5      # a: the sigma of a strong signal, m
C_N0_SCALE_M = 300.0    # b: sigma^2 = a^2 + b^2 10^(-C/N0/10), m
DEFAULT_CN0_DBHZ = 45.0
ITERATIONS = 8
BAND_HZ = 50e6  # carriers within 25 MHz share a band: L1/E1/G1 (FDMA) apart from B1I, L5/E5a
CONVERGED_M = 1e-4
FDE_FALSE_ALARM = 1e-3  # false-alarm probability of the residual test

OUTPUT_COLUMNS = ("lat", "lon", "alt", "vn", "ve", "vd", "roll", "pitch", "yaw",
                  "std_n", "std_e", "std_d", "std_vn", "std_ve", "std_vd",
                  "clock_bias", "clock_drift", "num_sats")


class GnssWls(Estimator):
    """Snapshot weighted least squares on pseudoranges and pseudorange rates."""

    name = "gnss_wls"
    needs = ("gnss_raw",)
    paper = "baseline: epoch-by-epoch weighted least squares (Misra & Enge 2011, 6.1-6.2)"
    initialises_itself = True
    output_rate_hz = 1.0
    defaults = {"elevation_mask": 10.0, "nlos_sigma": NLOS_SIGMA_M}
    config_help = {"elevation_mask": ("deg", "satellites below this elevation are left out"),
                   "nlos_sigma": ("m", "1-sigma of a reflected signal's extra path, added to "
                                       "a pseudorange whose C/N0 is far below the template")}
    output_columns = OUTPUT_COLUMNS

    def setup(self) -> None:
        self._cols = self.columns["gnss_raw"]
        self._pos = np.zeros(3)
        self._row: list[float] | None = None
        self._t = math.nan
        self._mask = math.radians(float(self.config["elevation_mask"]))
        gnss = self.datasheet.get("gnss") or {}
        self._iono_common, self._iono_field = iono_residual_fractions(gnss)
        self._cn0_template = cn0_template(gnss)
        self._nlos_sigma_m = float(self.config["nlos_sigma"])

    def on_gnss_raw(self, t: float, block: np.ndarray) -> None:
        cols = self._cols
        if "health" in cols:
            block = block[block[:, cols["health"]] == 0]
        if "elevation" in cols:
            elevation = block[:, cols["elevation"]]
            block = block[~(elevation < self._mask)]  # NaN elevations are kept
        # one clock bias per system and frequency band: systems keep their own time, and a
        # receiver's code delay differs between bands (a phone's L1 and L5: tens of metres)
        systems = (block[:, cols["system_code"]] if "system_code" in cols
                   else np.zeros(len(block)))
        if "frequency" in cols:
            systems = systems * 1000.0 + np.round(block[:, cols["frequency"]] / BAND_HZ)
        ep = raw_epoch(block, cols)
        ok = np.isfinite(ep.pseudorange) & np.isfinite(ep.sat_pos).all(axis=1)
        labels, system_index = np.unique(systems[ok], return_inverse=True)
        n_clock = len(labels)
        # the clock written out: GPS's (its lowest band) where GPS is tracked
        gps = np.flatnonzero(labels // 1000 == ord("G"))
        reference_clock = int(gps[0]) if gps.size else 0
        if ok.sum() < 3 + n_clock:
            self._row = None
            return
        sat_pos, sat_vel = ep.sat_pos[ok], ep.sat_vel[ok]
        rho = ep.pseudorange[ok]
        cn0 = block[:, cols["cn0"]][ok] if "cn0" in cols else None
        sigma = _sigma(ep.pseudorange_std[ok], cn0, C_N0_FLOOR_M)
        if cn0 is not None and self._cn0_template is not None and "elevation" in cols:
            sigma = nlos_sigma(sigma, cn0, block[:, cols["elevation"]][ok],
                               self._cn0_template, self._nlos_sigma_m)
        iono = np.zeros(len(rho)) if ep.iono is None else np.nan_to_num(ep.iono[ok])
        field = None
        if self._iono_field > 0 and "elevation" in cols and "azimuth" in cols:
            field = iono_field_covariance(self._iono_field, iono,
                                          block[:, cols["azimuth"]][ok],
                                          block[:, cols["elevation"]][ok])
        cov = _range_covariance(sigma, self._iono_common * iono, field)
        cov_weights = _range_covariance(sigma, self._iono_common * iono)
        clock_cols = np.zeros((len(rho), n_clock))
        clock_cols[np.arange(len(rho)), system_index] = 1.0
        used = np.ones(len(rho), dtype=bool)
        while True:
            weight = np.linalg.inv(cov_weights[np.ix_(used, used)])
            x, h, residual = _solve(self._pos, sat_pos[used], sat_vel[used], rho[used],
                                    clock_cols[used], weight)
            dof = int(used.sum()) - h.shape[1]
            wssr = float(residual @ weight @ residual)
            # fault detection and exclusion: while the weighted residuals fail the chi-square
            # test, drop the measurement whose Pope tau statistic exceeds its critical value
            # (the largest); none does when the errors are spread over all (module docstring)
            if dof < 2 or wssr <= chi2.ppf(1.0 - FDE_FALSE_ALARM, dof):
                break
            tau = _tau_statistics(h, weight, residual, wssr / dof)
            worst = int(np.argmax(np.abs(tau)))
            if abs(tau[worst]) <= tau_critical(dof, FDE_FALSE_ALARM):
                break
            used[np.flatnonzero(used)[worst]] = False
        gain = np.linalg.solve(h.T @ weight @ h, h.T @ weight)  # dx = gain residual
        cov_pos = gain @ cov[np.ix_(used, used)] @ gain.T
        if dof > 0:  # the a-posteriori variance factor, when the residuals say more
            cov_pos = cov_pos * max(wssr / dof, 1.0)
        self._pos = x[:3]
        lat, lon, alt = ecef_to_geodetic(x[:3])
        c_ne = ned_to_ecef_matrix(lat, lon)
        std_ned = np.sqrt(np.diag(c_ne.T @ cov_pos[:3, :3] @ c_ne))

        rate = ep.range_rate[ok]
        good = np.isfinite(rate)
        vel = np.full(3, np.nan)
        std_vel = np.full(3, np.nan)
        drift = math.nan
        if good.sum() >= 4:
            rate_sigma = _sigma(ep.range_rate_std[ok][good], None, 0.05)
            w_rate = 1.0 / rate_sigma**2
            _, predicted_rate, los = predict(sat_pos[good], sat_vel[good], x[:3], np.zeros(3))
            h_rate = np.hstack([-los, np.ones((good.sum(), 1))])
            sol = _wls(h_rate, rate[good] - predicted_rate, np.diag(w_rate))
            cov_vel = np.linalg.inv(h_rate.T @ (h_rate * w_rate[:, None]))
            vel = c_ne.T @ sol[:3]
            std_vel = np.sqrt(np.diag(c_ne.T @ cov_vel[:3, :3] @ c_ne))
            drift = float(sol[3])
        self._row = [math.degrees(float(lat)), math.degrees(float(lon)), float(alt),
                     *vel, math.nan, math.nan, math.nan, *std_ned, *std_vel,
                     float(x[3 + reference_clock]), drift, float(used.sum())]
        self._t = t

    def solution(self, t: float) -> list[float] | None:
        if self._row is None or abs(t - self._t) > 1e-6:
            return None
        return self._row


def _solve(start: np.ndarray, sat_pos: np.ndarray, sat_vel: np.ndarray, rho: np.ndarray,
           clock_cols: np.ndarray, weight: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gauss-Newton WLS of position and clocks (``weight``: the inverse covariance matrix); the
    state (NaN for the clock of a band with no measurement left), the design matrix and the
    residuals at the solution."""
    keep = clock_cols.any(axis=0)  # a band whose every measurement was excluded
    clock_cols = clock_cols[:, keep]
    x = np.concatenate([start, np.zeros(clock_cols.shape[1])])
    for _ in range(ITERATIONS):
        geometric, _, los = predict(sat_pos, sat_vel, x[:3], np.zeros(3))
        residual = rho - geometric - clock_cols @ x[3:]
        h = np.hstack([-los, clock_cols])
        dx = _wls(h, residual, weight)
        x += dx
        if np.linalg.norm(dx[:3]) < CONVERGED_M:
            break
    geometric, _, los = predict(sat_pos, sat_vel, x[:3], np.zeros(3))
    residual = rho - geometric - clock_cols @ x[3:]
    full = np.full(3 + keep.size, np.nan)  # NaN for a band with no measurement left
    full[:3] = x[:3]
    full[3:][keep] = x[3:]
    return full, np.hstack([-los, clock_cols]), residual


def _sigma(reported: np.ndarray, cn0: np.ndarray | None, floor: float) -> np.ndarray:
    """1-sigma per measurement: the receiver's report where finite and positive, else the
    C/N0 model (or ``floor`` without C/N0)."""
    if cn0 is None:
        model = np.full(len(reported), floor)
    else:  # a signal without a C/N0 (an observation file that has none) is taken at 45 dB-Hz
        cn0 = np.where(np.isfinite(cn0), cn0, DEFAULT_CN0_DBHZ)
        model = np.sqrt(C_N0_FLOOR_M**2 + C_N0_SCALE_M**2 * 10.0 ** (-cn0 / 10.0))
    return np.where(np.isfinite(reported) & (reported > 0), reported, model)


def _tau_statistics(h: np.ndarray, weight: np.ndarray, residual: np.ndarray,
                    unit_variance: float) -> np.ndarray:
    """Pope's tau statistic of each measurement: Baarda's normalised residual w_i = (W r)_i /
    sqrt((W Q_r W)_ii), Q_r = W^-1 - H (H^T W H)^-1 H^T the residuals' covariance, over the
    a-posteriori sigma_0 (Pope 1976, eq. 10; Teunissen 2000, *Testing Theory*, section 4.6)."""
    q_r = np.linalg.inv(weight) - h @ np.linalg.solve(h.T @ weight @ h, h.T)
    spread = np.sqrt(np.maximum(np.einsum("ij,jk,ki->i", weight, q_r, weight), 1e-30))
    return (weight @ residual) / spread / math.sqrt(unit_variance)


def tau_critical(dof: int, false_alarm: float) -> float:
    """The two-sided critical value of Pope's tau with ``dof`` redundancy at ``false_alarm``:
    sqrt(r) t / sqrt(r - 1 + t^2), t Student's quantile with r - 1 degrees of freedom (Pope
    1976, eq. 12)."""
    t = student_t.ppf(1.0 - false_alarm / 2.0, dof - 1)
    return float(math.sqrt(dof) * t / math.sqrt(dof - 1 + t * t))


def _range_covariance(sigma: np.ndarray, common: np.ndarray, field: np.ndarray | None = None
                      ) -> np.ndarray:
    """R = diag(sigma^2 - common^2 - F_ii) + common common^T + F (module docstring): the
    reported 1-sigma of each pseudorange with the part ``common`` (m) common to them and the
    ionosphere field's covariance F (None: none); the independent part keeps at least a tenth
    of the reported sigma."""
    shared = np.outer(common, common)
    if field is not None:
        shared = shared + field
    own = np.maximum(sigma**2 - np.diag(shared), (0.1 * sigma) ** 2)
    return np.diag(own) + shared


def _wls(h: np.ndarray, residual: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """The generalised least-squares solution of h dx = residual with the weight matrix
    ``weight`` (the inverse of the residuals' covariance)."""
    hw = weight @ h
    return np.linalg.solve(h.T @ hw, hw.T @ residual)
