"""``rtk_ins_ekf``: tightly coupled RTK/INS, an error-state EKF on double-differenced code and
carrier phase against a base station, with integer ambiguity resolution (docs/rtk-ins.md).

* **INS**: the toolbox's 15-state error-state filter (``toolbox.ins_filter.InsFilter``: the
  strapdown of ``toolbox.strapdown``, the error model of ``toolbox.ins_error``, the Joseph
  update of ``toolbox.kalman``; Groves 2013, chapter 14), its IMU noise from the datasheet
  (``toolbox.datasheet.imu_error_model``), closed loop, the IMU's mounting and the antenna's
  lever arm from the installation (``toolbox.installation``). Its scale-factor and
  g-sensitivity noise counts the change of the mean readings from one ``scale_noise_window``
  to the next, not from one propagation step to the next, where the car body's vibration
  would count as a change of the biases (docs/rtk-ins.md, "Consistency").
* **Ambiguities**: one state per signal (satellite and band) for the between-receiver
  single-difference ambiguity N_rover - N_base in cycles, a random constant, after the 15
  (``ambiguity_states`` slots, taken as satellites rise and given back when they set; the
  same formulation as RTKLIB's, Takasu & Yasuda 2009). The measurements double-difference them
  against each group's reference satellite (``toolbox.double_difference``), so the receivers'
  clocks cancel and only double-differenced ambiguities are observed; a new state starts at
  (phase - code) / lambda of its single differences with ``ambiguity_std``.
* **Measurements** at each rover epoch with a base epoch of the same time, satellites above
  ``elevation_mask``: double-differenced pseudoranges and carrier phases (m), with the broadcast
  satellite clock, ionosphere and troposphere applied to each receiver's own measurement
  (they cancel to the baseline's gradient), predicted from the antenna position r + C_b^n l
  (``gnss_model.predict``: Sagnac, the satellite's transmit-time position) and from the base's
  surveyed position (the datasheet's ``gnss_base.surveyed_position``, or ``base_position``):

      DD code  = DD range + e_code
      DD phase = DD range + lambda (a_s - a_ref) + e_phase

  H has -(u_s - u_ref) on the position error, (u_s - u_ref) [(C_b^n l) x] on the attitude
  error (u the NED lines of sight; Groves eq. 14.127 differenced) and +-lambda on the two
  ambiguities. Each receiver's undifferenced 1-sigma is ``*_std`` / sin(elevation) (the
  elevation model of RTKLIB's ``err`` option); the single differences are independent, the
  double differences share their reference's variance (``double_difference_covariance``).
  The code's sigma is scaled by the correlated-noise inflation of ``code_correlation_time``
  at ``gnss_interval`` (``gnss_model.correlated_noise_inflation``; by default the rover's
  carrier-smoothing window from the datasheet, ``gnss.carrier_smoothing``: a smoothed code's
  errors stay for that long, and weighted as white a thousand rows of decimetres off
  together bias the float ambiguities beyond their sigma and the partial fixes built on
  them), the rover's phase by that of ``phase_correlation_time`` (the reflections change
  as the car moves; the base's still antenna has white phase errors). The first epoch of a
  rover signal's code arc (the filter's first use of it since the receiver's tracking, and so
  its smoothing, began) counts at its marginal sigma ``code_arc_std`` (the raw code's, the
  smoothing barely begun), not inflated: the information of n samples of a
  first-order Gauss-Markov error about a constant is (n (1 - phi) + 2 phi) / (1 + phi) times
  one sample's, one for the first sample and (1 - phi) / (1 + phi), the inverse square of the
  inflation, for each later one. Each DD code row passes a chi-square gate
  (``gate_probability``).
* **Ionosphere**: one state per satellite, g_s, the horizontal gradient of the L1 vertical
  delay along the baseline at the satellite's pierce point, in parts per million (a
  Gauss-Markov process, 1-sigma ``iono_ppm``, ``iono_correlation_time``); the satellite's
  single-difference L1 delay is I_s = g_s b M(el_s), b the current baseline length and M the
  thin-shell (350 km) obliquity, gamma I_s on a band of gamma = (f_L1 / f)^2, delaying the
  code and advancing the phase. A delay that grows with the baseline (the residual of the
  broadcast model and the travelling disturbances of a gradient: 1-2 ppm, Wanninger 1995)
  is then a constant state, not a state that has to move. A satellite's state is kept
  through a gap of up to a tenth of its correlation time (a tunnel), its value then still
  90 % correlated with the truth's.
* **Cycle slips**: a signal's ambiguity state is reset (new value, ``ambiguity_std``, no
  correlation, not held) when either receiver's LLI has bit 0 (loss of lock), its lock time
  fell, it was not seen for ``max_gap`` s, its half-cycle flag (LLI bit 1) cleared (the phase
  moved by half a cycle), the geometry-free phase lambda_1 phi_1 - lambda_2 phi_2 of its
  satellite at either receiver jumped by more than ``slip_geometry_free`` m since the last
  epoch (Blewitt 1990: the ionosphere moves it by millimetres per second), or its
  double-differenced phase innovation against the INS prediction exceeds
  ``slip_sigmas`` times its sigma and ``slip_cycles`` cycles (a reference that fails with most
  of its group resets the reference). A phase whose half cycle is still unresolved (LLI bit
  1) is used, its double differences searched as integers of half cycles.
* **Integer ambiguities**: after each update the double-differenced float ambiguities a = D x_a
  (covariance D P D^T) are resolved by LAMBDA with the ratio test and partial fixing
  (``toolbox.ambiguity.resolve``: Chang, Yang & Zhou 2005; ``ratio_threshold``,
  ``min_success_rate``, ``min_fixed``): a subset is fixed when its ratio test passes and
  either its bootstrapped success rate reaches ``min_success_rate`` or the ratio test's
  failure rate for the float covariance, by Monte Carlo (``failure_samples``), is at most 1 -
  ``min_success_rate`` (the fixed failure-rate ratio test, Verhagen & Teunissen 2013). Each
  group's reference is a held signal if it has one, else one whose half cycle is resolved.
  A fixed epoch's solution is the float one conditioned
  on the integers: dx = P_xa Q_a^-1 (a - a_fixed), P = P - P_xa Q_a^-1 (Q_a - Q_fixed)
  Q_a^-1 P_ax (Teunissen 1995). **Fix and hold** (``hold``): when every double difference is
  fixed, the integers are applied to the filter as measurements of 1-sigma ``hold_std``
  cycles and their states marked held; an epoch whose phases all belong to held states is
  fixed without a search (a slip or a failed innovation releases a state). Such an epoch
  uses no code (``held_code``): the rover's carrier-smoothed code errors stay correlated over
  the smoothing (100 s), and its thousand rows per 100 s weighted as independent pull the
  held ambiguities and the position by centimetres over minutes, where the phases alone
  know them to millimetres.
* **Odometer and NHC** (``odometer``, ``nhc``) when the dataset has an odometer: the body
  velocity of the rear axle [v_odo, 0, 0] (``aiding.odometer``), its noise the odometer's
  datasheet resolution and age and a 3 % scale, the lateral and vertical the car's physics
  (``constraints.NonholonomicNoise``).

Solution rows: the navigation columns and their 1-sigma, the bias estimates, ``fix_status``
(2 fixed, 1 float, at the rows of a GNSS epoch; NaN at rows without one, whose INS-only
solution has no carrier-phase status), ``ratio`` (of the last search), ``fixed_ambiguities``
and the NIS of the epoch's GNSS rows (``nis_gnss``, ``nis_gnss_dof``).

Public names
------------
RtkInsEkf.
"""

