"""One receiver's raw measurements of every signal it tracks: the geometry of each satellite,
the error terms (its own and those it shares with a second receiver of the same drive), and
code, Doppler, C/N0 and carrier phase per signal, as stream rows.

The rover (``sensors.gnss``) and the base station (``sensors.gnss_base``) run ``observe`` on the
same broadcast records and epochs; the base takes the rover's ``Shared`` draws (signal-in-space
error, the two ionosphere fields, the troposphere residual and its gradient, the orbit error
vectors), so that what differs between them is what their separation makes differ:

- the ionosphere: the regional field (1000 km) and the travelling disturbances (150 km,
  ``TID_LENGTH_KM``) evaluated at each receiver's own pierce points;
- the troposphere: the zenith residual plus a horizontal gradient held for the drive;
- the orbit: each broadcast record's orbit error vector (``ORBIT_ERROR_M`` per axis) projected
  on each receiver's line of sight (the classic |dr| b / rho of relative positioning).

Measurement model of signal s at frequency f (lambda = c / f), in metres, gamma_s = (f_L1/f)^2:

    pseudorange = range + receiver_clock - sat_clock_s + gamma_s I + T + sis + m_code_s
                  + nlos_delay + code_noise_s
    carrier_phase lambda = range + receiver_clock - (sat_clock_s + group_delay_s) - gamma_s I
                  + T + sis + m_carrier_s + nlos_delay + phase_noise_s
                  + lambda (ambiguity + half_cycle)

(``sat_clock_s`` = c (dt_sv - G_s) the clock a user of the signal applies, ``group_delay_s`` =
c G_s the code's group delay against the broadcast clock's reference, per system and signal
from T_GD, BGD or TGD1/TGD2: ``simulator.gnss.signals.signal_group_delay_s``; the carrier
carries no hardware delay). The carrier phase has RINEX's sign: it grows with the range, as
the pseudorange does.

How it is computed: only the satellites that may rise above the horizon during the drive
(``signal_geometry_chunks``) are measured; every random process is still drawn for every
satellite of the sky, in the same order, and the measured ones keep theirs, so a draw never
depends on which satellites rise. What runs along the epochs (the draws, the carrier
smoothing, the phase arcs, the rates by central differences) sees the whole drive; what is
elementwise over satellites x epochs is computed a chunk of epochs at a time
(``simulator.gnss.chunks``), and each signal's rows go straight to their places in the tables.
The numbers are those of one pass over the whole drive (the chunk size changes none of them).

Random streams: every error process draws from its own stream, the child of the receiver's
stream (the rover's: the sensor stream ``gnss``) named after the process
(``simulator.stochastic.child_rng``), so a process that draws more or fewer numbers (a new
model, a speed-up) redraws no other one, and the same scenario and seed give the same files:

- drawn once per drive or per satellite: ``receiver_clock`` (initial bias and drift, then the
  oscillator's noise), ``sis`` (per satellite and broadcast record), ``iono_field`` (the
  regional field's waves), ``tropo_zenith``; shared with a second receiver, and drawn by the
  first only: ``iono_tid``, ``tropo_gradient``, ``orbit_error``; the canyon zones' buildings
  and facade losses, one stream per zone named after it, in the child ``environment``;
- along the drive, for every satellite: ``cn0_fading``, ``cn0_noise``, ``multipath`` (its
  in-phase unit process), ``multipath_quadrature``, ``reflector_normal``, ``code_noise`` and
  ``rate_noise`` (the primary signals' tracking noise);
- per signal, named ``<system letter><RINEX code>/<process>`` (e.g. ``E5Q/phase_noise``):
  ``cn0_noise``, ``code_noise`` and ``rate_noise`` (signals other than the primary one),
  ``phase_noise``, ``cycle_slips``, ``phase_arcs`` (ambiguities, slip sizes, half cycles);
- ``second_receiver``: the base station's own stream, from which it names its processes as
  above (it draws none of the shared ones).

Public names
------------
TID_LENGTH_KM, TID_TIME_S, ORBIT_ERROR_M, Shared, Observed, observe, signal_geometry_chunks.

References
----------
Travelling ionospheric disturbances: Hernandez-Pajares, Juan & Sanz, "Medium-scale traveling
ionospheric disturbances affecting GPS measurements: spatial and temporal analysis", J.
Geophys. Res. 111, A07S11, 2006 (wavelengths 100-300 km, periods 10-60 min).
Broadcast orbit errors of about a metre per axis: Montenbruck, Steigenberger & Hauschild,
"Broadcast versus precise ephemerides: a multi-GNSS perspective", GPS Solutions 19, 2015.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from simulator import columns as col
from simulator.earth import ecef_to_ned, geodetic_rates
from simulator.gnss.atmosphere import broadcast_delays, klobuchar_obliquity
from simulator.gnss.carrier import (
    draw_slips,
    dynamic_stress_cycles,
    phase_arcs,
    pll_response,
    pll_sigma_cycles,
    reflection_multipath,
    reflection_path_rate_m_s,
    slip_probability,
)
from simulator.gnss.chunks import epoch_chunks
from simulator.gnss.constants import C_M_S, F_L1_HZ
from simulator.gnss.ephemeris import STATE_KEYS, gather, satellite_state
from simulator.gnss.errors import (
    IonoField,
    decorrelation_coordinate,
    draw_error_terms,
    draw_fading,
    draw_receiver_clock,
    gauss_markov_along,
    loop_time_constant_s,
    pierce_points_km,
    pseudorange_sigma,
    smooth_code_errors,
)
from simulator.gnss.receiver import (
    cn0_model,
    dll_sigma_m,
    fll_sigma_hz,
    look_angles,
    signal_geometry,
)
from simulator.gnss.signals import (
    PRIMARY_SIGNAL,
    carrier_frequency_hz,
    iono_factor,
    signal,
    signal_group_delay_s,
)
from simulator.gnss.timesystems import SYSTEMS
from simulator.stochastic import child_rng, gauss_markov

if TYPE_CHECKING:
    import pandas as pd

TID_LENGTH_KM = 150.0  # correlation length of the travelling disturbances' field
TID_TIME_S = 900.0  # their correlation time
ORBIT_ERROR_M = 1.0  # broadcast orbit error per axis, 1-sigma
_CA_CHIP_RATE_HZ = 1.023e6


@dataclass
class Shared:
    """The draws two receivers of one drive share (module docstring)."""

    sis: np.ndarray
    iono_field: IonoField | None
    tid: IonoField
    tid_sigma_m: float
    tropo_zenith_m: float
    tropo_gradient: np.ndarray  # zenith residual change per metre north, east
    orbit_m: np.ndarray  # per broadcast record, (n_records, 3)
    origin_lla: tuple[float, float, float]
    los_rows: np.ndarray  # the satellites (rows of the sky) the first receiver measured
    los: np.ndarray  # its lines of sight to them (len(los_rows), n_epoch, 3)
    second_rng: np.random.Generator  # the second receiver's own random stream


@dataclass
class Observed:
    raw: pd.DataFrame
    truth: pd.DataFrame
    clock_m: np.ndarray
    drift_m_s: np.ndarray
    drawn: dict
    shared: Shared


class _Table:
    """One stream table's rows: each signal's (satellite, epoch) samples where its mask is set,
    written straight to their places in the table's columns, which are in the order of epochs,
    then satellites (PRN order), then the receiver's signals. The places are a counting rank:
    every signal's mask is known before the first signal's rows are written, so nothing is
    sorted, and each column is allocated once, at the table's size. A text value (one per
    signal) is spread over the signal's rows."""

    def __init__(self, t: np.ndarray, svs: np.ndarray,
                 masks: list[tuple[np.ndarray, np.ndarray]]):
        """``masks``: per signal in the receiver's order, its satellites' rows of ``svs`` and
        its (satellite, epoch) mask of the samples that are rows."""
        self.t, self.svs = t, svs
        count = np.zeros((len(svs), len(t)), dtype=np.int32)
        for sel, mask in masks:  # one pass per signal
            count[sel] += mask
        per_slot = count.T.ravel()  # epoch by epoch, satellites in order
        # each (epoch, satellite)'s first row, moved on as each of its signals takes its row
        self.next_row = np.cumsum(per_slot, dtype=np.int64) - per_slot
        self.n_rows = int(per_slot.sum())
        self.columns: dict[str, np.ndarray] = {}
        self.texts: dict[str, list[str]] = {}  # a text column's distinct values; its codes
        # are in ``columns``

    def _write(self, key: str, rows: np.ndarray, values: np.ndarray) -> None:
        """``values`` into column ``key`` at ``rows``; a column whose values come in several
        types takes the type they all fit (as concatenating them would)."""
        column = self.columns.get(key)
        if column is None:
            column = self.columns[key] = np.empty(self.n_rows, dtype=values.dtype)
        elif column.dtype != values.dtype:
            kind = np.promote_types(column.dtype, values.dtype)
            if kind != column.dtype:
                column = self.columns[key] = column.astype(kind)
        column[rows] = values

    def add(self, sel: np.ndarray, mask: np.ndarray, columns: dict[str, np.ndarray | str],
            first_epoch: int = 0) -> None:
        """The next signal's rows: ``columns`` of (satellite, epoch) arrays over ``sel``'s
        satellites (or broadcastable to them; a text value stays one text) where ``mask``,
        whose epochs begin at ``first_epoch`` (a chunk of the drive's)."""
        sat, ep = np.nonzero(mask)
        slot = (first_epoch + ep) * len(self.svs) + sel[sat]
        rows = self.next_row[slot]
        self.next_row[slot] += 1
        self._write("t", rows, self.t[first_epoch + ep])
        self._write("sv", rows, self.svs[sel[sat]])
        for key, value in columns.items():
            if isinstance(value, str):  # its code among the column's texts
                texts = self.texts.setdefault(key, [])
                if value not in texts:
                    texts.append(value)
                self._write(key, rows, np.full(len(rows), texts.index(value), dtype=np.int16))
            elif value.shape == mask.shape:
                self._write(key, rows, value[mask])
            elif value.shape == (mask.shape[0], 1):  # one value per satellite
                self._write(key, rows, value[sat, 0])
            elif value.shape == (1, mask.shape[1]):  # one value per epoch
                self._write(key, rows, value[0, ep])
            else:
                self._write(key, rows, np.broadcast_to(value, mask.shape)[mask])

    def names(self, order: tuple[str, ...]) -> list[str]:
        """The columns of ``order`` this table has."""
        return [c for c in order if c in self.columns]

    def frame(self, names: list[str]) -> pd.DataFrame:
        """The table of the columns ``names`` (each column its own array: the table takes them
        as they are, without copying them into blocks)."""
        import pandas as pd

        columns = {}
        for name in names:
            values = self.columns.pop(name)
            if name in self.texts:  # the texts of the codes
                values = pd.Series(self.texts[name]).array.take(values)
            columns[name] = values
        return pd.DataFrame(columns, copy=False)


