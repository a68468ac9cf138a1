"""Carrier phase as a receiver's phase-lock loop delivers it: thermal jitter from C/N0 and the
loop bandwidth, the loop's dynamic stress, cycle slips, continuous arcs each with one integer
ambiguity, the half-cycle ambiguity of data channels, the RINEX loss-of-lock indicator and the
lock time; and the carrier multipath of the reflection that gives the code multipath.

Every function works on whole (signal or satellite) x epoch arrays: arcs come from cumulative
sums over the tracking and slip masks, never from a loop over epochs.

Public names
------------
LLI_LOST_LOCK, LLI_HALF_CYCLE, pll_sigma_cycles, dynamic_stress_cycles, pll_response,
reflection_path_rate_m_s, slip_probability, draw_slips, PhaseArcs, phase_arcs,
reflection_multipath.

References
----------
Kaplan & Hegarty, *Understanding GPS/GNSS*, 3rd ed., 2017, section 8.7.2 (PLL thermal noise
jitter sigma = (1 / 2 pi) sqrt(B_n / (C/N0) (1 + 1 / (2 T C/N0))) cycles, eq. 5.6 of the 2nd
ed. 2006; the third-order loop's dynamic stress error theta_e = (d^3 R / dt^3) / omega_0^3 with
B_n = 0.7845 omega_0, Table 8.23 / 2nd ed. Table 5.6; the rule of thumb 3 sigma_PLL =
3 sigma_j + theta_e / 3 for the loop's total phase error).
Viterbi, A. J., *Principles of Coherent Communication*, McGraw-Hill 1966, ch. 4 (mean time to
the first cycle slip of a first-order PLL, T = pi^2 rho I0(rho)^2 / (2 B_L), rho = 1 / sigma^2
the loop SNR); for a Costas loop the squaring doubles the phase error, so rho / 4 and slips of
half a cycle (Simon & Lindsey, *Telecommunication Systems Engineering*, 1973, ch. 2).
RINEX 3.04 section 5.3 and Table A3 (loss of lock indicator: bit 0 lost lock since the previous
observation, cycle slip possible; bit 1 half-cycle ambiguity / slip possible).
Multipath of one reflection of relative amplitude alpha and phase psi: code error
d alpha cos psi and carrier error atan(alpha sin psi / (1 + alpha cos psi)) for a reflection
delayed d (m) (Braasch 1996, "Multipath effects", in Parkinson & Spilker, vol. I ch. 14,
eqs. 6 and 11, narrow-correlator small-delay form; Georgiadou & Kleusberg 1988).
The third-order loop's closed-loop response H(s) = (b w0 s^2 + a w0^2 s + w0^3) / (s^3 +
b w0 s^2 + a w0^2 s + w0^3), a = 1.1, b = 2.4, B_n = 0.7845 w0 (Kaplan & Hegarty 2017, Table 8.23:
the loop filter of a third-order PLL). The carrier multipath of one reflection oscillates at
the fading (fringe) frequency, the rate of change of the reflection's extra path over the
wavelength (Braasch 1996, the fading frequency of a moving antenna's multipath); the loop's
phase follows that input with the gain |H| at that frequency, so a reflection whose phase turns
well beyond the loop's bandwidth leaves little carrier error (the choice made here: the loop's
gain scales the phase error; its harmonics, at multiples of the fringe, are attenuated at least
as much).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

LLI_LOST_LOCK = 1  # RINEX 3.04: lost lock between the previous and this observation
LLI_HALF_CYCLE = 2  # RINEX 3.04: half-cycle ambiguity / slip possible
_THIRD_ORDER_BN_PER_OMEGA0 = 0.7845  # Kaplan & Hegarty Table 8.23: B_n = 0.7845 omega_0
_MAX_SLIP_CYCLES = 8  # the largest integer jump drawn for one slip
_THIRD_ORDER_A, _THIRD_ORDER_B = 1.1, 2.4  # Kaplan & Hegarty Table 8.23: the loop filter's a3, b3


def pll_sigma_cycles(cn0_dbhz: np.ndarray, bandwidth_hz: float, integration_s: float
                     ) -> np.ndarray:
    """PLL thermal-noise jitter, cycles: (1 / 2 pi) sqrt(B_n / (C/N0) (1 + 1 / (2 T C/N0)))
    (Kaplan & Hegarty 2017 section 8.7.2)."""
    cn0 = 10.0 ** (np.asarray(cn0_dbhz, dtype=float) / 10.0)
    return np.sqrt(bandwidth_hz / cn0 * (1.0 + 1.0 / (2.0 * integration_s * cn0))) / (2 * np.pi)


def dynamic_stress_cycles(los_jerk_m_s3: np.ndarray, wavelength_m: float, bandwidth_hz: float
                          ) -> np.ndarray:
    """Steady-state phase error of a third-order PLL under a line-of-sight jerk, cycles:
    |d^3 R / dt^3| / omega_0^3 / lambda, omega_0 = B_n / 0.7845 (Kaplan & Hegarty 2017
    Table 8.23)."""
    omega0 = bandwidth_hz / _THIRD_ORDER_BN_PER_OMEGA0
    return np.abs(np.asarray(los_jerk_m_s3, dtype=float)) / omega0**3 / wavelength_m


def pll_response(frequency_hz: np.ndarray, bandwidth_hz: float) -> np.ndarray:
    """|H(j 2 pi f)| of a third-order PLL of noise bandwidth B_n (module docstring): the gain
    with which the loop's phase follows a phase input at frequency f (1 well inside the
    bandwidth, a peak of 1.28 near B_n / 5, then falling as b w0 / (2 pi f))."""
    omega0 = bandwidth_hz / _THIRD_ORDER_BN_PER_OMEGA0
    s = 2j * np.pi * np.asarray(frequency_hz, dtype=float) / omega0  # in units of omega0
    numerator = _THIRD_ORDER_B * s**2 + _THIRD_ORDER_A * s + 1.0
    return np.abs(numerator / (s**3 + numerator))


def reflection_path_rate_m_s(v_ned: np.ndarray, azimuth_rad: np.ndarray,
                             elevation_rad: np.ndarray, wall_normal_rad: np.ndarray
                             ) -> np.ndarray:
    """Rate (m/s) at which the extra path of a reflection off a vertical plane changes while
    the antenna moves; over the wavelength, the frequency at which its carrier multipath turns.
    The extra path 2 h cos(el) cos(az - phi) of a plane at distance h with horizontal normal
    phi (Georgiadou & Kleusberg 1988, a vertical reflector) changes as dh/dt = -v . n
    (n = (cos phi, sin phi) north, east): |2 cos(el) cos(az - phi) (v . n)|, up to 2 v towards
    a wall ahead, zero along a wall parallel to the track.

    Parameters
    ----------
    v_ned : ndarray, shape (n_epoch, 3)
    azimuth_rad, elevation_rad, wall_normal_rad : ndarray, shape (n_sat, n_epoch)
    """
    along = v_ned[:, 0] * np.cos(wall_normal_rad) + v_ned[:, 1] * np.sin(wall_normal_rad)
    return np.abs(2.0 * np.cos(elevation_rad) * np.cos(azimuth_rad - wall_normal_rad) * along)


def slip_probability(sigma_cycles: np.ndarray, stress_cycles: np.ndarray, bandwidth_hz: float,
                     dt_s: float, pilot: bool) -> np.ndarray:
    """Probability of at least one cycle slip within an epoch interval dt: 1 - exp(-dt / T)
    with Viterbi's mean time to slip T = pi^2 rho I0(rho)^2 / (2 B_L) of the loop SNR
    rho = 1 / sigma_e^2, sigma_e = 2 pi (sigma + theta_e / 3) rad the loop's total phase error
    (thermal jitter plus a third of the dynamic stress, Kaplan & Hegarty's rule of thumb); a
    data channel's Costas loop has rho / 4 (its slips are half cycles). Computed in logs: T
    exceeds any float for a strong signal."""
    from scipy.special import i0e  # imported on first use: a drive without GNSS never pays for it

    sigma_rad = 2.0 * np.pi * (np.asarray(sigma_cycles) + np.asarray(stress_cycles) / 3.0)
    rho = 1.0 / np.maximum(sigma_rad, 1e-9) ** 2
    if not pilot:
        rho = rho / 4.0
    # log T = log(pi^2 rho / (2 B)) + 2 log I0(rho), I0(rho) = i0e(rho) e^rho
    log_t = np.log(np.pi**2 * rho / (2.0 * bandwidth_hz)) + 2.0 * (np.log(i0e(rho)) + rho)
    return -np.expm1(-np.exp(np.log(dt_s) - log_t))


def draw_slips(uniform: np.ndarray, probability: np.ndarray, tracked: np.ndarray
               ) -> np.ndarray:
    """Epochs (bool, shape of ``tracked``) at which a cycle slip occurred since the previous
    epoch, within continuous tracking: a Bernoulli draw of ``probability`` per epoch from
    ``uniform``, U(0, 1) draws of that shape."""
    before = np.zeros_like(tracked)
    before[:, 1:] = tracked[:, :-1]
    return tracked & before & (uniform < probability)


@dataclass
class PhaseArcs:
    """The arcs of continuous phase tracking of each row (satellite or signal) and what they
    put into the phase, all shape (rows, n_epoch): ``arc`` the arc's index (-1 untracked);
    ``ambiguity`` its integer cycles; ``half`` the half cycle (0 or 0.5) still in the phase;
    ``cycle_slip`` the integer jump at the epoch a slip happened (0 elsewhere); ``lli`` the
    RINEX loss-of-lock indicator; ``lock_time`` seconds since the arc began."""

    arc: np.ndarray
    ambiguity: np.ndarray
    half: np.ndarray
    cycle_slip: np.ndarray
    lli: np.ndarray
    lock_time: np.ndarray


def _arc_index(starts: np.ndarray, tracked: np.ndarray) -> np.ndarray:
    """Global arc number of every tracked sample (row-major order), -1 elsewhere."""
    number = np.cumsum(starts.ravel()).reshape(starts.shape) - 1
    return np.where(tracked, number, -1)


def phase_arcs(rng: np.random.Generator, tracked: np.ndarray, slips: np.ndarray,
               lost: np.ndarray, dt_s: float, pilot: bool, frame_s: float) -> PhaseArcs:
    """Arcs, ambiguities, half cycles, LLI and lock time of one signal's rows.

    An arc begins where tracking begins, after every loss of lock (``lost``: e.g. a switch
    between the direct and the reflected signal) and at every cycle slip (``slips``). An arc
    after a gap or a loss of lock gets a fresh ambiguity (uniform within +-2^20 cycles: the
    receiver's arbitrary initial count); a slip adds a nonzero integer jump (its magnitude
    geometric with p = 1/2, at most ``_MAX_SLIP_CYCLES``, random sign) to the ambiguity of the
    arc it ends. On a data channel (``pilot`` false) every arc begins with an unknown half
    cycle (0 or 0.5, equally likely) that the receiver resolves when the navigation message's
    preamble arrives, U(0, ``frame_s``) s after the arc began; until then the LLI's half-cycle
    bit is set (RINEX 3.04), after it the receiver has removed the half cycle. A slip is
    flagged with LLI bit 0 at its epoch; so is every arc's first epoch.
    """
    n_rows, n_ep = tracked.shape
    before = np.zeros_like(tracked)
    before[:, 1:] = tracked[:, :-1]
    fresh = tracked & (~before | lost)  # arcs with a new ambiguity
    slip = slips & ~fresh
    starts = fresh | slip
    arc = _arc_index(starts, tracked)
    n_arcs = int(starts.sum())
    is_fresh = fresh.ravel()[starts.ravel()]  # per arc, in arc order
    value = np.where(is_fresh, rng.integers(-(2**20), 2**20, n_arcs), 0)
    magnitude = np.minimum(rng.geometric(0.5, n_arcs), _MAX_SLIP_CYCLES)
    jump = np.where(is_fresh, 0, magnitude * rng.choice([-1, 1], n_arcs))
    # the ambiguity of an arc: its fresh value plus the jumps since (a cumulative sum restarted
    # at each fresh arc)
    total = np.cumsum(value + jump)
    fresh_idx = np.maximum.accumulate(np.where(is_fresh, np.arange(n_arcs), 0))
    ambiguity_per_arc = total - total[fresh_idx] + value[fresh_idx]
    half_per_arc = np.zeros(n_arcs)
    resolve_s = np.zeros(n_arcs)
    if not pilot:
        half_per_arc = 0.5 * (rng.random(n_arcs) < 0.5)
        resolve_s = rng.uniform(0.0, frame_s, n_arcs)
    if n_arcs == 0:  # nothing tracked: one placeholder arc for the (empty) look-ups below
        ambiguity_per_arc, half_per_arc, resolve_s, jump = (np.zeros(1) for _ in range(4))
    k = np.arange(n_ep)
    arc_start = np.maximum.accumulate(np.where(starts, k, 0), axis=1)
    lock_time = np.where(tracked, (k - arc_start) * dt_s, 0.0)
    safe = np.maximum(arc, 0)
    unresolved = tracked & (lock_time < resolve_s[safe])
    half = np.where(unresolved, half_per_arc[safe], 0.0)
    lli = (np.where(starts, LLI_LOST_LOCK, 0)
           | np.where(unresolved, LLI_HALF_CYCLE, 0)).astype(np.int8)
    return PhaseArcs(arc=arc, ambiguity=np.where(tracked, ambiguity_per_arc[safe], 0),
                     half=half, cycle_slip=np.where(slip, jump[safe], 0), lli=lli,
                     lock_time=lock_time)


def reflection_multipath(in_phase: np.ndarray, quadrature: np.ndarray, code_sigma_m: np.ndarray,
                         delay_m: float, frequency_offset_hz: float, wavelength_m: float
                         ) -> tuple[np.ndarray, np.ndarray]:
    """Code and carrier multipath (m) of one reflection on a signal ``frequency_offset_hz``
    above the reference frequency at which the reflection's relative amplitude and phase are
    alpha e^{i psi} = (code_sigma / d) (in_phase + i quadrature) (unit processes; d
    ``delay_m`` the reflection's extra path): at this signal the phase is turned by
    2 pi d df / c. Code error d alpha cos psi (so that the reference signal's code multipath is
    code_sigma x in_phase), carrier error (lambda / 2 pi) atan2(alpha sin psi,
    1 + alpha cos psi), alpha capped at 0.9 (Braasch 1996)."""
    turn = 2.0 * np.pi * delay_m * frequency_offset_hz / 299792458.0
    c, s = np.cos(turn), np.sin(turn)
    re = in_phase * c - quadrature * s
    im = in_phase * s + quadrature * c
    code = code_sigma_m * re
    alpha_scale = code_sigma_m / delay_m
    magnitude = alpha_scale * np.hypot(re, im)
    shrink = np.minimum(1.0, 0.9 / np.maximum(magnitude, 1e-12))
    a_re, a_im = alpha_scale * re * shrink, alpha_scale * im * shrink
    carrier = wavelength_m / (2.0 * np.pi) * np.arctan2(a_im, 1.0 + a_re)
    return code, carrier
