"""The receiver's error budget: draws every error term of the raw measurements (receiver clock,
signal-in-space error, ionosphere and troposphere residuals, multipath, code and carrier
tracking noise) for satellites x epochs, and the 1-sigma the receiver reports for weighting.

The processes themselves are in ``simulator.stochastic`` (Gauss-Markov) and
``simulator.gnss.receiver`` (two-state clock, DLL/FLL jitter, multipath shape); this module sets
how large each is and how they are shared.

Public names
------------
OSCILLATORS, CARRIER_SMOOTHING_TIME_S, SIS_CORRELATION_TIME_S, IONO_CORRELATION_TIME_S,
IONO_OWN_SHARE, REPORTED_PR_STD_FLOOR_M, REPORTED_RATE_STD_FLOOR_M_S, draw_receiver_clock,
draw_error_terms, pseudorange_sigma.

References
----------
Brown & Hwang 2012, Table 9.1 (oscillator h-parameters). Kaplan & Hegarty 2017, section 10.2
(the single-frequency error budget: satellite clock/ephemeris, ionosphere after the broadcast
correction, troposphere, multipath, receiver noise).
"""

from __future__ import annotations

import numpy as np

from simulator.gnss.constants import LAMBDA_L1_M
from simulator.gnss.receiver import clock_process, dll_sigma_m, fll_sigma_hz, multipath_sigma_m
from simulator.stochastic import gauss_markov

# receiver oscillators: Allan h-parameters (Brown & Hwang Table 9.1: compensated and ovenized
# crystal) and the 1-sigma spread of the clock state at switch-on
OSCILLATORS: dict[str, dict[str, float]] = {
    "tcxo": {"h0": 2e-19, "h_minus2": 2e-20, "bias_s": 1e-4, "drift_s_s": 5e-7},
    "ocxo": {"h0": 8e-20, "h_minus2": 4e-23, "bias_s": 1e-4, "drift_s_s": 1e-8},
    "ideal": {"h0": 0.0, "h_minus2": 0.0, "bias_s": 0.0, "drift_s_s": 0.0},
}
SIS_CORRELATION_TIME_S = 3600.0  # broadcast orbit/clock errors change over an upload cycle
IONO_CORRELATION_TIME_S = 1800.0  # residual of the Klobuchar model
IONO_OWN_SHARE = 0.5  # 1-sigma of the per-signal iono residual relative to the common one
# the code tracking error of a receiver that smooths its code with the carrier (Hatch filter):
# correlated over the smoothing time constant, the 100 s of RTCA DO-229 (SBAS airborne
# receivers) and DO-253 (GBAS airborne receivers). The automotive preset uses it: the
# fix error of a mass-market receiver changes by centimetres per second while driving, e.g.
# 0.036 m/s per axis in a u-blox log at 17.6 m/s (issue 19's measurement); a 1 m error
# correlated over 100 s changes by 1 m x sqrt(2 (1 - exp(-1/100))) = 0.14 m in a second.
CARRIER_SMOOTHING_TIME_S = 100.0
REPORTED_PR_STD_FLOOR_M = 0.1  # the smallest pseudorange 1-sigma the receiver reports
REPORTED_RATE_STD_FLOOR_M_S = 0.01  # the smallest pseudorange-rate 1-sigma it reports


def draw_receiver_clock(rng: np.random.Generator, oscillator: str, n: int, dt_s: float
                        ) -> tuple[np.ndarray, np.ndarray, dict]:
    """Receiver clock bias (s) and drift (s/s) at n epochs, and the drawn initial state."""
    osc = OSCILLATORS[oscillator]
    bias0 = osc["bias_s"] * rng.standard_normal()
    drift0 = osc["drift_s_s"] * rng.standard_normal()
    bias, drift = clock_process(n, dt_s, osc["h0"], osc["h_minus2"], bias0, drift0, rng)
    return bias, drift, {"oscillator": oscillator, "bias_s": bias0, "drift_s_s": drift0}