def _switches(state: np.ndarray) -> np.ndarray:
    """Where a boolean state differs from the previous epoch's (False at the first)."""
    out = np.zeros_like(state)
    out[:, 1:] = state[:, 1:] != state[:, :-1]
    return out


def _gradient_part(values: np.ndarray, cols: slice, dt_s: float, times: int = 1) -> np.ndarray:
    """``np.gradient`` along the epochs (axis 1) of ``values``, applied ``times`` times, at the
    epochs ``cols`` only: from those epochs and ``times`` neighbours on each side (central
    differences inside the drive, one-sided at its ends, as on the whole array)."""
    lo, hi = max(cols.start - times, 0), min(cols.stop + times, values.shape[1])
    part = values[:, lo:hi]
    for _ in range(times):
        part = np.gradient(part, dt_s, axis=1)
    return part[:, cols.start - lo:cols.stop - lo]


def _shared_draws(rng: np.random.Generator, cfg: dict, err: dict, n_records: int, n_ep: int,
                  dt_s: float, ant: dict, los_rows: np.ndarray, los: np.ndarray) -> Shared:
    """The first receiver's draws a second one shares, each from its own named stream (module
    docstring), and the second receiver's own stream."""
    tid = IonoField(child_rng(rng, "iono_tid"), n_ep, dt_s, TID_LENGTH_KM, TID_TIME_S)
    gradient = cfg["tropo_gradient"] * child_rng(rng, "tropo_gradient").standard_normal(2)
    orbit = ORBIT_ERROR_M * child_rng(rng, "orbit_error").standard_normal((n_records, 3))
    return Shared(sis=err["sis_all"], iono_field=err["iono_field"], tid=tid,
                  tid_sigma_m=cfg["iono_gradient"] * TID_LENGTH_KM * 1e3,
                  tropo_zenith_m=float(err["tropo_zenith"]), tropo_gradient=gradient,
                  orbit_m=orbit,
                  origin_lla=(float(ant["lat"][0]), float(ant["lon"][0]), float(ant["alt"][0])),
                  los_rows=los_rows, los=los, second_rng=child_rng(rng, "second_receiver"))