from __future__ import annotations

import math

import numpy as np

from estimators.base import Estimator
from estimators.toolbox import aiding, ambiguity, gating, gnss_model, nav_error
from estimators.toolbox import double_difference as ddiff
from estimators.toolbox.config_help import shared_help
from estimators.toolbox.constraints import NonholonomicNoise
from estimators.toolbox.datasheet import imu_error_model, odometer_delay_s, odometer_speed_sigma
from estimators.toolbox.ins_error import N_STATES
from estimators.toolbox.ins_filter import SOLUTION_COLUMNS, InsFilter
from estimators.toolbox.installation import Installation
from simulator.earth import (
    geodetic_to_ecef,
    ned_to_ecef_matrix,
    quat_to_dcm,
    quat_to_euler,
    skew,
)
from simulator.errors import InputError
from simulator.gnss.constants import C_M_S

G0 = 9.80665  # m/s^2
EARTH_RADIUS_M = 6_371_000.0  # the ionosphere's thin-shell model (Klobuchar's)
IONO_SHELL_M = 350_000.0
SATELLITES_PER_SYSTEM = 14  # above a 10 deg mask: GPS 8-12, Galileo 6-10, BeiDou MEO 6-10
F_L1_HZ = 1575.42e6
ODOMETER_SCALE_SIGMA = 0.03  # unmodelled odometer scale error, 1-sigma (as ins_odo_ekf's)
HALF_CYCLE = 2  # LLI bit 1: half-cycle ambiguity unresolved
LOSS_OF_LOCK = 1  # LLI bit 0
NHC_POINTS = ("rear_axle", "imu")

