"""Random error processes (white noise, random walk, first-order Gauss-Markov, AR(1), flicker),
generated vectorised and discretised exactly, their discrete models and their analytic Allan
variances: the one home of the processes the sensors draw and the estimators model.

Every process here is defined in continuous time and sampled exactly at the sample times, so its
statistics do not depend on the sample rate (a first-order Gauss-Markov process is the exact
AR(1) recursion, run vectorised in blocks in ``ar1_filter``; scipy is not imported, so that
generating a dataset stays quick to start).

Conventions (IEEE Std 952-1997, Annex C): a white rate noise of density N (unit/sqrt(Hz)) has
Allan variance N^2 / tau; a rate random walk of density K (unit/s/sqrt(Hz)) has K^2 tau / 3; a
flicker ("bias instability") noise with two-sided power spectral density B^2 / (2 pi f) has the flat
Allan deviation sqrt(2 ln 2 / pi) B = 0.664 B; an exponentially correlated ("Markov") noise of
stationary std sigma and correlation time T_c has Allan variance
sigma^2 (T_c / tau)^2 (2 tau / T_c - 3 + 4 exp(-tau / T_c) - exp(-2 tau / T_c)) (IEEE Std 952,
Annex C, Markov noise, with sigma^2 = q_c^2 T_c / 2), rising as sqrt(tau) well below T_c, peaking at
0.617 sigma at 1.89 T_c and falling as 1 / sqrt(tau) beyond.

Public names
------------
FLICKER_ADEV_FACTOR, GM_ADEV_PEAK, GM_ADEV_PEAK_TAU, FLICKER_TAUS_S, gm_adev_peak,
gauss_markov_continuous, gauss_markov_discrete,
ar1_filter, white, random_walk, gauss_markov, gauss_markov_at, flicker, gauss_markov_avar,
flicker_avar, adev_model, stream_rng, child_rng.

References
----------
IEEE Std 952-1997, *IEEE Standard Specification Format Guide and Test Procedure for Single-Axis
Interferometric Fiber Optic Gyros*, Annex C (Allan variance of the noise terms).
Gelb, *Applied Optimal Estimation*, 1974, Table 3.8-1 (exact discrete first-order Markov process).
Brown & Hwang, *Introduction to Random Signals and Applied Kalman Filtering*, 4th ed., chapters 2
and 3: a Gauss-Markov process x' = -x / tau + w, E[w(t) w(s)] = q_c delta(t - s) with
q_c = 2 sigma^2 / tau keeps the stationary std sigma; over a step dt, phi = exp(-dt / tau) and
q_d = sigma^2 (1 - exp(-2 dt / tau)).
Keshner, "1/f noise", Proc. IEEE 70(3), 1982 (1/f spectrum as a sum of Lorentzians with
log-uniform time constants).
"""

from __future__ import annotations

import zlib

import numpy as np

# Allan deviation floor of flicker noise per unit bias instability, sqrt(2 ln 2 / pi) (IEEE 952)
FLICKER_ADEV_FACTOR = float(np.sqrt(2.0 * np.log(2.0) / np.pi))

# time constants of the Gauss-Markov processes whose sum makes the flicker floor: two per decade
# from 0.1 s to 1e5 s, fixed (not tied to the sample rate, so the process is rate independent);
# the floor is flat within 1 % from about 1 s to 1e4 s
FLICKER_TAUS_S = 10.0 ** (np.arange(-2, 11) / 2.0)
_FLICKER_RATIO = 10.0 ** 0.5  # ratio of consecutive time constants
# a flicker component slower than this many samples per correlation time is generated exactly on
# a coarser grid of this many points per correlation time and interpolated linearly (the part of
# its variance the interpolation misses is about 1 / (2 x 64), under 1 %)
_POINTS_PER_TAU = 64


def gauss_markov_continuous(tau: np.ndarray, sigma: np.ndarray
                            ) -> tuple[np.ndarray, np.ndarray]:
    """Continuous model of first-order Gauss-Markov processes.

    Parameters
    ----------
    tau : float or array, shape (k,)
        Correlation times, s.
    sigma : float or array, shape (k,)
        Steady-state standard deviations (any unit u).

    Returns
    -------
    f : (k,) diagonal of the system matrix, -1 / tau, 1/s; q_c : (k,) white-noise power
    spectral densities 2 sigma^2 / tau, u^2/s.
    """
    tau = np.asarray(tau, dtype=float)
    sigma = np.asarray(sigma, dtype=float)
    return -1.0 / tau, 2.0 * sigma**2 / tau