def observe(cfg: dict, t: np.ndarray, dt_s: float, sky: dict, ant: dict[str, np.ndarray],
            rng: np.random.Generator,
            reception: Callable[[np.ndarray, np.ndarray, Callable, np.ndarray],
                                tuple[np.ndarray, ...]],
            shared: Shared | None = None) -> Observed:
    """Every signal's measurements of one receiver (module docstring).

    Parameters
    ----------
    cfg : dict
        The receiver's resolved block (``sensors.gnss`` or ``sensors.gnss_base``).
    sky : dict
        The broadcast records in use (``Gnss.broadcast``).
    ant : dict of ndarray
        The antenna over the epochs (``Gnss.antenna``).
    reception : callable
        (azimuth, elevation, antenna gain, rows) -> (los, nlos, extra path, C/N0 loss), the
        environment's effect on each signal of the satellites ``rows`` (of the sky's) whose
        azimuth and elevation it is given.
    shared : Shared, optional
        The first receiver's shared draws; None for the first receiver (it draws them).
    """
    raw, truth, rest = _measure(cfg, t, dt_s, sky, ant, rng, reception, shared)
    # the tables, made once the per-satellite arrays of ``_measure`` are gone
    return Observed(raw=raw.frame(raw.names(col.GNSS_RAW)),
                    truth=truth.frame(truth.names(col.TRUTH_GNSS)), **rest)