DEFAULTS = {
    "elevation_mask": 15.0,
    "code_std": 0.3,
    "base_code_std": 0.3,
    "code_arc_std": 0.6,
    "phase_std": 0.003,
    "base_phase_std": 0.001,
    "iono_ppm": 1.5,
    "iono_correlation_time": 600.0,
    "code_correlation_time": None,
    "phase_correlation_time": 0.4,
    "gnss_interval": 0.1,
    "gate_probability": 0.999,
    "ambiguity_states": None,
    "ambiguity_std": 30.0,
    "ratio_threshold": 3.0,
    "min_success_rate": 0.999,
    "min_fixed": 4,
    "failure_samples": 2000,
    "fixed_position_std": 0.05,
    "hold": True,
    "hold_std": 0.01,
    "held_code": False,
    "slip_geometry_free": 0.05,
    "slip_sigmas": 6.0,
    "slip_cycles": 0.5,
    "max_gap": 1.0,
    "initial_position_std": 1.0,
    "initial_velocity_std": 0.2,
    "initial_attitude_std": [1.0, 1.0, 3.0],
    "scale_noise_window": 1.0,
    "odometer": True,
    "odometer_rate": 10.0,
    "nhc": True,
    "nhc_point": "rear_axle",
    "lever_arm": None,
    "base_position": None,
}
CONFIG_HELP = {
    "elevation_mask": ("deg", "satellites below it are not used"),
    "code_std": ("m", "rover pseudorange 1-sigma at zenith (over sin(elevation) below)"),
    "base_code_std": ("m", "base pseudorange 1-sigma at zenith"),
    "code_arc_std": ("m", "rover pseudorange 1-sigma at zenith in the first epoch of a "
                          "tracking arc the filter uses (its smoothing has barely begun)"),
    "phase_std": ("m", "rover carrier-phase 1-sigma at zenith"),
    "base_phase_std": ("m", "base carrier-phase 1-sigma at zenith"),
    "iono_ppm": ("", "1-sigma of each satellite's ionosphere state: the single-difference L1 "
                     "delay in parts per million of the baseline, vertical (times the "
                     "obliquity factor)"),
    "iono_correlation_time": ("s", "correlation time of the ionosphere states"),
    "code_correlation_time": ("s", "correlation time of the code errors the weights count "
                                   "(0: white; null: the datasheet's gnss.carrier_smoothing, "
                                   "the window of the rover's smoothed code)"),
    "phase_correlation_time": ("s", "correlation time of the rover's carrier-phase errors the "
                                    "weights count (multipath along the road, 0: white)"),
    "gnss_interval": ("s", "the epoch interval the correlations are counted at (the "
                           "rover's; set it for a receiver at another rate than 10 Hz)"),
    "gate_probability": ("", "chi-square gate of each double-differenced code row"),
    "ambiguity_states": ("", "single-difference ambiguity slots (signals tracked at once); "
                             "null: 14 satellites per system times its signals, from the "
                             "datasheet"),
    "ambiguity_std": ("cycles", "1-sigma of a new ambiguity state"),
    "ratio_threshold": ("", "LAMBDA ratio test: second-best over best squared norm"),
    "min_success_rate": ("", "bootstrapped success rate a fixed subset must reach"),
    "min_fixed": ("", "fewest double-differenced ambiguities a fix may hold"),
    "failure_samples": ("", "Monte Carlo samples of the ratio test's failure rate, which "
                            "accepts a subset whose bootstrapped success rate falls short "
                            "when at most 1 - min_success_rate (0: the bootstrapped rate "
                            "alone)"),
    "fixed_position_std": ("m", "a fix counts (and is written) when its position 1-sigma "
                                "is at most this on every axis"),
    "hold": ("", "fix and hold: a full fix constrains the float ambiguities"),
    "hold_std": ("cycles", "1-sigma of the hold's ambiguity measurements"),
    "held_code": ("", "use the double-differenced code in an epoch whose ambiguities are all "
                      "held (its errors, correlated over the carrier smoothing, pull a held "
                      "solution by centimetres)"),
    "slip_geometry_free": ("m", "geometry-free phase jump between epochs taken as a slip"),
    "slip_sigmas": ("", "DD phase innovation, in its sigmas, taken as a slip"),
    "slip_cycles": ("cycles", "and at least this many cycles"),
    "max_gap": ("s", "a signal unseen for longer starts a new ambiguity"),
    **shared_help("initial_position_std", "initial_velocity_std", "initial_attitude_std",
                  "nhc_point"),
    "scale_noise_window": ("s", "the IMU's scale-factor errors drive its bias states by the "
                                "change of the mean rate and specific force from one window "
                                "of this length to the next (0: from one flush to the next, "
                                "where the car body's vibration counts as a change)"),
    "odometer": ("", "odometer speed updates (when the dataset has an odometer)"),
    "odometer_rate": ("Hz", "odometer updates per second at most (the samples between are "
                            "not used)"),
    "nhc": ("", "non-holonomic constraint with the odometer updates"),
    "lever_arm": ("m", "IMU to GNSS antenna, body FRD; null: the datasheet's"),
    "base_position": ("deg, deg, m", "base antenna latitude, longitude, ellipsoidal height; "
                                     "null: the datasheet's gnss_base.surveyed_position"),
}
OUTPUT_COLUMNS = (*SOLUTION_COLUMNS, "fix_status", "ratio", "fixed_ambiguities", "nis_gnss",
                  "nis_gnss_dof")


def _zero_nan(x: np.ndarray) -> np.ndarray:
    """``x`` with its NaN (a correction the receiver did not give) as zero."""
    return np.where(np.isnan(x), 0.0, x)


def _members(keys: np.ndarray, known: set[int]) -> np.ndarray:
    """Whether each of ``keys`` is in ``known`` (a few dozen keys: a set lookup each, where
    ``np.isin`` sorts both)."""
    return np.fromiter((k in known for k in keys.tolist()), dtype=bool, count=len(keys))


class _Epoch:
    """One receiver's signals of an epoch, sorted by signal key, with the broadcast
    corrections applied: ``code`` and ``phase`` (m) are rho + receiver clock (+ lambda N for
    the phase) and the residual errors."""

    def __init__(self, block: np.ndarray, cols: dict[str, int]):
        if "health" in cols:
            block = block[block[:, cols["health"]] == 0]
        freq = block[:, cols["frequency"]]
        system = block[:, cols["system_code"]] if "system_code" in cols else np.full(
            len(block), float(ord("G")))
        keys = ddiff.signal_keys(system, block[:, cols["sv"]], freq)
        order = np.argsort(keys, kind="stable")
        block, keys, freq = block[order], keys[order], freq[order]

        def c(name: str) -> np.ndarray:
            return block[:, cols[name]]

        self.keys = keys
        self.wavelength = C_M_S / freq
        self.gamma = (F_L1_HZ / freq) ** 2
        clock = c("sat_clock")
        iono, tropo = _zero_nan(c("iono")), _zero_nan(c("tropo"))
        delay = _zero_nan(c("group_delay")) if "group_delay" in cols else 0.0
        self.code = c("pseudorange") + clock - iono - tropo
        self.phase = self.wavelength * c("carrier_phase") + clock + delay + iono - tropo
        self.lli = _zero_nan(c("lli")).astype(np.int64)
        self.lock = c("lock_time") if "lock_time" in cols else np.full(len(keys), np.inf)
        self.elevation = c("elevation")
        self.sat_pos = block[:, [cols["sat_x"], cols["sat_y"], cols["sat_z"]]]
        self.sat_vel = block[:, [cols["sat_vx"], cols["sat_vy"], cols["sat_vz"]]]
        self.raw_phase_m = self.wavelength * c("carrier_phase")

    def take(self, index: np.ndarray) -> None:
        """Keep the signals at ``index``."""
        for name in ("keys", "wavelength", "gamma", "code", "phase", "lli", "lock",
                     "elevation", "sat_pos", "sat_vel", "raw_phase_m"):
            setattr(self, name, getattr(self, name)[index])