def gauss_markov_discrete(tau: np.ndarray, sigma: np.ndarray, dt: float
                          ) -> tuple[np.ndarray, np.ndarray]:
    """Exact discrete model of first-order Gauss-Markov processes over a step ``dt`` (s).

    Returns
    -------
    phi : (k,) transition factors exp(-dt / tau); q_d : (k,) discrete noise variances
    sigma^2 (1 - exp(-2 dt / tau)).
    """
    tau = np.asarray(tau, dtype=float)
    sigma = np.asarray(sigma, dtype=float)
    phi = np.exp(-dt / tau)
    return phi, sigma**2 * -np.expm1(-2.0 * dt / tau)


def _gm_avar_unit(x: np.ndarray) -> np.ndarray:
    """Allan variance of a unit-variance Gauss-Markov process at tau = x * correlation time."""
    x = np.asarray(x, dtype=float)
    small = x < 1e-4
    xs = np.where(small, 1.0, x)
    full = (2 * xs - 3 + 4 * np.exp(-xs) - np.exp(-2 * xs)) / xs**2
    return np.where(small, 2.0 * x / 3.0, full)


# Allan deviation peak of a unit-variance Gauss-Markov process and where it sits (in correlation
# times): the maximum of sqrt(_gm_avar_unit) on a grid of step 1e-5 from 1 to 3 correlation
# times, written out because the search costs 15 ms at every start (``gm_adev_peak`` redoes it;
# the tests check the two agree)
GM_ADEV_PEAK = 0.6173642831443085
GM_ADEV_PEAK_TAU = 1.89262


def gm_adev_peak() -> tuple[float, float]:
    """(GM_ADEV_PEAK, GM_ADEV_PEAK_TAU) computed: the grid search they come from."""
    x = np.linspace(1.0, 3.0, 200_001)
    avar = _gm_avar_unit(x)
    return float(np.sqrt(avar.max())), float(x[np.argmax(avar)])


# largest exponent |ln phi| k used inside one block of ``ar1_filter`` (e^300 = 2e130: the scaled
# inputs stay far from overflow), and the longest block (its factor tables stay in the cache)
_AR1_BLOCK_LOG_RANGE = 300.0
_AR1_MAX_BLOCK = 4096


def ar1_filter(u: np.ndarray, phi: float | np.ndarray, overwrite: bool = False,
               gain_in: float | np.ndarray = 1.0,
               gain_out: float | np.ndarray = 1.0) -> np.ndarray:
    """x[k] = phi x[k-1] + gain_in u[k] along axis 0, x[-1] = 0 (the first-order recursion of an
    exact Gauss-Markov discretisation), returned times ``gain_out``, vectorised without a loop
    over the samples.

    ``phi`` (0 <= phi <= 1) and the gains are one number, or one per column of a 2-D ``u`` (shape
    (m,)). A complex ``phi`` (|phi| <= 1, a damped rotation: one mode of a linear system, such
    as the ride model's, ``simulator.vehicle.suspension``) filters complex ``u`` the same way,
    with complex powers phi^j.
    Blocks of L samples are solved in closed form, x[j] = phi^j (S[j] + phi c) with
    S[j] = cumsum(phi^-i gain_in u[i]) and c the state at the end of the previous block (L
    chosen so that phi^-L stays below e^300 for every column, at most 4096; the rounding error
    stays that of the recursion, since each partial sum is scaled back by phi^j). The block-end
    states follow from the same recursion on the block ends (factor phi^L). Four passes over the
    data whatever phi, the gains folded into the first and the last; a factor too small for
    blocks of two (phi < e^-150) falls back to recursive doubling, which then stops after a few
    passes once phi^(2^p) underflows. With ``overwrite`` a C-contiguous float array ``u`` is
    filtered in place (no copy).
    """
    kind = complex if np.iscomplexobj(phi) or np.iscomplexobj(u) else float
    in_place = overwrite and u.dtype == kind and u.flags.c_contiguous  # blocks are views
    x = u if in_place else np.array(u, dtype=kind, order="C")
    flat = x.ndim == 1
    if flat:
        x = x[:, None]
    n, m = x.shape
    phi = np.broadcast_to(np.asarray(phi, dtype=kind), (m,))
    gain_in = np.broadcast_to(np.asarray(gain_in, dtype=float), (m,))
    gain_out = np.broadcast_to(np.asarray(gain_out, dtype=float), (m,))
    if n == 0 or m == 0:
        return x[:, 0] if flat else x
    with np.errstate(divide="ignore"):
        decay = -np.log(phi)  # -ln phi per column (its real part |ln |phi||), inf for phi = 0
    fastest = float(decay.real.max())
    length = min(n, _AR1_MAX_BLOCK)
    if fastest > _AR1_BLOCK_LOG_RANGE / length:
        length = int(_AR1_BLOCK_LOG_RANGE / fastest)
    if length < 2:
        x *= gain_in
        power, shift = phi.copy(), 1
        while shift < n and np.any(np.abs(power) > 0.0):
            x[shift:] += power * x[:-shift]
            power, shift = power * power, shift * 2
        x *= gain_out
        return x[:, 0] if flat else x
    j = np.arange(length)[:, None]
    up, down = gain_in * np.exp(j * decay), gain_out * np.exp(-j * decay)
    blocks = n // length
    full = x[:blocks * length].reshape(blocks, length, m)
    tail = x[blocks * length:]
    full *= up
    np.cumsum(full, axis=1, out=full)
    tail *= up[:len(tail)]
    np.cumsum(tail, axis=0, out=tail)
    # the state at the end of block b: c[b] = phi^(L-1) S_b[L-1] + phi^L c[b-1]
    ends = ar1_filter(full[:, -1, :] * np.exp(-(length - 1) * decay), np.exp(-length * decay))
    carried = phi * ends  # what each block's state adds to the next block's partial sums
    full[1:] += carried[:-1, None, :]
    tail += carried[-1]
    full *= down
    tail *= down[:len(tail)]
    return x[:, 0] if flat else x