def _measure(cfg: dict, t: np.ndarray, dt_s: float, sky: dict, ant: dict[str, np.ndarray],
             rng: np.random.Generator,
             reception: Callable[[np.ndarray, np.ndarray, Callable, np.ndarray],
                                 tuple[np.ndarray, ...]],
             shared: Shared | None) -> tuple[_Table, _Table, dict]:
    """``observe``'s measurements as the rows of its raw and truth tables (``_Table``), with
    the receiver's clock (m, m/s), what it drew and the shared draws."""
    eph = sky["eph"]
    n_all, n_ep = sky["idx"].shape
    # the satellites that may rise above the horizon; the others are never measured (their
    # processes are drawn all the same, so that every stream draws what it always drew)
    rows, geo = signal_geometry_chunks(eph, sky["idx"], sky["t_gps"], ant, sky["day_of_year"],
                                       sky["alpha"], sky["beta"])
    model = geo
    idx, svs = sky["idx"][rows], sky["svs"][rows]
    n_sat = len(rows)
    el, az = geo["elevation"], geo["azimuth"]

    # what the receiver tracks: the C/N0 fades with the motion (correlated like the
    # multipath), the receiver's estimate of it adds white noise
    u = decorrelation_coordinate(t, ant["distance"], cfg["multipath_distance"],
                                 cfg["multipath_correlation_time"])
    los, nlos, extra, loss = reception(
        az, el, lambda elevation: cn0_model(elevation, cfg["cn0_zenith"], cfg["cn0_horizon"]),
        rows)
    fading = draw_fading(child_rng(rng, "cn0_fading"), cfg, u, n_all, rows)
    cn0_noise = child_rng(rng, "cn0_noise").standard_normal((n_all, n_ep))[rows]
    signal_cn0, cn0 = np.empty((n_sat, n_ep)), np.empty((n_sat, n_ep))
    for cols in epoch_chunks(n_ep):  # one pass per chunk of epochs
        signal_cn0[:, cols] = (cn0_model(el[:, cols], cfg["cn0_zenith"], cfg["cn0_horizon"])
                               - loss[:, cols] + fading[:, cols])
        cn0[:, cols] = signal_cn0[:, cols] + cfg["cn0_noise"] * cn0_noise[:, cols]
    del fading, cn0_noise
    have = idx >= 0
    # the broadcast record's fields each signal carries (0 where no record): only the fields
    # used, only for these satellites (a whole record per satellite and epoch is gigabytes
    # for a fast-rate hour)
    gathered = gather(eph, idx, ("health", "tgd", "tgd2", "group_delay"))
    record = {name: np.where(have, gathered[key], 0.0) for name, key in (
        ("health", "health"), ("tgd_s", "tgd"), ("tgd2_s", "tgd2"),
        ("primary_delay_s", "group_delay"))}
    del gathered
    visible = have & (el > np.radians(cfg["elevation_mask"])) & (los | nlos)
    tracked = visible & (cn0 >= cfg["cn0_threshold"])

    bias_s, drift_s_s, drawn_clock = draw_receiver_clock(child_rng(rng, "receiver_clock"),
                                                         cfg["clock"], n_ep, dt_s)
    # the tracking jitter follows the signal's C/N0, not the noise of its reported estimate
    # (below the horizon, where nothing is tracked, the pierce point of the horizon)
    pierce = np.empty((3, n_sat, n_ep))
    for cols in epoch_chunks(n_ep):  # one pass per chunk of epochs
        pierce[:, :, cols] = pierce_points_km(ant["lat"][cols], ant["lon"][cols], az[:, cols],
                                              np.maximum(el[:, cols], 0.0))
    err = draw_error_terms(rng, cfg, el, signal_cn0, dt_s, u, pierce, sky["idx"],
                           None if shared is None else shared, rows)
    if shared is None:
        shared = _shared_draws(rng, cfg, err, len(eph["toe_s"]), n_ep, dt_s, ant, rows,
                               geo["los"])
    else:  # the orbit error seen along this receiver's lines of sight
        # the first receiver's lines of sight of these satellites (zero where it had none)
        at = np.minimum(np.searchsorted(shared.los_rows, rows), len(shared.los_rows) - 1)
        common = np.flatnonzero(shared.los_rows[at] == rows)
        sis = np.empty((n_sat, n_ep))
        for cols in epoch_chunks(n_ep):  # one pass per chunk of epochs
            first_los = np.zeros((n_sat, cols.stop - cols.start, 3))
            first_los[common] = shared.los[at[common], cols]
            orbit = shared.orbit_m[np.maximum(idx[:, cols], 0)]
            sis[:, cols] = np.where(have[:, cols], err["sis"][:, cols] + np.einsum(
                "sek,sek->se", orbit, geo["los"][:, cols] - first_los), 0.0)
        err["sis"] = sis
    drawn = {"clock": drawn_clock, "tropo_zenith_error_m": shared.tropo_zenith_m,
             "tropo_gradient_m_per_km": (shared.tropo_gradient * 1e3).tolist()}

    # the atmosphere this receiver sees
    ned = ecef_to_ned(ant["pos"], *shared.origin_lla)
    tropo_zenith = shared.tropo_zenith_m + ned[:, :2] @ shared.tropo_gradient
    tid = shared.tid(pierce)
    for cols in epoch_chunks(n_ep):  # one pass per chunk of epochs
        tid[:, cols] *= shared.tid_sigma_m
        tid[:, cols] *= klobuchar_obliquity(np.maximum(el[:, cols], 0.0))
    rx_clock, rx_drift = C_M_S * bias_s, C_M_S * drift_s_s
    system_of = sky["systems"][rows]
    speed = np.linalg.norm(ant["v_ned"], axis=1)
    # the reflection's quadrature component (its in-phase one is the code multipath's process)
    quadrature = gauss_markov_along(u, n_all, child_rng(rng, "multipath_quadrature"),
                                    columns=rows)
    # the reflecting plane's normal (uniform in direction, changing as the reflectors do): with
    # the antenna's velocity it sets how fast the reflection's carrier phase turns
    from scipy.special import ndtr  # imported on first use, as in simulator.gnss.carrier

    wall_unit = gauss_markov_along(u, n_all, child_rng(rng, "reflector_normal"), columns=rows)
    moving = bool(np.any(ant["v_ned"] != 0.0))
    names = ["mapping", "tropo_true", "iono_true", "iono_true_rate", "tropo_true_rate",
             "sat_drift", "reference_clock", "nlos_delay", "los_jerk"] + ["path_rate"] * moving
    shared_terms = {name: np.empty((n_sat, n_ep)) for name in names}
    for cols in epoch_chunks(n_ep):  # one pass per chunk of epochs
        m = {k: a[:, cols] for k, a in model.items()}
        out = {name: a[:, cols] for name, a in shared_terms.items()}
        ratio = err["iono_ratio"][:, cols]
        out["mapping"][...] = mapping = m["tropo"] / m["zenith"]
        out["tropo_true"][...] = m["tropo"] + tropo_zenith[None, cols] * mapping
        out["iono_true"][...] = m["iono"] * ratio + tid[:, cols]
        # its rate: the broadcast model's along the geometry times the ratio, plus the (slow)
        # change of the ratio and of the disturbances
        iono_true_rate = m["iono_rate"] * ratio
        if n_ep > 1:
            iono_true_rate = (iono_true_rate
                              + m["iono"] * _gradient_part(err["iono_ratio"], cols, dt_s)
                              + _gradient_part(tid, cols, dt_s))
        out["iono_true_rate"][...] = iono_true_rate
        out["tropo_true_rate"][...] = m["tropo_rate"] * (1.0 + tropo_zenith[None, cols]
                                                         / m["zenith"])
        # the satellite clock against GPS time: the broadcast one of the primary signal (GPS:
        # L1, T_GD applied) against its system's time plus the broadcast system-time offset,
        # as a receiver applying GGTO / tau_GPS has it
        sat_clock = C_M_S * (m["clock_s"] + m["system_time_offset_s"])
        out["sat_drift"][...] = C_M_S * m["clock_drift_s_s"]
        # the broadcast clock's reference (the ionosphere-free pair, without the primary
        # signal's group delay): the carrier's clock; each code's own group delay is taken
        # from it (signals.signal_group_delay_s)
        out["reference_clock"][...] = sat_clock + C_M_S * record["primary_delay_s"][:, cols]
        out["nlos_delay"][...] = np.where(nlos[:, cols] & ~los[:, cols], extra[:, cols], 0.0)
        if moving:  # standing still, the loop's gain is 1
            out["path_rate"][...] = reflection_path_rate_m_s(
                ant["v_ned"][cols], az[:, cols], el[:, cols],
                np.pi * ndtr(wall_unit[:, cols]))
        out["los_jerk"][...] = (_gradient_part(geo["range_rate"], cols, dt_s, times=2)
                                if n_ep > 2 else 0.0)
    del wall_unit
    path_rate = shared_terms.get("path_rate")
    reflected = _switches(nlos & ~los)  # a switch between direct and reflected: lock lost
    scale = cfg["tracking_noise"]

    # per-satellite arrays each signal uses, taken on its system's rows only (the other rows
    # of a signal are never measured, so nothing is drawn for them)
    per_satellite = {
        "el": el, "az": az, "signal_cn0": signal_cn0, "cn0": cn0, "tracked": tracked,
        "visible": visible, "have": have, "los": los, "nlos_only": nlos & ~los,
        "reflected": reflected, "range": geo["range"], "range_rate": geo["range_rate"],
        "tau_rate": geo["tau_rate"], "pos": geo["pos"], "vel": geo["vel"], **shared_terms,
        "model_iono": model["iono"], "model_tropo": model["tropo"], "sis": err["sis"],
        "multipath_unit": err["multipath_unit"],
        "quadrature": quadrature, "multipath_sigma": err["multipath_sigma"],
        "code_sigma": err["code_sigma"], "code_noise": err["code_noise"],
        "rate_sigma": err["rate_sigma"], "rate_noise": err["rate_noise"],
        "health": record["health"].astype(np.int64),
        "primary_delay_s": record["primary_delay_s"], "tgd_s": record["tgd_s"],
        "tgd2_s": record["tgd2_s"], "channel": sky["channel"][rows]}
    views: dict[str, dict[str, np.ndarray]] = {}

    def unit_gm(tau_s: float, letter: str, stream: np.random.Generator) -> np.ndarray:
        return gauss_markov(n_ep, dt_s, np.ones(len(sky_sels[letter])), tau_s, stream,
                            columns=kept[letter]).T

    def draw(letter: str, values: Callable[[tuple[int, int]], np.ndarray]) -> np.ndarray:
        """A draw of one value per satellite of the system and epoch, the measured ones."""
        return values((len(sky_sels[letter]), n_ep))[kept[letter]]

    def stream(signal_name: str, process: str) -> np.random.Generator:
        """One signal's process's own stream (module docstring)."""
        return child_rng(rng, f"{signal_name}/{process}")

    codes = [(SYSTEMS[name], code) for name in cfg["systems"] for code in cfg["signals"][name]]
    sels = {letter: np.flatnonzero(system_of == letter) for letter, _ in codes}
    # each system's satellites in the sky, and where the measured ones are among them
    sky_sels = {letter: np.flatnonzero(sky["systems"] == letter) for letter in sels}
    kept = {letter: np.searchsorted(sky_sels[letter], rows[sel]) for letter, sel in sels.items()}
    for letter, sel in sels.items():
        # a system's satellites are consecutive rows of the sky: views, not copies
        block = (slice(sel[0], sel[-1] + 1) if sel.size and sel[-1] - sel[0] + 1 == sel.size
                 else sel)
        views[letter] = {k: np.asarray(v)[block] for k, v in per_satellite.items()}
    # what each signal tracks, first: every table row is then known before any is written
    tracking = {}
    for letter, code in codes:  # one pass per signal, vectorised
        v = views[letter]
        if code == PRIMARY_SIGNAL[letter]:
            tracking[letter, code] = v["cn0"], v["tracked"]
            continue
        cn0_true = v["signal_cn0"] + signal(letter, code).cn0_offset_db
        cn0_out = cn0_true + cfg["cn0_noise"] * draw(
            letter, stream(f"{letter}{code}", "cn0_noise").standard_normal)
        tracked_s = v["visible"] & (cn0_out >= cfg["cn0_threshold"])
        if code.endswith("W"):  # semicodeless P(Y): aided by the L1 C/A loops
            tracked_s &= v["tracked"]
        tracking[letter, code] = cn0_out, tracked_s
    in_truth = {letter: v["have"] & (v["el"] > 0) for letter, v in views.items()}
    raw_table = _Table(t, svs, [(sels[letter], tracking[letter, code][1])
                                for letter, code in codes])
    truth_table = _Table(t, svs, [(sels[letter], in_truth[letter]) for letter, code in codes])
    for letter, code in codes:  # one pass per signal, vectorised
        spec = signal(letter, code)
        sel = sels[letter]
        signal_name = f"{letter}{code}"  # its processes' streams are named after it
        v = views[letter]
        shape = (len(sel), n_ep)
        # per satellite (GLONASS: its FDMA channel)
        freq = carrier_frequency_hz(letter, code, v["channel"])[:, None]
        lam = C_M_S / freq
        k_iono = iono_factor(freq)
        cn0_out, tracked_s = tracking.pop((letter, code))
        if code == PRIMARY_SIGNAL[letter]:  # the error terms drawn for the primary signals
            cn0_true = v["signal_cn0"]
            code_sigma, code_noise = v["code_sigma"], v["code_noise"]
            rate_sigma, rate_noise = v["rate_sigma"], v["rate_noise"]
        else:
            cn0_true = v["signal_cn0"] + spec.cn0_offset_db
            code_sigma = scale * dll_sigma_m(cn0_true, cfg["dll_bandwidth"],
                                             cfg["correlator_spacing"], cfg["integration_time"]
                                             ) * (_CA_CHIP_RATE_HZ / spec.chip_rate_hz)
            code_noise = code_sigma * unit_gm(loop_time_constant_s(cfg["dll_bandwidth"]),
                                              letter, stream(signal_name, "code_noise"))
            rate_sigma = scale * lam * fll_sigma_hz(cn0_true, cfg["fll_bandwidth"],
                                                    cfg["integration_time"])
            rate_noise = rate_sigma * unit_gm(loop_time_constant_s(cfg["fll_bandwidth"]),
                                              letter, stream(signal_name, "rate_noise"))
        # what needs the whole drive (the draws, the smoothing and the arcs along the epochs)
        # first; the elementwise rest chunk by chunk (``epoch_chunks``)
        code_mp, carrier_mp = np.empty(shape), np.empty(shape)
        iono_s = np.empty(shape)
        chance = np.zeros(shape)  # a slip only matters where the signal is tracked
        for cols in epoch_chunks(n_ep):  # one pass per chunk of epochs
            code_mp[:, cols], carrier_mp[:, cols] = reflection_multipath(
                v["multipath_unit"][:, cols], v["quadrature"][:, cols],
                v["multipath_sigma"][:, cols], cfg["multipath_delay"], freq - F_L1_HZ, lam)
            if path_rate is not None:  # the loop follows the carrier multipath: its gain at
                # the fringe frequency
                carrier_mp[:, cols] *= pll_response(v["path_rate"][:, cols] / lam,
                                                    cfg["pll_bandwidth"])
            np.multiply(k_iono, v["iono_true"][:, cols], out=iono_s[:, cols])
            if cfg["carrier_phase"] and scale > 0:
                here = tracked_s[:, cols]
                sigma_cycles = scale * pll_sigma_cycles(cn0_true[:, cols], cfg["pll_bandwidth"],
                                                        cfg["integration_time"])
                stress = dynamic_stress_cycles(v["los_jerk"][:, cols], lam, cfg["pll_bandwidth"])
                chance[:, cols][here] = slip_probability(sigma_cycles[here], stress[here],
                                                         cfg["pll_bandwidth"], dt_s, spec.pilot)
        terms = smooth_code_errors(cfg, {"code_noise": code_noise, "multipath": code_mp},
                                   iono_s, tracked_s, dt_s)
        if cfg["carrier_phase"]:
            phase_draw = draw(letter, stream(signal_name, "phase_noise").standard_normal)
            slips = draw_slips(draw(letter, stream(signal_name, "cycle_slips").random), chance,
                               tracked_s)
            arcs = phase_arcs(stream(signal_name, "phase_arcs"), tracked_s, slips,
                              v["reflected"], dt_s, spec.pilot, spec.frame_s)
        whole = {**v, "iono_s": iono_s, "carrier_mp": carrier_mp, "tracked_s": tracked_s,
                 "in_truth": in_truth[letter], "cn0_true": cn0_true, "cn0_out": cn0_out,
                 "code_sigma": code_sigma, "rate_sigma": rate_sigma, "rate_noise": rate_noise,
                 "smoothed_multipath": terms["multipath"],
                 "smoothed_code_noise": terms["code_noise"]}
        if cfg["carrier_phase"]:
            whole.update(phase_draw=phase_draw, **vars(arcs))
        for cols in epoch_chunks(n_ep):  # one pass per chunk of epochs
            w = {k: a[:, cols] for k, a in whole.items() if np.ndim(a) > 1}
            group_delay = C_M_S * signal_group_delay_s(letter, code, w["primary_delay_s"],
                                                       w["tgd_s"], w["tgd2_s"])
            sat_clock_s = w["reference_clock"] - group_delay
            clock, drift = rx_clock[cols], rx_drift[cols]
            pseudorange = (w["range"] + clock - sat_clock_s + w["iono_s"] + w["tropo_true"]
                           + w["sis"] + w["smoothed_multipath"] + w["nlos_delay"]
                           + w["smoothed_code_noise"])
            rate = (w["range_rate"] + drift - w["sat_drift"] * (1.0 - w["tau_rate"])
                    + w["tropo_true_rate"] - k_iono * w["iono_true_rate"] + w["rate_noise"])
            pr_std, rate_std = pseudorange_sigma(
                cfg, {"code_sigma": w["code_sigma"], "multipath_sigma": w["multipath_sigma"],
                      "rate_sigma": w["rate_sigma"]}, k_iono * w["model_iono"], w["mapping"],
                dt_s, speed[cols])
            raw = {"system": letter, "signal": code, "frequency": freq,
                   "pseudorange": pseudorange, "pseudorange_rate": rate, "doppler": -rate / lam,
                   "cn0": w["cn0_out"], "sat_x": w["pos"][..., 0], "sat_y": w["pos"][..., 1],
                   "sat_z": w["pos"][..., 2], "sat_vx": w["vel"][..., 0],
                   "sat_vy": w["vel"][..., 1], "sat_vz": w["vel"][..., 2],
                   "sat_clock": sat_clock_s, "sat_clock_drift": w["sat_drift"],
                   "iono": k_iono * w["model_iono"], "tropo": w["model_tropo"],
                   "elevation": w["el"], "azimuth": w["az"], "pseudorange_std": pr_std,
                   "pseudorange_rate_std": rate_std, "health": w["health"],
                   "group_delay": group_delay}
            antenna = ant["pos"][None, cols]
            truth = {"system": letter, "signal": code, "frequency": freq,
                     "tracked": w["tracked_s"].astype(np.int8), "los": w["los"].astype(np.int8),
                     "nlos": w["nlos_only"].astype(np.int8), "elevation": w["el"],
                     "azimuth": w["az"], "range": w["range"], "range_rate": w["range_rate"],
                     "receiver_clock": clock[None, :], "receiver_clock_drift": drift[None, :],
                     "iono_true": w["iono_s"], "tropo_true": w["tropo_true"],
                     "iono_true_rate": k_iono * w["iono_true_rate"],
                     "tropo_true_rate": w["tropo_true_rate"], "sis_error": w["sis"],
                     "multipath": w["smoothed_multipath"], "nlos_delay": w["nlos_delay"],
                     "code_noise": w["smoothed_code_noise"], "rate_noise": w["rate_noise"],
                     "antenna_x": antenna[..., 0], "antenna_y": antenna[..., 1],
                     "antenna_z": antenna[..., 2], "group_delay": group_delay}
            if cfg["carrier_phase"]:
                sigma_cycles = scale * pll_sigma_cycles(w["cn0_true"], cfg["pll_bandwidth"],
                                                        cfg["integration_time"])
                phase_noise = lam * sigma_cycles * w["phase_draw"]
                phase_m = (w["range"] + clock - w["reference_clock"] - w["iono_s"]
                           + w["tropo_true"] + w["sis"] + w["carrier_mp"] + w["nlos_delay"]
                           + phase_noise)
                raw.update(carrier_phase=phase_m / lam + w["ambiguity"] + w["half"],
                           lli=w["lli"], lock_time=w["lock_time"])
                truth.update(ambiguity=w["ambiguity"], half_cycle=w["half"],
                             cycle_slip=w["cycle_slip"], arc=w["arc"],
                             carrier_multipath=w["carrier_mp"], phase_noise=phase_noise)
            raw_table.add(sel, w["tracked_s"], raw, cols.start)
            truth_table.add(sel, w["in_truth"], truth, cols.start)
    return raw_table, truth_table, {"clock_m": rx_clock, "drift_m_s": rx_drift,
                                    "drawn": drawn, "shared": shared}


