"""The receiver's error budget: draws every error term of the raw measurements (receiver clock,
signal-in-space error, ionosphere and troposphere residuals, multipath, C/N0 fading, code and
carrier tracking noise) for satellites x epochs, smooths the code with the carrier as the
receiver does, and gives the 1-sigma the receiver reports for weighting.

Time behaviour (issue 19):

- The code tracking error is the DLL's thermal jitter (Kaplan & Hegarty 2017 eq. 8.51) shaped by
  the loop: a first-order loop of noise bandwidth B_L passes white discriminator noise through
  a low-pass of time constant 1 / (4 B_L) (a first-order loop's noise bandwidth is
  B_L = K / 4: Kaplan & Hegarty 2017 ch. 8, the loop filter characteristics), so the error is
  a Gauss-Markov process of that correlation time sampled at the output rate: a 0.5 Hz loop
  is correlated over 0.5 s, so consecutive 10 Hz samples are (correlation 0.82), 1 Hz
  samples nearly not (0.14). The Doppler error is shaped likewise by
  the frequency loop.
- Carrier smoothing (Hatch 1982; the 100 s time constant of RTCA DO-229D and DO-253C)
  filters the code-minus-carrier: smoothed = carrier + F(code - carrier), F the first-order
  filter with weight 1 / min(n, N) for the n-th epoch of a tracking arc (a growing
  average until N = T / dt epochs, then fixed). Since code - carrier = 2 I + e_code + m_code
  (the carrier's own noise and multipath, millimetres, are left out), the smoothed pseudorange
  error is F(e_code) + F(m_code) + F(2 I) - I: the noise and multipath are lowered and become
  correlated over T, and the ionosphere's code-carrier divergence leaves a lag of about
  -2 T dI/dt. Choice: the former "level kept" simplification (the smoothed error held at the
  raw jitter's level, only its correlation changed) is dropped; the filter acts on the drawn
  errors, so smoothing lowers them as receivers' do. An NLOS signal's extra path delays code
  and carrier alike, so it passes the filter unchanged.
- Multipath and C/N0 fading decorrelate with the antenna's motion relative to the reflectors
  and, standing still, with the satellite's motion: Gauss-Markov processes in the coordinate
  u = distance / D + t / T_static (D ``multipath_distance``, T_static
  ``multipath_correlation_time``), so their correlation is exp(-|du|) (Braasch 1996,
  *Multipath effects*, in Parkinson & Spilker vol. I ch. 14; the static period
  lambda / (2 h cos(el) d el/dt) of Georgiadou & Kleusberg 1988 is minutes for reflectors
  metres away).
- The true ionosphere is ``iono_scale`` times the Klobuchar delay (1.5 by default: the model
  leaves a residual of half its own value; Klobuchar 1987 designed it to remove about 50 % of
  the rms delay) times 1 + ``iono_residual`` g, g a smooth random field over the ionospheric
  pierce points (the broadcast model's own thin-shell geometry,
  ``simulator.gnss.atmosphere.klobuchar_pierce_point``) and time: the vertical delay error is
  ``iono_scale`` ``iono_residual`` g times the model's vertical delay at the pierce point, and
  the slant error that times the model's obliquity factor. So signals close in the sky share
  their residual; what differs between them is what the pierce points' separation gives,
  not an independent draw per signal. g has unit variance and the correlation
  exp(-|dt| / 30 min) exp(-d^2 / (2 L^2)) at pierce points d apart, L = 1000 km (choice: the
  error of a broadcast or global ionosphere model is a regional structure; the WAAS and GIM
  vertical-delay variograms decorrelate over hundreds to a thousand kilometres: Blanch 2002,
  Sparks et al. 2011, and the 5 deg x 2.5 deg grid of the IGS maps resolves it, Hernandez-
  Pajares et al. 2009). g is drawn as a sum of random plane waves (``iono_field``; Rahimi &
  Recht 2007): wave numbers drawn from the Gaussian correlation's spectrum, amplitudes slowly
  varying Gauss-Markov processes: smooth in space and time (a wave shorter than a few hundred
  kilometres is unlikely, so the ionosphere's rate stays at the mm/s of a quiet ionosphere).
- The signal-in-space error (``sis_error``, the 1-sigma of the broadcast orbit and clock's
  range error) is a per-satellite offset for the drive (the control segment uploads each
  satellite about once a day) plus an offset per broadcast record, drawn anew when the
  receiver switches to the satellite's next ephemeris (``draw_sis``), constant within a
  record. Measured on the refdata's day 2015-07-19 (the broadcast file ``arlm2000.15n``
  against the NGA precise ephemeris, radial minus clock, each epoch's mean over the satellites
  removed): 0.80 m rms, of which 0.33 m varies about each satellite's day mean (``
  SIS_RECORD_SHARE`` = 0.33^2 / 0.80^2 of the variance), 0.05 m within an hour; the variable
  part's autocorrelation is 0.73 at 30 min, 0.45 at 1-2 h and 0 at 4 h: steps between records,
  not a drift within one. (The former model, one Gauss-Markov process over 1 h, varied 0.26 m
  within an hour.)

Public names
------------
OSCILLATORS, SIS_RECORD_SHARE, IONO_CORRELATION_TIME_S, IONO_CORRELATION_LENGTH_KM,
IONO_FIELD_WAVES, IONO_SHELL_RADIUS_KM, IONO_FIELD_STEP_S, SMOOTHING_GROUP_SAMPLES,
REPORTED_PR_STD_FLOOR_M, REPORTED_RATE_STD_FLOOR_M_S, IONO_GRID_STEP,
loop_time_constant_s,
decorrelation_coordinate, gauss_markov_along, pierce_points_km, iono_field_correlation,
iono_field, iono_field_at_epochs, draw_receiver_clock, draw_fading, draw_sis,
draw_error_terms, hatch_filter, smoothed_variance_factor, smooth_code_errors,
pseudorange_sigma.

References
----------
Brown & Hwang 2012, Table 9.1 (oscillator h-parameters). Kaplan & Hegarty 2017, section 10.2
(the single-frequency error budget) and ch. 8 (loop noise bandwidth). Hatch, R., "The
synergism of GPS code and carrier measurements", 3rd Int. Geodetic Symp. on Satellite Doppler
Positioning, 1982. Klobuchar, J. A., "Ionospheric time-delay algorithm for single-frequency GPS
users", IEEE Trans. AES 23(3), 325-331, 1987. Blanch, J., "An ionosphere estimation algorithm
for WAAS based on kriging", ION GPS 2002. Sparks, L., Blanch, J. & Pandya, N., "Estimating
ionospheric delay using kriging: 1. Methodology", Radio Sci. 46, RS0D21, 2011. Hernandez-Pajares,
M. et al., "The IGS VTEC maps: a reliable source of ionospheric information since 1998",
J. Geodesy 83, 263-275, 2009. Rahimi, A. & Recht, B., "Random features for large-scale kernel
machines", NIPS 2007. Georgiadou, Y. & Kleusberg, A., "On carrier signal
multipath effects in relative GPS positioning", Manuscripta Geodaetica 13, 172-179, 1988.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from simulator.datasheet import (  # the field's scales: the receivers' model reads them too
    EARTH_MEAN_RADIUS_KM,
    IONO_CORRELATION_LENGTH_KM,
    IONO_SHELL_HEIGHT_KM,
)
from simulator.gnss.atmosphere import klobuchar_pierce_point
from simulator.gnss.chunks import epoch_chunks
from simulator.gnss.constants import LAMBDA_L1_M
from simulator.gnss.receiver import clock_process, dll_sigma_m, fll_sigma_hz, multipath_sigma_m
from simulator.stochastic import ar1_filter, child_rng, gauss_markov, gauss_markov_at

# receiver oscillators: Allan h-parameters (Brown & Hwang Table 9.1: compensated and ovenized
# crystal) and the 1-sigma spread of the clock state at switch-on
OSCILLATORS: dict[str, dict[str, float]] = {
    "tcxo": {"h0": 2e-19, "h_minus2": 2e-20, "bias_s": 1e-4, "drift_s_s": 5e-7},
    "ocxo": {"h0": 8e-20, "h_minus2": 4e-23, "bias_s": 1e-4, "drift_s_s": 1e-8},
    "ideal": {"h0": 0.0, "h_minus2": 0.0, "bias_s": 0.0, "drift_s_s": 0.0},
}
# share of the signal-in-space error's variance drawn anew with each broadcast record (module
# docstring: the NGA precise ephemeris against the broadcast file on 2015-07-19, 0.33 / 0.80 m)
SIS_RECORD_SHARE = (0.33 / 0.80) ** 2
IONO_CORRELATION_TIME_S = 1800.0  # variations of the true/Klobuchar ratio
IONO_FIELD_WAVES = 64  # plane waves summed to draw the field (its variance is exact)
IONO_SHELL_RADIUS_KM = EARTH_MEAN_RADIUS_KM + IONO_SHELL_HEIGHT_KM  # Klobuchar's shell
# the field is evaluated every 10 s and interpolated linearly between: a pierce point moves by
# under 2 km in 10 s (a satellite's at about 0.1 km/s, a car's at its speed), 1/500 of L, so
# the interpolation changes the field by under 1e-5 of its sigma
IONO_FIELD_STEP_S = 10.0
# satellites x epochs carrier-smoothed together (``smooth_code_errors``): 1 MB per array
SMOOTHING_GROUP_SAMPLES = 2**17
REPORTED_PR_STD_FLOOR_M = 0.1  # the smallest pseudorange 1-sigma the receiver reports
REPORTED_RATE_STD_FLOOR_M_S = 0.01  # the smallest pseudorange-rate 1-sigma it reports
# the amplitudes of the ionosphere field's waves are drawn once per correlation time (30 min)
# and interpolated: their rate is then sigma x 1.1 / 30 min, about 1.5 mm/s on an 8 m delay
# with the default 1.5 x 0.2,
# the rate of TEC of a quiet mid-latitude ionosphere (below 0.5 TECU/min = 1.35 mm/s on L1;
# Pi et al., "Monitoring of global ionospheric irregularities using the worldwide GPS network",
# Geophys. Res. Lett. 24(18), 1997); drawn every epoch, the process would change like a random
# walk, some 10 mm/s, which the carrier smoothing turns into a metre of divergence error
IONO_GRID_STEP = 1.0


def loop_time_constant_s(bandwidth_hz: float) -> float:
    """Time constant of a first-order tracking loop of one-sided noise bandwidth B_L:
    B_L = K / 4 for the loop gain K, so the loop low-passes with 1 / K = 1 / (4 B_L) (Kaplan &
    Hegarty 2017 ch. 8, the loop filter characteristics)."""
    return 1.0 / (4.0 * bandwidth_hz)


def decorrelation_coordinate(t_s: np.ndarray, distance_m: np.ndarray, distance_scale_m: float,
                             time_scale_s: float) -> np.ndarray:
    """u = distance / D + t / T: one unit of u decorrelates multipath and fading by 1 / e."""
    return np.asarray(distance_m) / distance_scale_m + np.asarray(t_s) / time_scale_s


def gauss_markov_along(u: np.ndarray, rows: int, rng: np.random.Generator,
                       step: float | None = None, columns: np.ndarray | None = None
                       ) -> np.ndarray:
    """Unit-variance processes with correlation exp(-|u_i - u_j|) at the points u (ascending,
    shape (n,)), one per row: shape (rows, n). Without ``step``, the exact Gauss-Markov process
    at the points themselves (``simulator.stochastic.gauss_markov_at``). With ``step``, the
    exact process on a grid of ``step`` in u, interpolated linearly at u: smoother between grid
    points, where the variance falls to (1 + e^-step) / 2 at the middle (0.68 for a step of 1:
    the ionosphere field's amplitudes, whose rate this keeps at that of a quiet ionosphere).
    ``columns`` (without ``step``): only those rows of the processes, the same numbers
    (``gauss_markov_at``)."""
    u = np.asarray(u, dtype=float)
    if step is None:
        return gauss_markov_at(u, rows, rng, columns).T
    grid = u[0] + np.arange(int(np.ceil((u[-1] - u[0]) / step)) + 2) * step
    values = gauss_markov(len(grid), step, np.ones(rows), 1.0, rng)
    pos = (u - grid[0]) / step
    i = np.minimum(pos.astype(int), len(grid) - 2)
    w = pos - i
    return (values[i] * (1.0 - w)[:, None] + values[i + 1] * w[:, None]).T


def pierce_points_km(lat_rad: np.ndarray, lon_rad: np.ndarray, azimuth_rad: np.ndarray,
                     elevation_rad: np.ndarray) -> np.ndarray:
    """Earth-centred coordinates (km, shape (3,) + the arguments' broadcast shape) of the
    signals' ionospheric pierce points (``klobuchar_pierce_point``) on the shell of radius
    ``IONO_SHELL_RADIUS_KM``: the field is defined in space, so no map projection distorts the
    distances (the chord between two pierce points is their distance along the shell within
    0.1 % up to 1000 km, 0.4 % at 2000 km)."""
    phi_i, lam_i = klobuchar_pierce_point(lat_rad, lon_rad, azimuth_rad, elevation_rad)
    phi, lam = phi_i * np.pi, lam_i * np.pi
    return IONO_SHELL_RADIUS_KM * np.stack([np.cos(phi) * np.cos(lam),
                                            np.cos(phi) * np.sin(lam), np.sin(phi)])


def iono_field_correlation(distance_km: np.ndarray, lag_s: np.ndarray = 0.0) -> np.ndarray:
    """Correlation of the ionosphere field ``iono_field`` between pierce points ``distance_km``
    apart and ``lag_s`` apart in time: exp(-d^2 / (2 L^2)) exp(-|lag| / T) (L
    ``IONO_CORRELATION_LENGTH_KM``, T ``IONO_CORRELATION_TIME_S``; the time part is that of the
    amplitudes' Gauss-Markov processes, exact at the grid points they are drawn on)."""
    d = np.asarray(distance_km, dtype=float) / IONO_CORRELATION_LENGTH_KM
    return np.exp(-0.5 * d**2 - np.abs(np.asarray(lag_s, dtype=float)) / IONO_CORRELATION_TIME_S)


def _sum_of_waves(k: np.ndarray, phase: np.ndarray, amp: np.ndarray, pierce_km: np.ndarray
                  ) -> np.ndarray:
    """sqrt(2 / M) sum_m a_m(t) cos(k_m . x + p_m) over the M waves, at pierce points
    (3, n_sat, n_t) and amplitudes (M, n_t)."""
    x, y, z = pierce_km
    out = np.zeros(np.shape(x))
    wave, term = np.empty(np.shape(x)), np.empty(np.shape(x))  # reused by every wave
    for m in range(len(k)):  # a loop over the waves; each is vectorised over signals x epochs
        # amp_m cos(k_m . x + p_m), summed in the order (k0 x + k1 y) + k2 z, then + p_m
        np.multiply(x, k[m, 0], out=wave)
        wave += np.multiply(y, k[m, 1], out=term)
        wave += np.multiply(z, k[m, 2], out=term)
        wave += phase[m]
        np.cos(wave, out=wave)
        wave *= amp[m]
        out += wave
    return np.sqrt(2.0 / len(k)) * out


def iono_field(rng: np.random.Generator, pierce_km: np.ndarray, t_s: np.ndarray,
               length_km: float = IONO_CORRELATION_LENGTH_KM,
               time_s: float = IONO_CORRELATION_TIME_S) -> np.ndarray:
    """A unit-variance random field over the pierce points with the correlation
    ``iono_field_correlation`` (d the chord): g(x, t) = sqrt(2 / M) sum_m a_m(t)
    cos(k_m . x + p_m), M ``IONO_FIELD_WAVES`` plane waves in space (random Fourier features,
    Rahimi & Recht 2007: for wave numbers k_m ~ N(0, I3 / L^2), the spectrum of the Gaussian
    correlation, and phases p_m uniform, E[g(x) g(x')] = E[cos(k . (x - x'))]
    = exp(-|x - x'|^2 / (2 L^2))), the amplitudes
    a_m unit-variance Gauss-Markov processes over ``time_s`` drawn every
    ``IONO_GRID_STEP`` correlation times and interpolated. A sum of 64 waves is Gaussian to a
    good approximation; each drive draws its own waves.

    Parameters
    ----------
    pierce_km : ndarray, shape (3, n_sat, n_epoch)
        Pierce points (``pierce_points_km``).
    t_s : ndarray, shape (n_epoch,)
        Epoch times, ascending.
    length_km, time_s : float
        The correlation length L and time (the regional field's by default).
    """
    waves = IONO_FIELD_WAVES
    k = rng.standard_normal((waves, 3)) / length_km
    phase = rng.uniform(0.0, 2.0 * np.pi, waves)
    amp = gauss_markov_along(np.asarray(t_s, dtype=float) / time_s, waves, rng, IONO_GRID_STEP)
    return _sum_of_waves(k, phase, amp, pierce_km)


class IonoField:
    """``iono_field`` drawn once for the epochs of a drive (dt_s apart) and evaluated at any
    receiver's pierce points at those epochs: the rover and the base station see one
    ionosphere. Evaluated every ``IONO_FIELD_STEP_S`` (and at the last epoch) and interpolated
    linearly (the draws are those of ``iono_field`` at those epochs)."""

    def __init__(self, rng: np.random.Generator, n_epoch: int, dt_s: float,
                 length_km: float = IONO_CORRELATION_LENGTH_KM,
                 time_s: float = IONO_CORRELATION_TIME_S):
        step = max(1, int(IONO_FIELD_STEP_S / dt_s))
        self.n_epoch = n_epoch
        self.coarse = np.unique(np.append(np.arange(0, n_epoch, step), n_epoch - 1))
        self.k = rng.standard_normal((IONO_FIELD_WAVES, 3)) / length_km
        self.phase = rng.uniform(0.0, 2.0 * np.pi, IONO_FIELD_WAVES)
        self.amp = gauss_markov_along(self.coarse * dt_s / time_s, IONO_FIELD_WAVES, rng,
                                      IONO_GRID_STEP)

    def __call__(self, pierce_km: np.ndarray) -> np.ndarray:
        """The field at pierce points (3, n_sat, n_epoch), shape (n_sat, n_epoch)."""
        values = _sum_of_waves(self.k, self.phase, self.amp, pierce_km[..., self.coarse])
        if len(self.coarse) == self.n_epoch:
            return values
        coarse, n_ep = self.coarse, self.n_epoch
        k = np.arange(n_ep)
        i = np.minimum(np.searchsorted(coarse, k, side="right") - 1, len(coarse) - 2)
        w = (k - coarse[i]) / (coarse[i + 1] - coarse[i])
        out = np.empty((values.shape[0], n_ep))
        for cols in epoch_chunks(n_ep):  # one pass per chunk of epochs
            out[:, cols] = values[:, i[cols]] * (1.0 - w[cols]) + values[:, i[cols] + 1] * w[cols]
        return out


def iono_field_at_epochs(rng: np.random.Generator, pierce_km: np.ndarray, dt_s: float
                          ) -> np.ndarray:
    """``iono_field`` at every epoch (dt_s apart) of the pierce points (3, n_sat, n_epoch),
    evaluated every ``IONO_FIELD_STEP_S`` (and at the last epoch) and interpolated linearly."""
    return IonoField(rng, pierce_km.shape[-1], dt_s)(pierce_km)


def draw_receiver_clock(rng: np.random.Generator, oscillator: str, n: int, dt_s: float
                        ) -> tuple[np.ndarray, np.ndarray, dict]:
    """Receiver clock bias (s) and drift (s/s) at n epochs, and the drawn initial state."""
    osc = OSCILLATORS[oscillator]
    bias0 = osc["bias_s"] * rng.standard_normal()
    drift0 = osc["drift_s_s"] * rng.standard_normal()
    bias, drift = clock_process(n, dt_s, osc["h0"], osc["h_minus2"], bias0, drift0, rng)
    return bias, drift, {"oscillator": oscillator, "bias_s": bias0, "drift_s_s": drift0}


def draw_fading(rng: np.random.Generator, cfg: dict, u: np.ndarray, n_sat: int,
                rows: np.ndarray | None = None) -> np.ndarray:
    """C/N0 fading, dB, shape (n_sat, n_epoch) (or of the satellites ``rows`` only, the same
    numbers): ``cn0_fading`` times a unit process correlated in the motion coordinate ``u``
    (``decorrelation_coordinate``), not white from epoch to epoch: the fading comes from the
    same reflections as the multipath."""
    if cfg["cn0_fading"] == 0:
        return np.zeros((n_sat if rows is None else len(rows), len(u)))
    return cfg["cn0_fading"] * gauss_markov_along(u, n_sat, rng, columns=rows)


def draw_sis(rng: np.random.Generator, sigma_m: float, record: np.ndarray) -> np.ndarray:
    """Signal-in-space range error, m, shape of ``record`` (n_sat, n_epoch): a per-satellite
    offset of variance (1 - ``SIS_RECORD_SHARE``) sigma^2 plus, for each broadcast record the
    receiver uses (``record``: its index, -1 where none), an offset of variance
    ``SIS_RECORD_SHARE`` sigma^2 (module docstring); zero where no record."""
    record = np.asarray(record)
    per_satellite = rng.standard_normal(record.shape[0])[:, None]
    per_record = rng.standard_normal(int(record.max(initial=-1)) + 1)
    unit = (np.sqrt(1.0 - SIS_RECORD_SHARE) * per_satellite
            + np.sqrt(SIS_RECORD_SHARE) * per_record[np.maximum(record, 0)])
    return np.where(record >= 0, sigma_m * unit, 0.0)


def draw_error_terms(rng: np.random.Generator, cfg: dict, elevation_rad: np.ndarray,
                     cn0_dbhz: np.ndarray, dt_s: float, u: np.ndarray,
                     pierce_km: np.ndarray, record: np.ndarray, shared: Any = None,
                     rows: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Every error term of the raw measurements before the receiver's carrier smoothing,
    shape (n_sat, n_epoch) unless noted; with ``rows``, of those satellites only (the terms
    of every satellite are drawn, so the numbers are the same).

    Parameters
    ----------
    rng : Generator
        The receiver's random stream: each term draws from its own named child of it
        (``simulator.stochastic.child_rng``: ``sis``, ``iono_field``, ``tropo_zenith``,
        ``multipath``, ``code_noise``, ``rate_noise``), so no term's draws move another's.
    cfg : dict
        The resolved ``sensors.gnss`` block (error levels and tracking-loop parameters).
    elevation_rad, cn0_dbhz : ndarray, shape (n_sat, n_epoch) (with ``rows``: (len(rows),
        n_epoch))
        Elevation and true C/N0 of each signal.
    dt_s : float
        Epoch interval.
    u : ndarray, shape (n_epoch,)
        The motion coordinate of multipath (``decorrelation_coordinate``).
    pierce_km : ndarray, shape (3, n_sat, n_epoch)
        The signals' ionospheric pierce points (``pierce_points_km``).
    record : ndarray of int, shape (n_sat, n_epoch)
        Index of the broadcast record each signal is computed from (-1: none), for the
        signal-in-space error (``draw_sis``), of every satellite.
    shared : optional
        Another receiver's draws of the same drive (its ``sis``, ``iono_field`` and
        ``tropo_zenith_m``), taken instead of drawing them: a second receiver's sky.
    rows : ndarray of int, optional
        The satellites (rows of ``record``) whose terms are wanted.

    Returns
    -------
    dict with ``sis`` (m; ``sis_all`` that of every satellite, for a second receiver);
    ``iono_ratio`` (true / broadcast ionosphere, module docstring) and
    ``iono_field`` (its ``IonoField``, None without variation, for a second receiver);
    ``tropo_zenith`` (scalar, m: the zenith troposphere the model misses, for the whole drive);
    ``multipath`` and ``multipath_sigma`` (m, correlated in u); ``code_noise`` and
    ``code_sigma`` (m: the DLL jitter for the signal's C/N0, a Gauss-Markov process over the
    loop's time constant); ``rate_noise`` and ``rate_sigma`` (m/s, the FLL's likewise).
    """
    shape = elevation_rad.shape
    n_ep = shape[1]
    n_sat = record.shape[0]  # every satellite's processes are drawn
    scale = cfg["tracking_noise"]

    def unit_gm(count: int, tau_s: float, name: str) -> np.ndarray:  # unit variance
        return gauss_markov(n_ep, dt_s, np.ones(count), tau_s, child_rng(rng, name),
                            columns=rows).T

    # the ionosphere's error: a field smooth over the pierce points and in time (module
    # docstring), so that nearby signals share it and its rate (which the carrier smoothing's
    # code-carrier divergence sees) stays at the mm/s of a quiet ionosphere
    if shared is None:
        out = {"sis_all": draw_sis(child_rng(rng, "sis"), cfg["sis_error"], record)}
        out["iono_field"] = (IonoField(child_rng(rng, "iono_field"), n_ep, dt_s)
                             if cfg["iono_residual"] > 0 else None)
    else:
        out = {"sis_all": shared.sis, "iono_field": shared.iono_field}
    out["sis"] = out["sis_all"] if rows is None else out["sis_all"][rows]
    field = (out["iono_field"](pierce_km) if out["iono_field"] is not None
             else np.zeros(shape))
    out["iono_ratio"] = cfg["iono_scale"] * (1.0 + cfg["iono_residual"] * field)
    out["tropo_zenith"] = (cfg["tropo_residual"] * child_rng(rng, "tropo_zenith").standard_normal()
                           if shared is None else shared.tropo_zenith_m)
    out["multipath_sigma"] = multipath_sigma_m(elevation_rad, cfg["multipath"])
    out["multipath_unit"] = gauss_markov_along(u, n_sat, child_rng(rng, "multipath"),
                                               columns=rows)
    out["multipath"] = out["multipath_sigma"] * out["multipath_unit"]
    out["code_sigma"] = scale * dll_sigma_m(cn0_dbhz, cfg["dll_bandwidth"],
                                            cfg["correlator_spacing"], cfg["integration_time"])
    out["code_noise"] = out["code_sigma"] * unit_gm(
        n_sat, loop_time_constant_s(cfg["dll_bandwidth"]), "code_noise")
    out["rate_sigma"] = scale * LAMBDA_L1_M * fll_sigma_hz(cn0_dbhz, cfg["fll_bandwidth"],
                                                          cfg["integration_time"])
    out["rate_noise"] = out["rate_sigma"] * unit_gm(
        n_sat, loop_time_constant_s(cfg["fll_bandwidth"]), "rate_noise")
    return out


def hatch_filter(x: np.ndarray, tracked: np.ndarray, dt_s: float, time_constant_s: float
                 ) -> np.ndarray:
    """The Hatch filter's response to x along the epochs (last axis), restarted at every
    tracking arc: y_k = (1 - 1/n) y_{k-1} + x_k / n with n = min(epochs since the arc began,
    N), N = T / dt (the 100 s filter of RTCA DO-229D); zero where not tracked.

    Vectorised: the growing part is a running mean (cumulative sums restarted per arc), the
    fixed part the recursion ``simulator.stochastic.ar1_filter`` run over the whole row with
    zero input where not tracked, corrected at each arc by the state it inherited:
    y_k = r_k + a^(k - k0 + 1) (mean_{k0-1} - r_{k0-1}) for k >= k0, the first epoch of the arc
    with n = N, a = 1 - 1 / N, r the whole-row recursion.

    Parameters
    ----------
    x : ndarray, shape (..., n_sat, n_epoch)
    tracked : ndarray of bool, shape (n_sat, n_epoch)
    """
    x = np.where(tracked, x, 0.0)
    n_window = time_constant_s / dt_s
    if n_window <= 1.0:
        return x
    lead = x.shape[:-2]
    n_sat, n_ep = tracked.shape
    k = np.arange(n_ep)
    starts = tracked & ~np.concatenate([np.zeros((n_sat, 1), bool), tracked[:, :-1]], axis=1)
    arc_start = np.maximum.accumulate(np.where(starts, k, 0), axis=1)
    pos = k - arc_start  # epochs since the arc began, 0 at its first
    rows = np.arange(n_sat)[:, None]
    total = np.cumsum(x, axis=-1)
    before = np.where(arc_start > 0, total[..., rows, np.maximum(arc_start - 1, 0)], 0.0)
    mean = (total - before) / (pos + 1)
    a = 1.0 - 1.0 / n_window
    flat = np.moveaxis(x, -1, 0).reshape(n_ep, -1)
    run = np.moveaxis(ar1_filter(flat, a, gain_in=1.0 - a).reshape((n_ep,) + lead + (n_sat,)),
                      0, -1)
    first_fixed = int(np.ceil(n_window - 1.0))  # pos of k0
    k0 = np.minimum(arc_start + first_fixed, n_ep - 1)
    carried = mean[..., rows, k0 - 1] - run[..., rows, k0 - 1]
    steps = np.maximum(pos - first_fixed + 1, 0)
    # a^steps from a table of the whole powers (the same pow of each, without one per sample)
    fixed = run + np.power(a, np.arange(int(steps.max(initial=0)) + 1))[steps] * carried
    return np.where(tracked, np.where(pos < first_fixed, mean, fixed), 0.0)


def smoothed_variance_factor(correlation_time_s: float | np.ndarray, dt_s: float,
                             time_constant_s: float) -> np.ndarray:
    """Steady-state variance of the Hatch filter's output per unit variance of a Gauss-Markov
    input of correlation time tau sampled every dt: for the filter y_k = a y_{k-1} + (1 - a) x_k
    and the input's correlation phi = exp(-dt / tau),
    var = (1 - a)^2 (1 + a phi) / ((1 - a^2)(1 - a phi)) (the output of two first-order
    recursions in cascade); 1 without smoothing."""
    n_window = time_constant_s / dt_s
    if n_window <= 1.0:
        return np.ones_like(np.asarray(correlation_time_s, dtype=float))
    a = 1.0 - 1.0 / n_window
    phi = np.exp(-dt_s / np.asarray(correlation_time_s, dtype=float))
    return (1.0 - a) ** 2 * (1.0 + a * phi) / ((1.0 - a * a) * (1.0 - a * phi))


def smooth_code_errors(cfg: dict, terms: dict[str, np.ndarray], iono_true_m: np.ndarray,
                       tracked: np.ndarray, dt_s: float) -> dict[str, np.ndarray]:
    """The code error terms after the receiver's carrier smoothing (``carrier_smoothing`` T > 0;
    module docstring): ``code_noise`` = F(e_code) + F(2 I) - 2 I (the tracking noise and the
    ionosphere's code-carrier divergence), ``multipath`` = F(m_code). Untracked signals keep
    their raw values (nothing is smoothed there). Returns the updated copy of ``terms``."""
    rows = np.flatnonzero(tracked.any(axis=1))  # the satellites ever tracked
    if cfg["carrier_smoothing"] <= 0 or rows.size == 0:
        return terms
    out = dict(terms)
    for key in ("code_noise", "multipath"):
        out[key] = terms[key].copy()
    # the satellites in groups of about SMOOTHING_GROUP_SAMPLES samples: each row is filtered
    # alone, so the groups change nothing but the size of the filter's temporaries
    groups = -(-rows.size * tracked.shape[1] // SMOOTHING_GROUP_SAMPLES)
    for part in np.array_split(rows, groups):  # one pass per group of satellites
        iono = iono_true_m[part]
        stacked = np.stack([terms["code_noise"][part], terms["multipath"][part], 2.0 * iono])
        smooth = hatch_filter(stacked, tracked[part], dt_s, cfg["carrier_smoothing"])
        for key, value in (("code_noise", smooth[0] + smooth[2] - 2.0 * iono),
                           ("multipath", smooth[1])):
            out[key][part] = np.where(tracked[part], value, terms[key][part])
    return out


def pseudorange_sigma(cfg: dict, terms: dict[str, np.ndarray], iono_m: np.ndarray,
                      tropo_mapping: np.ndarray, dt_s: float, speed_m_s: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
    """The 1-sigma of each pseudorange (m) and pseudorange rate (m/s) the receiver reports:
    the root sum of squares of the configured budget (code noise and multipath after the carrier
    smoothing, ``smoothed_variance_factor`` at the loop's and the multipath's correlation time
    (the latter at the current speed); ionosphere residual (``iono_scale`` - 1 plus the
    field's variation) times the broadcast delay; troposphere zenith residual times the
    mapping; signal-in-space error), with floors of 0.1 m and 0.01 m/s.

    Parameters
    ----------
    terms : dict
        From ``draw_error_terms`` (the sigmas).
    iono_m : ndarray
        Broadcast ionosphere delay of each signal, m.
    tropo_mapping : ndarray
        Slant / zenith troposphere of each signal.
    speed_m_s : ndarray, shape (n_epoch,)
        Antenna speed (the multipath's correlation time falls with it).
    """
    smoothing = cfg["carrier_smoothing"]
    code_factor = smoothed_variance_factor(loop_time_constant_s(cfg["dll_bandwidth"]), dt_s,
                                           smoothing)
    mp_time = 1.0 / (speed_m_s / cfg["multipath_distance"]
                     + 1.0 / cfg["multipath_correlation_time"])
    mp_factor = smoothed_variance_factor(mp_time, dt_s, smoothing)[None, :]
    iono_rel = (cfg["iono_scale"] - 1.0) ** 2 + (cfg["iono_scale"] * cfg["iono_residual"]) ** 2
    var = (code_factor * terms["code_sigma"] ** 2 + mp_factor * terms["multipath_sigma"] ** 2
           + iono_rel * iono_m**2
           + (cfg["tropo_residual"] * tropo_mapping) ** 2 + cfg["sis_error"] ** 2)
    return (np.maximum(np.sqrt(var), REPORTED_PR_STD_FLOOR_M),
            np.maximum(terms["rate_sigma"], REPORTED_RATE_STD_FLOOR_M_S))