def draw_error_terms(rng: np.random.Generator, cfg: dict, elevation_rad: np.ndarray,
                     cn0_dbhz: np.ndarray, dt_s: float) -> dict[str, np.ndarray]:
    """Every error term of the raw measurements, shape (n_sat, n_epoch) unless noted.

    Parameters
    ----------
    cfg : dict
        The resolved ``sensors.gnss`` block (error levels and tracking-loop parameters).
    elevation_rad, cn0_dbhz : ndarray, shape (n_sat, n_epoch)
        Elevation and C/N0 of each signal.
    dt_s : float
        Epoch interval.

    Returns
    -------
    dict with ``sis`` (m); ``iono_ratio`` (true / broadcast ionosphere: the residual common to
    all signals plus ``IONO_OWN_SHARE`` times an independent one per signal); ``tropo_zenith``
    (scalar, m: the zenith troposphere the model misses, for the whole drive); ``multipath`` and
    ``multipath_sigma`` (m); ``code_noise`` and ``code_sigma`` (m); ``rate_noise`` and
    ``rate_sigma`` (m/s).

    The code error keeps its 1-sigma (the DLL jitter for the signal's C/N0, Kaplan & Hegarty
    2017 eq. 8.76 via ``dll_sigma_m``) and is, with ``code_correlation_time`` T > 0, a unit
    first-order Gauss-Markov process times that sigma, correlated over T, as the code of a
    carrier-smoothing receiver is; T = 0 draws it white per epoch. Choice: a Hatch filter of
    time constant T would also lower the white jitter's variance by about dt / (2 T); the
    preset's error level is kept instead (the ``tracking_noise`` scale describes the error the
    receiver delivers), so the fix scatter stays that of the preset and only its time behaviour
    changes. The multiplier on sigma(t) follows the C/N0 of each epoch. The code multipath goes
    through the same smoothing, so its correlation time is the longer of
    ``multipath_correlation_time`` and T (its level kept likewise).
    """
    shape = elevation_rad.shape
    n_sat, n_ep = shape
    scale = cfg["tracking_noise"]

    def unit_gm(rows: int, tau_s: float) -> np.ndarray:  # (rows, n_ep), unit variance
        return gauss_markov(n_ep, dt_s, np.ones(rows), tau_s, rng).T

    out = {"sis": cfg["sis_error"] * unit_gm(n_sat, SIS_CORRELATION_TIME_S)}
    common = unit_gm(1, IONO_CORRELATION_TIME_S)
    own = unit_gm(n_sat, IONO_CORRELATION_TIME_S)
    out["iono_ratio"] = 1.0 + cfg["iono_residual"] * (common + IONO_OWN_SHARE * own)
    out["tropo_zenith"] = cfg["tropo_residual"] * rng.standard_normal()
    out["multipath_sigma"] = multipath_sigma_m(elevation_rad, cfg["multipath"])
    tau_code = cfg["code_correlation_time"]
    tau_multipath = max(cfg["multipath_correlation_time"], tau_code)
    out["multipath"] = out["multipath_sigma"] * unit_gm(n_sat, tau_multipath)
    out["code_sigma"] = scale * dll_sigma_m(cn0_dbhz, cfg["dll_bandwidth"],
                                            cfg["correlator_spacing"], cfg["integration_time"])
    out["code_noise"] = out["code_sigma"] * (unit_gm(n_sat, tau_code) if tau_code > 0
                                             else rng.standard_normal(shape))
    out["rate_sigma"] = scale * LAMBDA_L1_M * fll_sigma_hz(cn0_dbhz, cfg["fll_bandwidth"],
                                                          cfg["integration_time"])
    out["rate_noise"] = out["rate_sigma"] * rng.standard_normal(shape)
    return out


def pseudorange_sigma(cfg: dict, terms: dict[str, np.ndarray], iono_m: np.ndarray,
                      tropo_mapping: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The 1-sigma of each pseudorange (m) and pseudorange rate (m/s) the receiver reports:
    the root sum of squares of the configured budget (code noise, multipath, ionosphere residual
    common and own, troposphere zenith residual times the mapping, signal-in-space error), with
    floors of 0.1 m and 0.01 m/s.

    Parameters
    ----------
    terms : dict
        From ``draw_error_terms`` (the sigmas).
    iono_m : ndarray
        Broadcast ionosphere delay of each signal, m.
    tropo_mapping : ndarray
        Slant / zenith troposphere of each signal.
    """
    var = (terms["code_sigma"] ** 2 + terms["multipath_sigma"] ** 2
           + (1.0 + IONO_OWN_SHARE**2) * (cfg["iono_residual"] * iono_m) ** 2
           + (cfg["tropo_residual"] * tropo_mapping) ** 2 + cfg["sis_error"] ** 2)
    return (np.maximum(np.sqrt(var), REPORTED_PR_STD_FLOOR_M),
            np.maximum(terms["rate_sigma"], REPORTED_RATE_STD_FLOOR_M_S))