COARSE_STEP_S = 60.0  # satellites move < 0.6 deg in elevation in this time
BELOW_HORIZON_MARGIN_RAD = np.radians(-5.0)  # skipped if lower than this all chunk long
# what the measurements need of ``_signals`` (the intermediate lines of sight are dropped)
_KEPT = ("pos", "vel", "los", "clock_s", "clock_drift_s_s", "system_time_offset_s", "range",
         "range_rate", "tau_rate",
         "elevation", "azimuth", "iono", "tropo", "zenith", "iono_rate", "tropo_rate")


def _signals(eph: dict[str, np.ndarray], t_gps: np.ndarray, ant: dict[str, np.ndarray],
             day_of_year: np.ndarray, alpha: list[float], beta: list[float]
             ) -> dict[str, np.ndarray]:
    """Signal geometry, look angles and broadcast delays (with rates) of gathered ephemerides
    (n_sat, n_epoch) received by the antenna ``ant`` (arrays over the same n_epoch)."""
    geo = signal_geometry(eph, t_gps, ant["pos"], ant["vel"])
    look = look_angles(geo["los"], geo["los_rate"], ant["lat"], ant["lon"])
    lat_rate, lon_rate, alt_rate = geodetic_rates(ant["lat"], ant["alt"], ant["v_ned"])
    model = broadcast_delays(
        ant["lat"], ant["lon"], ant["alt"], look["azimuth"], look["elevation"], t_gps,
        day_of_year, alpha, beta,
        rates={"lat": lat_rate, "lon": lon_rate, "alt": alt_rate, "azimuth": look["azimuth_rate"],
               "elevation": look["elevation_rate"]})
    return {**geo, **look, **model}