class _Track:
    """The last time and values seen of each integer key of one receiver (the per-signal
    state of the slip detectors), as sorted arrays: looked up and replaced an epoch at a
    time."""

    def __init__(self, n_values: int):
        self.keys = np.zeros(0, dtype=np.int64)
        self.t = np.zeros(0)
        self.values = np.zeros((0, n_values))

    def swap(self, keys: np.ndarray, t: float, values: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Store ``values`` (len(keys), n_values) seen at ``t`` for the unique ``keys``;
        returns whether each key was known, and its previous time and values (NaN where
        not)."""
        at = np.searchsorted(self.keys, keys)
        known = at < len(self.keys)
        known[known] = self.keys[at[known]] == keys[known]
        at = at[known]
        prev_t = np.full(len(keys), np.nan)
        prev = np.full(values.shape, np.nan)
        prev_t[known] = self.t[at]
        prev[known] = self.values[at]
        self.t[at] = t
        self.values[at] = values[known]
        if not known.all():
            new = ~known
            order = np.argsort(np.r_[self.keys, keys[new]], kind="stable")
            self.keys = np.r_[self.keys, keys[new]][order]
            self.t = np.r_[self.t, np.full(int(new.sum()), t)][order]
            self.values = np.concatenate([self.values, values[new]])[order]
        return known, prev_t, prev


def _geometry_free(keys: np.ndarray, phase_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per satellite with two bands or more: lambda_1 phi_1 - lambda_2 phi_2 of its first two
    (by band key), and the satellite's part of the key; signals sorted by key."""
    sat = keys // 10_000
    first = np.r_[True, sat[1:] != sat[:-1]]
    idx = np.flatnonzero(first)
    has_second = np.r_[idx[1:], len(keys)] - idx >= 2
    idx = idx[has_second]
    return sat[idx], phase_m[idx] - phase_m[idx + 1]


class RtkInsEkf(Estimator):
    """Tightly coupled RTK/INS error-state EKF (module docstring)."""

    name = "rtk_ins_ekf"
    needs = ("imu", "gnss_raw", "gnss_base_raw")
    uses = ("odometer",)
    paper = ("tightly coupled RTK/INS EKF: double-differenced code and carrier phase, LAMBDA "
             "(Chang, Yang & Zhou 2005) with ratio test, partial fixing and fix-and-hold")
    defaults = DEFAULTS
    config_help = CONFIG_HELP
    output_columns = OUTPUT_COLUMNS

    def setup(self) -> None:
        cfg = self.config
        if cfg["nhc_point"] not in NHC_POINTS:
            raise InputError(f"config of rtk_ins_ekf: nhc_point must be one of "
                             f"{', '.join(NHC_POINTS)}, got {cfg['nhc_point']!r}")
        raw = self.columns["gnss_raw"]
        missing = [c for c in ("carrier_phase", "frequency", "lli") if c not in raw]
        if missing:
            raise InputError(f"rtk_ins_ekf needs carrier phase: the dataset's gnss_raw lacks "
                             f"{', '.join(missing)} (sensors.gnss.carrier_phase)")
        self._base_xyz = self._base_position()
        site = Installation.from_datasheet(self.datasheet)
        lever = cfg["lever_arm"] if cfg["lever_arm"] is not None else site.antenna
        self._lever = np.zeros(3) if lever is None else np.asarray(lever, dtype=float)
        imu = imu_error_model(self.datasheet)
        n_slots, n_iono = self._state_pool()
        p0 = np.r_[[cfg["initial_position_std"]] * 3, [cfg["initial_velocity_std"]] * 3,
                   np.radians(cfg["initial_attitude_std"]),
                   np.broadcast_to(imu.accel_bias_initial, 3),
                   np.broadcast_to(imu.gyro_bias_initial, 3)]
        self.ins = InsFilter(self.initial, self.columns["imu"], self.imu_output == "increment",
                             p0, imu, mounting=site.mounting,
                             extra_sigma=np.zeros(n_slots + n_iono),
                             extra_tau=np.r_[np.full(n_slots, np.inf),
                                             np.full(n_iono, cfg["iono_correlation_time"])],
                             sparse=True, scale_noise_window=cfg["scale_noise_window"])
        code_tau = cfg["code_correlation_time"]
        if code_tau is None:
            code_tau = (self.datasheet.get("gnss") or {}).get("carrier_smoothing") or 0.0
        self._code_inflation = gnss_model.correlated_noise_inflation(
            float(code_tau), float(cfg["gnss_interval"]))
        self._phase_inflation = gnss_model.correlated_noise_inflation(
            float(cfg["phase_correlation_time"]), float(cfg["gnss_interval"]))
        self._mask = math.radians(cfg["elevation_mask"])
        self._slot: dict[int, int] = {}
        self._free = list(range(n_slots - 1, -1, -1))
        self._iono_slot: dict[int, int] = {}  # satellite key -> extra-state index
        self._iono_free = list(range(n_slots + n_iono - 1, n_slots - 1, -1))
        self._iono_seen: dict[int, float] = {}
        self._held: set[int] = set()
        self._code_used: set[int] = set()  # rover signals whose code arc the filter has used
        self._last_seen: dict[int, float] = {}
        # per receiver (rover, base): each signal's lock time and half-cycle flag, each
        # satellite's geometry-free phase, when last seen
        self._signal_track = (_Track(2), _Track(2))
        self._gf_track = (_Track(1), _Track(1))
        self._base: tuple[float, np.ndarray] | None = None
        self._status = np.nan
        self._status_t = -np.inf
        self._ratio = np.nan
        self._n_fixed = 0
        self._fixed_dx: np.ndarray | None = None  # the fix's correction of the nav errors
        self._fixed_p: np.ndarray | None = None
        self._phase_rows: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._held_epoch = False  # the epoch's double differences all held
        self._groups = np.zeros(0, dtype=np.int64)  # the epoch's signals' groups
        self._pending = np.zeros(0, dtype=bool)  # half cycle unresolved, per signal
        self.nis_gnss = np.nan
        self.nis_gnss_dof = np.nan
        self._odo = cfg["odometer"] and "odometer" in self.columns
        self._next_odometer = -np.inf
        if self._odo:
            self._speed = self.columns["odometer"]["speed"]
            self._odo_sigma = odometer_speed_sigma(self.datasheet)
            self._odo_still_sigma = odometer_speed_sigma(self.datasheet, 0.0)
            self._odo_delay = odometer_delay_s(self.datasheet)
            self._rear = site.rear_axle if cfg["nhc_point"] == "rear_axle" else None
            self._slip_model = (NonholonomicNoise(site.wheelbase or 2.7)
                                if self._rear is not None else None)

    def _state_pool(self) -> tuple[int, int]:
        """How many ambiguity and ionosphere states to hold: ``ambiguity_states`` (and half
        as many satellites), or ``SATELLITES_PER_SYSTEM`` per system of the datasheet's
        receiver and as many ambiguities per satellite as the system has signals."""
        given = self.config["ambiguity_states"]
        if given is not None:
            return int(given), max(int(given) // 2, 1)
        gnss = self.datasheet.get("gnss") or {}
        signals = gnss.get("signals") or {}
        systems = gnss.get("systems") or list(signals) or ["gps"]
        per_system = [len(signals.get(system) or ()) or 2 for system in systems]
        return (SATELLITES_PER_SYSTEM * sum(per_system),
                SATELLITES_PER_SYSTEM * len(per_system))

    def _base_position(self) -> np.ndarray:
        """The base antenna's ECEF position (m): ``base_position`` or the datasheet's."""
        given = self.config["base_position"]
        if given is not None:
            if len(given) != 3:
                raise InputError("config of rtk_ins_ekf: base_position must be [lat, lon, "
                                 f"alt] (deg, deg, m), got {given!r}")
            lat, lon, alt = (float(x) for x in given)
            return geodetic_to_ecef(math.radians(lat), math.radians(lon), alt)
        surveyed = (self.datasheet.get("gnss_base") or {}).get("surveyed_position")
        if not surveyed:
            raise InputError("rtk_ins_ekf needs the base station's position: the dataset's "
                             "datasheet has no gnss_base.surveyed_position (a dataset made "
                             "before it was written: generate it again) and the config no "
                             "base_position")
        return np.array([surveyed["x"], surveyed["y"], surveyed["z"]], dtype=float)

    # -- streams -------------------------------------------------------------------------------
    def on_imu(self, t: float, row: np.ndarray) -> None:
        self.ins.add_imu(t, row)

    def on_gnss_base_raw(self, t: float, block: np.ndarray) -> None:
        self._base = (t, block)

    def on_odometer(self, t: float, row: np.ndarray) -> None:
        if not self._odo or t < self._next_odometer - 1e-6:
            return
        self._next_odometer = t + 1.0 / self.config["odometer_rate"]
        ins = self.ins
        ins.flush()
        speed = float(row[self._speed])
        dz, h = aiding.odometer(ins.q, ins.v, speed, self.config["nhc"], ins.n_states,
                                ins.mean_rate, self._rear)
        accel = ins.mean_force[0] + quat_to_dcm(ins.q)[2, 0] * G0
        sigma = self._odo_sigma if speed != 0.0 else self._odo_still_sigma
        var = [sigma**2 + (self._odo_delay * accel) ** 2 + (ODOMETER_SCALE_SIGMA * speed) ** 2]
        if len(dz) == 3:
            if self._slip_model is not None:
                lateral, vertical = self._slip_model.sigma_of_state(ins.q, ins.v, ins.mean_rate,
                                                                    ins.mean_force)
            else:
                lateral = vertical = NonholonomicNoise.floor
            var += [lateral**2, vertical**2]
        ins.update(dz, h, np.diag(var))

    def on_gnss_raw(self, t: float, block: np.ndarray) -> None:
        if self._base is None or abs(self._base[0] - t) > 1e-6 or len(block) == 0:
            return
        cols = self.columns["gnss_raw"]
        rover = _Epoch(block, cols)
        base = _Epoch(self._base[1], self.columns["gnss_base_raw"])
        self._detect_slips(t, rover, base)
        _, ir, ib = np.intersect1d(rover.keys, base.keys, assume_unique=True,
                                   return_indices=True)
        rover.take(ir)
        base.take(ib)
        usable = ((rover.elevation >= self._mask) & np.isfinite(rover.code)
                  & np.isfinite(base.code))
        rover.take(usable)
        base.take(usable)
        if len(rover.keys) == 0:
            return
        self.ins.flush()
        phase_ok = np.isfinite(rover.phase) & np.isfinite(base.phase)
        self._pending = ((rover.lli | base.lli) & HALF_CYCLE) != 0
        slots = self._assign_slots(rover, base, phase_ok)
        for key in rover.keys:
            self._last_seen[int(key)] = t
        self._iono, self._iono_scale = self._assign_iono(t, rover)
        self._update(rover, base, slots)
        self._resolve(rover, slots)
        self._status_t = t

    # -- cycle slips and states ----------------------------------------------------------------
    def _detect_slips(self, t: float, rover: _Epoch, base: _Epoch) -> None:
        """Reset the ambiguity of every signal with a slip or a loss of lock at either
        receiver (module docstring): LLI bit 0, a lock time that fell, a half cycle that
        cleared, a geometry-free jump, a gap."""
        max_gap = float(self.config["max_gap"])
        slipped = []
        for ep, signals, satellites in zip((rover, base), self._signal_track,
                                           self._gf_track, strict=True):
            half = (ep.lli & HALF_CYCLE) != 0
            known, prev_t, prev = signals.swap(ep.keys, t, np.stack([ep.lock, half], axis=1))
            relocked = ((ep.lli & LOSS_OF_LOCK) != 0) | (known & (
                (ep.lock < prev[:, 0] - 1e-6) | (t - prev_t > max_gap)))
            lost = relocked | (known & (prev[:, 1] == 1.0) & ~half)
            if ep is rover:  # a new tracking arc restarts the receiver's carrier smoothing
                self._code_used.difference_update(ep.keys[relocked].tolist())
            sats, gf = _geometry_free(ep.keys, ep.raw_phase_m)
            known, prev_t, prev = satellites.swap(sats, t, gf[:, None])
            jumped = sats[known & (t - prev_t <= max_gap)
                          & (np.abs(gf - prev[:, 0]) > self.config["slip_geometry_free"])]
            slipped.append(ep.keys[lost | np.isin(ep.keys // 10_000, jumped)])
        slipped = np.unique(np.concatenate(slipped)).tolist()
        for key in slipped:
            self._release(key)
        stale = [k for k, seen in self._last_seen.items() if t - seen > max_gap]
        for key in stale:
            self._release(key)
            del self._last_seen[key]
        # a satellite's ionosphere state outlives a gap (a tunnel) for a tenth of its
        # correlation time, its value still 90 % correlated with the truth's then
        iono_gap = 0.1 * float(self.config["iono_correlation_time"])
        for sat in [k for k, seen in self._iono_seen.items() if t - seen > iono_gap]:
            index = self._iono_slot.pop(sat)
            self.ins.set_extra_sigma(index, 0.0)
            self.ins.extra[index] = 0.0
            self._iono_free.append(index)
            del self._iono_seen[sat]

    def _assign_iono(self, t: float, rover: _Epoch) -> tuple[np.ndarray, np.ndarray]:
        """The extra-state index (after the 15) of each signal's satellite's ionosphere
        gradient (-1: none free), and the factor (m per ppm) that turns it into the
        single-difference L1 delay: the current baseline times the thin-shell obliquity (350
        km) at the satellite's elevation (module docstring). A new satellite's state starts
        at zero with 1-sigma ``iono_ppm``."""
        ins = self.ins
        baseline = float(np.linalg.norm(geodetic_to_ecef(*ins.pos) - self._base_xyz))
        ratio = EARTH_RADIUS_M * np.cos(rover.elevation) / (EARTH_RADIUS_M + IONO_SHELL_M)
        scale = 1e-6 * baseline / np.sqrt(1.0 - ratio**2)
        sats = rover.keys // 10_000
        out = np.full(len(sats), -1, dtype=np.int64)
        for i, sat in enumerate(sats.tolist()):
            index = self._iono_slot.get(sat)
            if index is None:
                if not self._iono_free:
                    continue
                index = self._iono_free.pop()
                self._iono_slot[sat] = index
                ins.set_extra_sigma(index, self.config["iono_ppm"])
                ins.extra[index] = 0.0
            self._iono_seen[sat] = t
            out[i] = index
        return out, scale

    def _release(self, key: int) -> None:
        """Forget a signal's ambiguity (its slot is given back, its state zeroed)."""
        slot = self._slot.pop(key, None)
        self._held.discard(key)
        if slot is not None:
            self.ins.set_extra_sigma(slot, 0.0)
            self.ins.extra[slot] = 0.0
            self._free.append(slot)

    def _assign_slots(self, rover: _Epoch, base: _Epoch, phase_ok: np.ndarray) -> np.ndarray:
        """The ambiguity slot of each signal (-1: its phase is not used this epoch); a signal
        new to the filter gets a free slot, started at its (phase - code) / lambda."""
        slots = np.full(len(rover.keys), -1, dtype=np.int64)
        sigma = float(self.config["ambiguity_std"])
        for i in np.flatnonzero(phase_ok):
            key = int(rover.keys[i])
            slot = self._slot.get(key)
            if slot is None:
                if not self._free:
                    continue
                slot = self._free.pop()
                self._slot[key] = slot
                self.ins.set_extra_sigma(slot, sigma)
                sd_phase = rover.phase[i] - base.phase[i]
                sd_code = rover.code[i] - base.code[i]
                self.ins.extra[slot] = (sd_phase - sd_code) / rover.wavelength[i]
            slots[i] = slot
        return slots

    # -- measurement update --------------------------------------------------------------------
    def _geometry(self, rover: _Epoch, base: _Epoch) -> tuple[np.ndarray, np.ndarray,
                                                                np.ndarray, float]:
        """Single-differenced predicted ranges (m), NED lines of sight of the rover (m, 3),
        the skew matrix of the lever arm in NED (the attitude error's columns) and the
        baseline length (m)."""
        ins = self.ins
        c_bn = quat_to_dcm(ins.q)
        c_ne = ned_to_ecef_matrix(ins.pos[0], ins.pos[1])
        arm = c_bn @ self._lever
        antenna = geodetic_to_ecef(*ins.pos) + c_ne @ arm
        # the two receivers in one call: (2, m, 3) satellites against (2, 3) antennas
        rng, _, los = gnss_model.predict(np.stack([rover.sat_pos, base.sat_pos]),
                                         np.stack([rover.sat_vel, base.sat_vel]),
                                         np.stack([antenna, self._base_xyz]), np.zeros(3))
        return (rng[0] - rng[1], los[0] @ c_ne, skew(arm),
                float(np.linalg.norm(antenna - self._base_xyz)))

    def _sd_variance(self, rover: _Epoch, base: _Epoch, baseline: float, code: bool
                     ) -> np.ndarray:
        """Variance (m^2) of each signal's single difference (module docstring)."""
        cfg = self.config
        sin_el = np.maximum(np.sin(rover.elevation), 0.1)
        if code:
            # a code arc's first epoch in the filter counts at its marginal sigma, the later
            # ones at what they add to it (module docstring)
            seen = _members(rover.keys, self._code_used)
            rover_std = np.where(seen, cfg["code_std"] * self._code_inflation,
                                 cfg["code_arc_std"])
            base_std = cfg["base_code_std"]
        else:
            rover_std = cfg["phase_std"] * self._phase_inflation
            base_std = cfg["base_phase_std"]  # a still antenna: its reflections do not move
        return (rover_std**2 + base_std**2) / sin_el**2

    def _rows(self, rover: _Epoch, base: _Epoch, geometry: tuple[np.ndarray, np.ndarray,
                                                                   np.ndarray, float],
              sel: np.ndarray, priority: np.ndarray | None, observed: np.ndarray,
              slots: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                 np.ndarray, np.ndarray]:
        """dz, H, R of the double differences of the signals ``sel`` (their single
        differences ``observed``, m): code rows, or phase rows with the signals' ambiguity
        ``slots``; and each row's signal and reference indices. ``geometry``: the
        single-differenced ranges, the NED lines of sight, the lever arm's attitude columns
        and the baseline (``_geometry``)."""
        ins = self.ins
        sd_range, u, arm, baseline = geometry
        code = slots is None
        idx = np.flatnonzero(sel)
        ref = ddiff.references(self._groups[idx], rover.elevation[idx],
                               None if priority is None else priority[idx])
        d, nonref = ddiff.difference_matrix(ref)
        sig, refs = idx[nonref], idx[ref[nonref]]
        du = u[sig] - u[refs]
        h = np.zeros((len(sig), ins.n_states))
        h[:, 0:3] = -du
        h[:, 6:9] = du @ arm
        dz = d @ (sd_range[idx] - observed[idx])
        # the single-difference ionosphere: the code delayed, the phase advanced
        sign = 1.0 if code else -1.0
        for rows_of, side in ((sig, 1.0), (refs, -1.0)):
            iono = self._iono[rows_of]
            have = iono >= 0
            g = (sign * side) * rover.gamma[rows_of[have]] * self._iono_scale[rows_of[have]]
            h[np.flatnonzero(have), N_STATES + iono[have]] += g
            dz[have] += g * ins.extra[iono[have]]
        if not code:
            lam = rover.wavelength[sig]
            a = ins.extra[slots[sig]] - ins.extra[slots[refs]]
            dz = dz + lam * a
            h[np.arange(len(sig)), N_STATES + slots[sig]] = lam
            h[np.arange(len(sig)), N_STATES + slots[refs]] = -lam
        var = self._sd_variance(rover, base, baseline, code)[idx]
        return dz, h, ddiff.double_difference_covariance(d, var), sig, refs

    def _update(self, rover: _Epoch, base: _Epoch, slots: np.ndarray) -> None:
        """One update with the epoch's DD code (gated) and phase rows; phase innovations the
        INS did not predict are slips (their states reset, the rows formed again)."""
        ins = self.ins
        self._phase_rows = None
        self._groups = ddiff.group_of(rover.keys)
        geometry = self._geometry(rover, base)
        sd_phase = rover.phase - base.phase
        for _ in range(2):
            # a held reference first, then one whose half cycle is resolved
            priority = (np.where(_members(rover.keys, self._held), 2, 0)
                        + np.where(self._pending, 0, 1))
            dz_p, h_p, r_p, sig, refs = self._rows(rover, base, geometry, slots >= 0, priority,
                                                   sd_phase, slots)
            s_p = gating.innovation_variances(ins.kf.p, h_p, r_p)
            lam = rover.wavelength[sig]
            bad = ((np.abs(dz_p) > self.config["slip_sigmas"] * np.sqrt(s_p))
                   & (np.abs(dz_p) > self.config["slip_cycles"] * lam))
            if not bad.any():
                break
            for ref in np.unique(refs):
                members = refs == ref
                if bad[members].sum() * 2 > members.sum():  # the reference itself slipped
                    culprits = [ref]
                else:
                    culprits = sig[members & bad].tolist()
                for i in culprits:
                    key = int(rover.keys[i])
                    self._release(key)
                    slots[i] = -1
            slots = self._reassign(rover, base, slots)
        self._held_epoch = self._all_held(rover, sig, refs)
        keep_code = self.config["held_code"] or not self._held_epoch
        if keep_code:
            dz_c, h_c, r_c, _, _ = self._rows(rover, base, geometry,
                                              np.ones(len(rover.keys), dtype=bool), None,
                                              rover.code - base.code, None)
            s_c = gating.innovation_variances(ins.kf.p, h_c, r_c)
            keep = gating.rows_passing(dz_c, s_c, float(self.config["gate_probability"]))
            dz_c, h_c, r_c = dz_c[keep], h_c[keep], r_c[np.ix_(keep, keep)]
            self._code_used.update(rover.keys.tolist())
        else:
            dz_c, h_c, r_c = np.zeros(0), np.zeros((0, ins.n_states)), np.zeros((0, 0))
        dz = np.concatenate([dz_c, dz_p])
        if len(dz) == 0:
            return
        h = np.vstack([h_c, h_p])
        k = len(dz_c)
        r = np.zeros((len(dz), len(dz)))
        r[:k, :k] = r_c
        r[k:, k:] = r_p
        s = ins.update(dz, h, r)
        self.nis_gnss = gating.normalised_innovation_squared(dz, s)
        self.nis_gnss_dof = float(len(dz))
        self._phase_rows = (sig, refs, slots)

    def _all_held(self, rover: _Epoch, sig: np.ndarray, refs: np.ndarray) -> bool:
        """Whether the epoch's double differences (signals ``sig`` against ``refs``) are at
        least ``min_fixed`` and all of held ambiguities."""
        return len(sig) >= self.config["min_fixed"] and bool(
            _members(rover.keys[np.r_[sig, refs]], self._held).all())

    def _reassign(self, rover: _Epoch, base: _Epoch, slots: np.ndarray) -> np.ndarray:
        """Slots again after resets: the reset signals start new ambiguities."""
        phase_ok = slots >= 0
        for i in np.flatnonzero(slots == -1):
            phase_ok[i] = int(rover.keys[i]) not in self._slot and np.isfinite(rover.phase[i])
        fresh = self._assign_slots(rover, base, phase_ok)
        return np.where(slots >= 0, slots, fresh)

    # -- integer ambiguities -------------------------------------------------------------------
    def _resolve(self, rover: _Epoch, slots: np.ndarray) -> None:
        """LAMBDA on the epoch's DD ambiguities, the fixed solution, fix and hold."""
        self._fixed_dx = None
        self._fixed_p = None
        self._ratio = np.nan
        self._n_fixed = 0
        self._status = 1.0
        rows = self._phase_rows
        if rows is None or len(rows[0]) == 0:
            return
        sig, refs, slots = rows
        keys = [int(rover.keys[i]) for i in np.unique(np.r_[sig, refs])]
        cfg = self.config
        if self._held_epoch:
            self._status = 2.0
            self._n_fixed = len(sig)
            return
        ins = self.ins
        n_amb = ins.n_states - N_STATES
        # a double difference with a half cycle still unresolved is an integer number of
        # half cycles
        scale = np.where(self._pending[sig] | self._pending[refs], 2.0, 1.0)
        d = np.zeros((len(sig), n_amb))
        d[np.arange(len(sig)), slots[sig]] = scale
        d[np.arange(len(sig)), slots[refs]] = -scale
        a = d @ ins.extra
        amb = slice(N_STATES, ins.n_states)
        p = ins.kf.p
        q_a = d @ p[amb, amb] @ d.T
        try:
            res = ambiguity.resolve(a, q_a, cfg["ratio_threshold"], cfg["min_success_rate"],
                                    int(cfg["min_fixed"]), int(cfg["failure_samples"]))
        except np.linalg.LinAlgError:
            return
        self._ratio = res.ratio
        if not res.fixed:
            return
        p_xa = p[:N_STATES, amb] @ d.T
        gain = np.linalg.solve(q_a, p_xa.T).T  # P_xa Q_a^-1
        fixed_p = p[:N_STATES, :N_STATES] - gain @ (q_a - res.q_fixed) @ gain.T
        if np.max(np.diag(fixed_p)[:3]) > cfg["fixed_position_std"] ** 2:
            return  # a partial fix that leaves the position a float one
        self._fixed_dx = gain @ (a - res.a_fixed)
        self._fixed_p = fixed_p
        self._status = 2.0
        self._n_fixed = res.n_fixed
        if cfg["hold"] and res.n_fixed == len(a):
            hold = float(cfg["hold_std"])
            h = np.zeros((len(a), ins.n_states))
            h[:, amb] = d
            ins.update(a - res.a_fixed, h, np.eye(len(a)) * hold**2)
            self._held.update(keys)
            self._fixed_dx = None
            self._fixed_p = None

    # -- output --------------------------------------------------------------------------------
    def solution(self, t: float) -> list[float]:
        ins = self.ins
        ins.flush()
        at_epoch = abs(t - self._status_t) < 1e-6
        if at_epoch and self._fixed_dx is not None:
            q, v, pos = nav_error.correct(ins.q, ins.v, ins.pos, self._fixed_dx[:9])
            p = self._fixed_p
            roll, pitch, yaw = quat_to_euler(q)
            std = np.sqrt(np.maximum(np.diag(p)[:6], 0.0))
            jac = nav_error.euler_error_jacobian(quat_to_dcm(q))
            std_att = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", jac, p[6:9, 6:9], jac), 0.0))
            row = [math.degrees(pos[0]), math.degrees(pos[1]), pos[2], *v, roll, pitch, yaw,
                   *std, *std_att, *(ins.ba - self._fixed_dx[9:12]),
                   *(ins.bg - self._fixed_dx[12:15])]
        else:
            row = ins.solution_row()
        status = self._status if at_epoch else np.nan
        nis = (self.nis_gnss, self.nis_gnss_dof) if at_epoch else (np.nan, np.nan)
        return [*row, status, self._ratio if at_epoch else np.nan,
                float(self._n_fixed) if at_epoch else np.nan, *nis]