def white(n: int, dt_s: float, density: np.ndarray, rng: np.random.Generator,
          increment: bool = False) -> np.ndarray:
    """Samples of white noise of two-sided density ``density`` (per axis, shape (m,)).

    Rate output: sigma = N / sqrt(dt); increment output (the noise integrated over each
    interval): sigma = N * sqrt(dt). Returns shape (n, m).
    """
    density = np.atleast_1d(np.asarray(density, dtype=float))
    scale = np.sqrt(dt_s) if increment else 1.0 / np.sqrt(dt_s)
    noise = rng.standard_normal((n, density.size))
    noise *= density * scale
    return noise


def random_walk(n: int, dt_s: float, density: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Random walk b(k dt) = K * W(k dt) sampled exactly, b(0) = 0; K per axis (unit/s/sqrt(Hz)).

    Allan variance K^2 tau / 3 (IEEE Std 952, Annex C). Returns shape (n, m).
    """
    density = np.atleast_1d(np.asarray(density, dtype=float))
    steps = rng.standard_normal((n, density.size))
    steps *= density * np.sqrt(dt_s)
    steps[0] = 0.0
    return np.cumsum(steps, axis=0, out=steps)


def gauss_markov(n: int, dt_s: float, sigma: np.ndarray, tau_s: float | np.ndarray,
                 rng: np.random.Generator, columns: np.ndarray | None = None) -> np.ndarray:
    """Stationary first-order Gauss-Markov process, exact discretisation (Gelb 1974, Table 3.8-1).

    x[k+1] = exp(-dt/tau) x[k] + sigma sqrt(1 - exp(-2 dt/tau)) w[k], x[0] ~ N(0, sigma^2).

    Parameters
    ----------
    n : number of samples.
    dt_s : sample interval, s.
    sigma : stationary standard deviation per axis, shape (m,).
    tau_s : correlation time, s: one for all axes or one per axis, shape (m,).
    columns : only these axes (indices into the m) are returned: all m are drawn, as without
        ``columns``, and only these filtered (each axis is filtered alone, so they are the
        same numbers); one ``tau_s`` for all axes.

    Returns
    -------
    ndarray, shape (n, m), or (n, len(columns))
    """
    sigma = np.atleast_1d(np.asarray(sigma, dtype=float))
    phi, q_unit = gauss_markov_discrete(tau_s, 1.0, dt_s)
    drive = rng.standard_normal((n, sigma.size))
    drive[0] = rng.standard_normal(sigma.size)  # the stationary state x[0] / sigma
    if columns is not None:
        if np.ndim(tau_s) != 0:
            raise ValueError("columns needs one correlation time for all axes")
        drive, sigma = drive[:, columns], sigma[columns]
    drive[0] /= np.sqrt(q_unit)  # which the filter's gain_in turns back into N(0, 1)
    return ar1_filter(drive, phi, overwrite=True, gain_in=np.sqrt(q_unit), gain_out=sigma)


# the largest step (in correlation lengths) ``gauss_markov_at`` carries a state across: beyond it
# the correlation exp(-step) is below 1e-13 and the state restarts (the exponents of one block
# then stay within _AR1_BLOCK_LOG_RANGE however sparse the points)
_GM_MAX_STEP = 30.0


def gauss_markov_at(points: np.ndarray, rows: int, rng: np.random.Generator,
                    columns: np.ndarray | None = None) -> np.ndarray:
    """Unit-variance Gauss-Markov processes sampled exactly at ascending points (shape (n,), in
    correlation lengths: any coordinate along which the process decorrelates, such as time /
    tau or distance / D), one per column: shape (n, rows), correlation exp(-|p_i - p_j|).

    The exact discretisation of a first-order Markov process between unequally spaced points
    (Gelb 1974, Table 3.8-1, with a step of its own per interval): x_0 ~ N(0, 1),
    x_k = e^{-dp_k} x_{k-1} + sqrt(1 - e^{-2 dp_k}) w_k. Solved without a loop over the samples,
    as ``ar1_filter`` does: over a block of points within ``_AR1_BLOCK_LOG_RANGE`` of its first
    point p_b, x_k = e^{-(p_k - p_b)} (e^{-(p_b - p_{b-1})} x_{b-1}
    + cumsum_j e^{p_j - p_b} g_j w_j), one pass per block (about (p_n - p_0) / 300 of them).
    With ``columns`` (indices into the rows), only those processes: all are drawn, and only
    these solved (each alone: the same numbers).
    """
    p = np.asarray(points, dtype=float)
    n = len(p)
    x = rng.standard_normal((n, rows))
    if columns is not None:
        x = x[:, columns]
    if n < 2:
        return x
    step = np.diff(p)
    gain = np.sqrt(-np.expm1(-2.0 * step))  # the innovations' std, the first sample's is 1
    x[1:] *= gain[:, None]
    # the decorrelation accumulated along the points, each step capped (module constant)
    s = np.concatenate([[0.0], np.cumsum(np.minimum(step, _GM_MAX_STEP))])
    start, carry = 0, None
    while start < n:  # one pass per block of points within the log range of its first
        end = max(int(np.searchsorted(s, s[start] + _AR1_BLOCK_LOG_RANGE, side="right")),
                  start + 1)
        rel = s[start:end] - s[start]
        block = x[start:end]
        block *= np.exp(rel)[:, None]
        if carry is not None:
            block[0] += np.exp(-(s[start] - s[start - 1])) * carry
        np.cumsum(block, axis=0, out=block)
        block *= np.exp(-rel)[:, None]
        carry = block[-1]
        start = end
    return x


def flicker(n: int, dt_s: float, instability: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Flicker (1/f) bias with the flat Allan floor 0.664 B, as a sum of Gauss-Markov processes.

    Lorentzians with log-uniformly spaced time constants (``FLICKER_TAUS_S``, ratio r between
    neighbours) each of variance B^2 ln(r) / pi sum to the two-sided spectrum B^2 / (2 pi f)
    between 1 / (2 pi tau_max) and 1 / (2 pi tau_min) (Keshner 1982). Components with more than
    128 samples per correlation time run exactly on a grid of tau / 64 and are interpolated.

    Parameters
    ----------
    n : number of samples.
    dt_s : sample interval, s.
    instability : bias instability B per axis, shape (m,).

    Returns
    -------
    ndarray, shape (n, m)
    """
    instability = np.atleast_1d(np.asarray(instability, dtype=float))
    sigma = instability * np.sqrt(np.log(_FLICKER_RATIO) / np.pi)
    m = instability.size
    slowest_first = sorted(FLICKER_TAUS_S, reverse=True)
    fast = [tau for tau in slowest_first if tau / _POINTS_PER_TAU < 2 * dt_s]
    if fast:  # the components run at the sample rate: one recursion, a column per term and axis
        terms = gauss_markov(n, dt_s, np.tile(sigma, len(fast)), np.repeat(fast, m), rng)
        # column blocks added (4x quicker than a reshaped sum)
        total = terms[:, :m] + terms[:, m:2 * m] if len(fast) > 1 else terms[:, :m].copy()
        for j in range(2, len(fast)):
            total += terms[:, j * m:(j + 1) * m]
    else:
        total = np.zeros((n, m))
    # slow components, slowest first, each on its own grid of tau / 64; the running sum is carried
    # down to each finer grid, and to the sample times once at the end
    t_end = (n - 1) * dt_s
    grid, slow = None, None
    for tau in slowest_first[:len(slowest_first) - len(fast)]:
        step = tau / _POINTS_PER_TAU
        fine = np.arange(int(np.ceil(t_end / step)) + 2) * step
        part = gauss_markov(len(fine), step, sigma, tau, rng)
        if slow is not None:
            part += _interp_columns(fine, grid, slow)
        grid, slow = fine, part
    if slow is not None:
        t = np.arange(n) * dt_s
        for j in range(m):
            total[:, j] += np.interp(t, grid, slow[:, j])
    return total


def _interp_columns(x: np.ndarray, xp: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """Linear interpolation of each column of fp (len(xp), m) at x."""
    return np.stack([np.interp(x, xp, fp[:, j]) for j in range(fp.shape[1])], axis=1)


def gauss_markov_avar(tau_s: np.ndarray, sigma: float, corr_time_s: float) -> np.ndarray:
    """Allan variance of a Gauss-Markov process of std ``sigma`` and correlation time tau_c.

    AVAR(T) = sigma^2 (tau_c / T)^2 (2 T / tau_c - 3 + 4 exp(-T / tau_c) - exp(-2 T / tau_c)).
    """
    return sigma**2 * _gm_avar_unit(np.asarray(tau_s, dtype=float) / corr_time_s)


def flicker_avar(tau_s: np.ndarray, instability: float) -> np.ndarray:
    """Allan variance of the sum-of-Gauss-Markov flicker process made by ``flicker``."""
    sigma = instability * np.sqrt(np.log(_FLICKER_RATIO) / np.pi)
    return sum(gauss_markov_avar(tau_s, sigma, tau) for tau in FLICKER_TAUS_S)


def adev_model(tau_s: np.ndarray, noise_density: float = 0.0, bias_instability: float = 0.0,
               random_walk_density: float = 0.0, ramp: float = 0.0,
               correlation_time_s: float | None = None, markov_sigma: float = 0.0,
               markov_time_s: float | None = None) -> np.ndarray:
    """Allan deviation of white noise + bias instability + random walk + rate ramp
    (IEEE Std 952, Annex C: N^2 / tau, K^2 tau / 3, R^2 tau^2 / 2) + an optional exponentially
    correlated (Markov) bias of std ``markov_sigma`` and correlation time ``markov_time_s``
    (``gauss_markov_avar``).

    The bias instability B is a Gauss-Markov process whose Allan peak is 0.664 B when a
    correlation time is given, and the flicker sum of ``flicker`` otherwise. The Markov bias is a
    separate process, added to either (the terms are independent, so their variances add).
    """
    tau_s = np.asarray(tau_s, dtype=float)
    avar = (noise_density**2 / tau_s + random_walk_density**2 * tau_s / 3.0
            + ramp**2 * tau_s**2 / 2.0)
    if bias_instability > 0:
        if correlation_time_s:
            sigma = FLICKER_ADEV_FACTOR * bias_instability / GM_ADEV_PEAK
            avar = avar + gauss_markov_avar(tau_s, sigma, correlation_time_s)
        else:
            avar = avar + flicker_avar(tau_s, bias_instability)
    if markov_sigma > 0:
        avar = avar + gauss_markov_avar(tau_s, markov_sigma, markov_time_s)
    return np.sqrt(avar)


def stream_rng(seed: int, name: str) -> np.random.Generator:
    """The random stream named ``name`` (a sensor, the road) of a scenario's ``seed``: a
    SeedSequence child keyed by the name, so adding a stream does not change the others (SPEC
    section 2). The bit generator is numpy's SFC64 (Doty-Humphrey's Small Fast Chaotic
    generator; expected period 2^255, and a 64-bit counter keeps distinct seeds apart for at
    least 2^64 draws, per numpy's documentation): the IMU of an hour draws some 15 million
    normals, 8 % quicker than with the default PCG64."""
    return np.random.Generator(np.random.SFC64(np.random.SeedSequence(seed, spawn_key=(
        zlib.crc32(name.encode()),))))


def child_rng(rng: np.random.Generator, name: str) -> np.random.Generator:
    """The random stream named ``name`` inside the stream ``rng`` (one error process of a
    sensor): the SeedSequence child of ``rng``'s seed keyed by the name (its spawn key extended
    by the name's CRC-32), with ``rng``'s bit generator. It depends only on ``rng``'s seed and
    the name, never on how many draws ``rng`` or any other child has made, so a process that
    changes how many numbers it draws redraws no other process."""
    seq = rng.bit_generator.seed_seq
    return np.random.Generator(type(rng.bit_generator)(np.random.SeedSequence(
        seq.entropy, spawn_key=(*seq.spawn_key, zlib.crc32(name.encode())),
        pool_size=seq.pool_size)))