def _maybe_above_horizon(eph: dict[str, np.ndarray], idx: np.ndarray, t_gps: np.ndarray,
                         ant: dict[str, np.ndarray]) -> np.ndarray:
    """Satellites (rows of idx) that may rise above the horizon during these epochs: their
    elevation, sampled every ``COARSE_STEP_S`` without the light-time correction, exceeds
    ``BELOW_HORIZON_MARGIN_RAD`` somewhere."""
    n = len(t_gps)
    step = 1 if n < 2 else max(1, int(round(COARSE_STEP_S / (t_gps[1] - t_gps[0]))))
    cols = np.unique(np.concatenate([np.arange(0, n, step), [n - 1]]))
    pos = satellite_state(gather(eph, idx[:, cols], STATE_KEYS), t_gps[None, cols])["pos"]
    lat, lon = ant["lat"][cols], ant["lon"][cols]
    up = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=-1)
    rel = pos - ant["pos"][None, cols]
    sin_el = np.einsum("sek,ek->se", rel, up) / np.linalg.norm(rel, axis=-1)
    return np.flatnonzero((sin_el > np.sin(BELOW_HORIZON_MARGIN_RAD)).any(axis=1)
                          & (idx >= 0).any(axis=1))


def signal_geometry_chunks(eph: dict[str, np.ndarray], idx: np.ndarray, t_gps: np.ndarray,
                           ant: dict[str, np.ndarray], day_of_year: np.ndarray,
                           alpha: list[float], beta: list[float]
                           ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """``_signals`` of the satellites that may be above the horizon, evaluated
    ``CHUNK_EPOCHS`` at a time (``simulator.gnss.chunks``) and in each chunk only for the
    satellites that may be above the horizon then: the satellites (rows of idx, ascending)
    that may be above it in some chunk, and their signals over every epoch, (rows, n_epoch)
    arrays in which the epochs of a chunk where a satellite stays below keep elevation -90 deg
    (never tracked), a unit zenith delay and zeros elsewhere. The other satellites are never
    above the horizon: nothing of them is measured."""
    n_ep = idx.shape[1]
    screened = []
    for cols in epoch_chunks(n_ep):  # one pass per chunk of epochs
        ant_c = {k: v[cols] for k, v in ant.items()}
        screened.append((cols, ant_c, _maybe_above_horizon(eph, idx[:, cols], t_gps[cols],
                                                           ant_c)))
    rows = np.unique(np.concatenate([np.zeros(0, dtype=int)] + [r for _, _, r in screened]))
    first = {k: v[:1] for k, v in ant.items()}
    shapes = _signals(gather(eph, idx[:1, :1], STATE_KEYS), t_gps[:1], first, day_of_year[:1],
                      alpha, beta)
    fill = {"elevation": -np.pi / 2, "zenith": 1.0}
    out = {k: np.full((len(rows), n_ep) + shapes[k].shape[2:], fill.get(k, 0.0)) for k in _KEPT}
    for cols, ant_c, up in screened:  # one pass per chunk of epochs
        part = _signals(gather(eph, idx[up, cols], STATE_KEYS), t_gps[cols], ant_c,
                        day_of_year[cols], alpha, beta)
        at = np.searchsorted(rows, up)
        for key in _KEPT:
            out[key][at, cols] = part[key]
    return rows, out
