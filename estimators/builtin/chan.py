"""Chan et al., "Robust Navigation System for a Land Vehicle" (seeds/001): tightly coupled
INS/GPS on pseudorange and pseudorange rate, as a total-state unscented Kalman filter
(``tc_ukf``) and as its error-state extended Kalman filter counterpart (``tc_ekf``), each with the
non-holonomic constraint (NHC) as a measurement.

State (paper, section "System Models"): latitude, longitude, height, NED velocity, attitude,
accelerometer biases, gyro biases (random constants), receiver clock bias cb (m) and drift d (m/s)
(random walk). The UKF carries the attitude as a quaternion; since a quaternion inside the
sigma-point covariance is rank deficient (four numbers, three degrees of freedom), the filter's
17-dimensional tangent space is

    [dr_n, dr_e, dr_d (m), dv_n, dv_e, dv_d (m/s), psi_n, psi_e, psi_d (rad),
     ba_x, ba_y, ba_z (m/s^2), bg_x, bg_y, bg_z (rad/s), cb (m), d (m/s)]

with position and attitude as small NED displacements and rotations around the mean
(``estimators.toolbox.nav_error`` convention: C_b^n(point) = exp([psi x]) C_b^n(mean)). The EKF's
error state is the same 17-vector (paper: the EKF state vector with phi_N, phi_E, phi_D).

Choices where the paper is silent, ambiguous or wrong (also in docs/reproduction_chan.md):

* UKF weights: W_i = 1 / (2 (n + lambda)) (the paper prints lambda / (2 (n + lambda)), which does
  not sum to one); P^xy has no R added (the paper adds R to P^xy, a misprint); the covariance
  update is P = P^xx - K P^yy K^T (the paper prints K P^xy K^T, dimensionally wrong);
  alpha = 0.99, beta = 2, kappa = 0 (paper).
* Propagation (paper: each sigma point integrated through the noise-free dynamics with 10 RK4
  steps per GPS interval): every sigma point is integrated with one RK4 step of eqs. 1-3 per IMU
  interval (``strapdown.rk4_step``; rates at the interval's ends and their mean at its middle),
  i.e. 100 steps per second at 100 Hz rather than 10, so that no IMU sample is skipped (an
  IMU that outputs increments gives the intervals' mean rates, used at the interval's end and,
  from the interval before, at its start). The
  process noise is added to the propagated covariance (additive Q) and the points are drawn
  again from it before the measurement update.
* Eq. 7 lacks the receiver position and prints "+" for a product: the model is
  ``estimators.toolbox.gnss_model`` (range to r_ins + C_b^n l_b, with the Sagnac rotation).
* NHC: the rows are the body y and z velocities (the paper's text says "x and y" once) of the
  point where the constraint holds on a car, the rear axle (the wheels there do not steer;
  ``constraints.nonholonomic`` with the lever arm of the datasheet's rear axle,
  ``toolbox.installation``; at the IMU itself on a rigid body or with ``nhc_point: imu``):
  v^b = C_n^b v^n + w x r with w the compensated gyro rate. The paper says its R^v "depends on
  the noise of forward velocity and misalignment angle" and prints no value; here its 1-sigma
  is the car's physics (``constraints.NonholonomicNoise`` from the datasheet's wheelbase: the
  rear tyres' slip growing with speed times lateral acceleration, the body's pitch on its
  springs, the road's roughness, over a 0.1 m/s floor), evaluated at the filter's speed, yaw
  rate and forward acceleration of each update; at the IMU, the floor, 0.1 m/s (the value
  chosen for a rigid body before). ``nhc_std`` (a number) fixes it instead. The UKF predicts
  the rows of every sigma point with ``constraints.body_velocity_points``. It is stacked with
  the GPS measurements at each GPS epoch and applied alone at 1 Hz when an expected GPS epoch
  has not come half an interval after its time (complete outages).
* Not printed: P0, Q, R. Two settings, ``tuning``:

  - ``paper`` (what the reproduction, ``simulator/reproduce/chan.py``, uses, so that its
    figures do not move): P0 ``initial_position_std`` per axis (10 m), 0.5 m/s, 1 deg roll and
    pitch, 3 deg yaw, the bias priors of an automotive MEMS IMU (10 mg, 0.2 deg/s), cb and d
    from the first GPS epoch's residuals with 30 m and 3 m/s; Q 3x the automotive preset's
    white noise, small bias random walks, the TCXO clock (``gnss_model.clock_noise``); R the
    receiver's reported 1-sigma of each signal (the config's ``pseudorange_std``, 3 m, and
    ``range_rate_std``, 0.1 m/s, when the stream lacks them), white, as the paper treats
    them; no gate (``PAPER_TUNING``).
  - ``datasheet`` (the default): what a user knows from the dataset's datasheet
    (``toolbox.sensor_datasheet``): the noise densities (at least a tactical grade's, the
    strapdown's own discretisation error: an ``ideal`` IMU's datasheet of zeros made the tilt
    sigma fall 20 times below the error, roll NSE 522); the bias priors are the turn-on
    biases (the accelerometers' with their scale factor and misalignment under 1 g), the bias
    walks the rate random walk with the bias instability; the gyro and accelerometer scale
    factors and misalignments times the rate and the non-gravity specific force as extra
    white noise over ``SCALE_FACTOR_TIME_S`` (a constant scale-factor error adds up over a
    turn, which a white Q only approximates). The receiver's pseudorange errors are
    correlated in time (docs/gnss-errors.md), so R white at 1 Hz made the filters 10-1000x
    over-confident (position NEES 40-1989). Modelled as states instead
    (``toolbox.range_budget``, as ``fgo_tc`` carries them as variables), each Gauss-Markov of
    30 min: the broadcast ionosphere's residual shared by the satellites, four unit-variance
    states (its part common to them, 1-sigma |scale - 1| of the receiver datasheet's
    ``iono_scale``, and its smooth field's value and north and east gradient at the zenith
    pierce point, 1-sigma scale ``iono_residual``; each pseudorange's row their coefficients
    from its broadcast delay I and pierce point, ``toolbox.iono_field``; ``iono_scale_std`` is
    their combined 1-sigma, 0: none), and one range-error state per satellite
    (``toolbox.range_bias``, 16 channels: the signal-in-space error, the field's remainder at
    its pierce point and the troposphere's residual); R keeps the rest of the reported
    variance (tracking noise and multipath after the carrier smoothing), scaled by the
    correlated-noise inflation of the datasheet's ``carrier_smoothing``
    (``gnss_model.correlated_noise_inflation``). The field taken instead as common plus an
    independent share per satellite missed its gradient across the sky, a range error that
    the position takes in whole (``toolbox.iono_field``). A chi-square gate (1 dof, probability
    ``gate_probability``, 0.999) drops each pseudorange whose innovation is not plausible
    against H P H^T plus its reported (uninflated) variance: the NLOS delays of a street
    canyon, tens of metres, which no reported sigma contains (Groves 2013, section 17.3.1;
    the EKF keeps that satellite's range rate, the UKF drops both rows).

  Each of the ``TUNED_KEYS`` given as a number in the config overrides the setting's value.
  The antenna lever arm is the datasheet's ``antenna_lever_arm`` unless ``lever_arm`` is given.
  The solution's attitude sigmas are those of roll, pitch and yaw
  (``nav_error.euler_covariance``; the psi-frame sigmas were written as roll and pitch before,
  which misstated the tilt sigmas by the heading's rotation), and ``nis_gnss``,
  ``nis_gnss_dof`` give the NIS of each GNSS update's rows (SPEC section 8).
* The EKF (eqs. 4-6): position error rate dr' = dv as printed (eq. 4), velocity and attitude error
  equations in the psi convention of ``nav_error`` (eq. 5: -[f^n x] psi - C_b^n dba
  - (2 w_ie + w_en) x dv - (2 dw_ie + dw_en) x v; eq. 6: psi' = -w_in x psi - C_b^n dbg - dw_in,
  with dw_ie from the latitude error and dw_en from the velocity error; the paper's phi is -psi).
  The nominal state is propagated by the toolbox strapdown (``strapdown.propagate``), the
  covariance at 10 Hz with Phi = I + F dt + (F dt)^2 / 2; closed loop (errors fed back after each
  update). Measurements linearised at the nominal state (the "linearised model given in [2]"):
  the pseudorange rows carry the lever arm's attitude term, the range-rate rows -los on the
  velocity error, 1 on the drift and the lever arm's velocity C_b^n (w x l) terms in attitude and
  gyro bias (a 1.5 m mast on a body rolling at 0.1 rad/s moves 0.15 m/s, five times the
  Doppler noise; left out before).
* The UKF runs on the toolbox's sigma-point driver (``estimators.toolbox.ukf``, symmetric set)
  with this module's ``boxplus``/``boxminus`` on an 18-number nominal state (position, velocity,
  quaternion, biases, clock); the whole point set moves through one compiled call per batch of
  IMU samples (``_propagate_points``).

Public names
------------
TcUkf, TcEkf, boxplus, boxminus, error_dynamics.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numba import njit

from estimators.base import NAV_COLUMNS, STD_COLUMNS, Estimator
from estimators.toolbox import constraints, gating, gnss_model, nav_error
from estimators.toolbox.config_help import shared_help
from estimators.toolbox.datasheet import SCALE_FACTOR_TIME_S
from estimators.toolbox.installation import Installation
from estimators.toolbox.iono_field import SHARED_TERMS
from estimators.toolbox.kalman import ErrorState
from estimators.toolbox.range_bias import RangeBiasChannels
from estimators.toolbox.range_budget import CORRELATION_TIME_S, RangeBudget, range_budget
from estimators.toolbox.sensor_datasheet import (
    ACCEL_NOISE_FLOOR,
    GYRO_NOISE_FLOOR,
    ImuDatasheet,
)
from estimators.toolbox.strapdown import propagate, rk4_step
from estimators.toolbox.ukf import SigmaPointFilter
from simulator.datasheet import iono_residual_fractions
from simulator.earth import (
    OMEGA_E_RAD_S,
    dcm_to_euler,
    earth_rate_ned,
    geodetic_rates,
    geodetic_to_ecef,
    ned_to_ecef_matrix,
    normal_gravity,
    quat_multiply,
    quat_to_dcm,
    quat_to_euler,
    radii_of_curvature,
    rotvec_to_quat,
    skew,
)
from simulator.errors import InputError
from simulator.units import DEG_S, DEG_S_RT_HZ, MILLI_G, MILLI_G_RT_HZ

N_STATES = 17  # [dr(3), dv(3), psi(3), ba(3), bg(3), cb, d]
SENSOR_COLUMNS = ("accel_bias_x", "accel_bias_y", "accel_bias_z", "gyro_bias_x", "gyro_bias_y",
                  "gyro_bias_z", "clock_bias", "clock_drift")
PAPER = ("Chan, Aung, Thar, Lee, Kaung, 'Robust Navigation System for a Land Vehicle' "
         "(tightly coupled INS/GPS, UKF vs EKF, NHC)")
COVARIANCE_RATE_HZ = 10.0  # EKF covariance propagation (and strapdown batch) rate
CLOCK_INIT_STD = (30.0, 3.0)  # cb (m), d (m/s) after the first epoch's residuals
NHC_POINTS = ("rear_axle", "imu")
IONO = 17  # the first ionosphere state, after the 17 (datasheet tuning)
GATE_PROBABILITY = 0.999  # chi-square gate of each pseudorange innovation (1 dof: 10.8)
PSEUDORANGE_STD_FLOOR = 0.1  # m, what is left of a pseudorange's variance at least


# the values chosen for the reproduction (the paper prints no P0, Q or R): ``tuning: paper``
PAPER_TUNING = {
    "accel_bias_std": 10 * MILLI_G,  # m/s^2, prior
    "gyro_bias_std": 0.2 * DEG_S,  # rad/s, prior
    "accel_noise": 0.1 * MILLI_G_RT_HZ * 3,  # m/s^2/sqrt(Hz), velocity random walk (3x datasheet:
    "gyro_noise": 0.005 * DEG_S_RT_HZ * 3,  # rad/s/sqrt(Hz) unmodelled scale factors, vibration)
    "accel_bias_walk": 1e-4,  # m/s^2/sqrt(s)
    "gyro_bias_walk": 1e-5,  # rad/s/sqrt(s)
    "gyro_scale_factor": 0.0,  # 1-sigma, with the misalignment: rate-proportional gyro noise
    "accel_scale_factor": 0.0,  # the same for the accelerometers, on the non-gravity force
    "gyro_z_scale_factor_std": 0.0,  # prior of a z-gyro scale-factor state (0: no state)
    "accel_z_misalignment_std": 0.0,  # prior of the z accelerometer's two misalignment states
    # s: correlation time of the pseudorange errors (0: white, as the paper treats them)
    "pseudorange_correlation_time": 0.0,
    "iono_scale_std": 0.0,  # 1-sigma of the ionosphere's residual, as states (0: none)
    "range_bias_channels": 0,  # per-satellite range-error states (0: none)
}
TUNINGS = ("datasheet", "paper")
TUNED_KEYS = tuple(PAPER_TUNING)
STANDARD_GRAVITY = 9.80665  # m/s^2
RANGE_BIAS_CHANNELS = 16  # per-satellite range-error states of the datasheet tuning
RANGE_BIAS_TIME_S = CORRELATION_TIME_S  # s: their correlation time (signal in space, ...)
SIS_ERROR_M = 0.5  # m: the signal-in-space error without a receiver datasheet (IS-GPS-200 URA)
IONO_CORRELATION_TIME_S = CORRELATION_TIME_S  # s: the broadcast ionosphere residual's
KLOBUCHAR_RESIDUAL = 0.5  # the broadcast model leaves about half the delay (Klobuchar 1987)


DEFAULTS = {
    "nhc": True,
    "nhc_std": None,  # m/s, body y and z velocity; None: from the car's physics (docstring)
    "nhc_point": "rear_axle",  # where the NHC holds: rear_axle (the datasheet's) or imu
    "nhc_rate": 1.0,  # Hz, NHC alone when GPS is missing
    "lever_arm": None,  # IMU to GPS antenna, body FRD, m; None: the datasheet's (else zero)
    "initial_position_std": 10.0,  # m per axis
    "initial_velocity_std": 0.5,  # m/s
    "initial_attitude_std": [1.0, 1.0, 3.0],  # deg roll, pitch, yaw
    "tuning": "datasheet",  # datasheet | paper: where the None keys below come from
    **dict.fromkeys(TUNED_KEYS),  # None: from ``tuning`` (module docstring); a number fixes it
    "pseudorange_std": 3.0,  # m, when the stream reports none
    "range_rate_std": 0.1,  # m/s, when the stream reports none
    "gnss_interval": 1.0,  # s, the epoch interval the correlation is counted in
    "gate_probability": None,  # pseudorange gate; None: 0.999 (datasheet), off (paper)
}
CONFIG_HELP = {  # key -> (SI unit, meaning), shown by `landnav estimators tc_ekf`
    **shared_help("nhc", "nhc_point", "initial_position_std", "initial_velocity_std",
                  "initial_attitude_std"),
    "nhc_std": ("m/s", "its 1-sigma on the body y and z velocity; null: from the car's physics"),
    "nhc_rate": ("Hz", "constraint updates per second while GPS is missing"),
    "lever_arm": ("m", "IMU to GPS antenna, body FRD"),
    "accel_bias_std": ("m/s^2", "prior of the accelerometer biases, 1-sigma"),
    "gyro_bias_std": ("rad/s", "prior of the gyro biases, 1-sigma"),
    "accel_noise": ("m/s^2/sqrt(Hz)", "accelerometer white noise (velocity random walk)"),
    "gyro_noise": ("rad/s/sqrt(Hz)", "gyro white noise (angle random walk)"),
    "accel_bias_walk": ("m/s^3/sqrt(Hz)", "accelerometer bias random walk"),
    "gyro_bias_walk": ("rad/s^2/sqrt(Hz)", "gyro bias random walk"),
    "pseudorange_std": ("m", "pseudorange noise when the stream reports none, 1-sigma"),
    "range_rate_std": ("m/s", "pseudorange-rate noise when the stream reports none, 1-sigma"),
    "pseudorange_correlation_time": ("s", "correlation time of the pseudorange errors (0: "
                                          "white, as the paper treats them)"),
    "gnss_interval": ("s", "the epoch interval the correlation is counted in"),
    "gyro_scale_factor": ("", "gyro scale-factor and misalignment error, 1-sigma: "
                              "rate-proportional gyro noise"),
    "range_bias_channels": ("", "per-satellite range-error states (0: none)"),
    "accel_scale_factor": ("", "accelerometer scale-factor error, 1-sigma: noise on the "
                               "non-gravity force"),
    "gyro_z_scale_factor_std": ("", "prior of a z-gyro scale-factor state (0: no state)"),
    "accel_z_misalignment_std": ("rad", "prior of two states of the z accelerometer's "
                                        "misalignment towards x and y (0: none)"),
    "iono_scale_std": ("", "1-sigma of the ionosphere's relative residual, carried as states "
                           "(0: none)"),
    "tuning": ("", "datasheet: the null keys from the manifest's datasheet (default); paper: "
                   "the reproduction's values"),
    "gate_probability": ("", "pseudorange chi-square gate; null: 0.999 (datasheet), off "
                             "(paper)"),
}


class _TightlyCoupled(Estimator):
    """What the two filters share: configuration, IMU handling, GPS epochs, clock start,
    NHC scheduling, output."""

    needs = ("imu", "gnss_raw")
    paper = PAPER
    output_columns = (*NAV_COLUMNS, *STD_COLUMNS, *SENSOR_COLUMNS, "nis_gnss", "nis_gnss_dof")
    defaults = DEFAULTS
    config_help = CONFIG_HELP

    def setup(self) -> None:
        cfg = self.config
        imu = self.columns["imu"]
        self._gyro_idx = [imu[c] for c in ("gyro_x", "gyro_y", "gyro_z")]
        self._accel_idx = [imu[c] for c in ("accel_x", "accel_y", "accel_z")]
        self._increments = self.imu_output == "increment"
        if cfg["nhc_point"] not in NHC_POINTS:
            raise InputError(f"config of {self.name}: nhc_point must be one of "
                             f"{', '.join(NHC_POINTS)}, got {cfg['nhc_point']!r}")
        if cfg["tuning"] not in TUNINGS:
            raise InputError(f"config of {self.name}: tuning must be one of "
                             f"{', '.join(TUNINGS)}, got {cfg['tuning']!r}")
        site = Installation.from_datasheet(self.datasheet)
        lever = cfg["lever_arm"] if cfg["lever_arm"] is not None else site.antenna
        self._lever = np.zeros(3) if lever is None else np.asarray(lever, dtype=float)
        self.tuning = self._tuning(cfg)
        sheet = ImuDatasheet.from_datasheet(self.datasheet)
        self._triad_misalignment = (sheet.accel.misalignment
                                    if sheet is not None and cfg["tuning"] == "datasheet"
                                    else 0.0)
        tun = self.tuning
        self._pr_inflation = gnss_model.correlated_noise_inflation(
            tun["pseudorange_correlation_time"], cfg["gnss_interval"])
        gnss = self.datasheet.get("gnss") or {}
        self._sis = float(gnss.get("sis_error", SIS_ERROR_M))
        self._budget = self._range_budget(gnss)
        # the ionosphere's quantities shared by an epoch's satellites (``toolbox.range_budget``)
        self._iono_used = (self._budget.shared_in_use() if tun["iono_scale_std"] > 0.0
                           else np.zeros(len(SHARED_TERMS), dtype=bool))
        self._iono = bool(self._iono_used.any())
        self._terms_key: bytes | None = None  # the pseudoranges of ``_terms``
        self._terms = (np.zeros((0, 0)), np.zeros(0))
        self._n_iono = int(self._iono_used.sum())
        self.n_states = N_STATES + self._n_iono
        n_channels = int(tun["range_bias_channels"])
        self._channels = (RangeBiasChannels(self.n_states, n_channels, RANGE_BIAS_TIME_S)
                          if n_channels > 0 else None)
        self.n_states += n_channels
        # the z accelerometer's misalignment towards x and y, two random constants: in a long
        # turn it reads m f_y of the lateral force (1 mrad of 1.45 m/s^2 for the 50 s of a
        # parking helix: 0.07 m/s of vertical velocity, which no white Q describes)
        self._mz = self.n_states if tun["accel_z_misalignment_std"] > 0.0 else None
        self.n_states += 2 * int(self._mz is not None)
        # the z gyro's scale-factor error: the last state (a car turns about z: a constant
        # error adds up over every turn one way, 11 deg over the garage's six helix turns at
        # 0.5 %, which no white Q describes)
        self._sf = self.n_states if tun["gyro_z_scale_factor_std"] > 0.0 else None
        self.n_states += int(self._sf is not None)
        # 1 / correlation time of the states after the 17 (Gauss-Markov), 1/s
        self._inv_tau = np.r_[np.full(self._n_iono, 1.0 / IONO_CORRELATION_TIME_S),
                              np.full(n_channels, 1.0 / RANGE_BIAS_TIME_S),
                              np.zeros(2 * int(self._mz is not None)),
                              np.zeros(int(self._sf is not None))]
        gate = cfg["gate_probability"]
        if gate is None and cfg["tuning"] == "datasheet":
            gate = GATE_PROBABILITY
        self._gate_p = gate
        self._nhc_point = site.rear_axle if cfg["nhc_point"] == "rear_axle" else None
        self._nhc_physics = (constraints.NonholonomicNoise(site.wheelbase or 2.7)
                             if cfg["nhc_std"] is None and self._nhc_point is not None
                             else None)
        self._t_imu: float | None = None
        self._w_prev = np.zeros(3)
        self._f_prev = np.zeros(3)
        self._rate_sq = np.zeros(3)  # sum of w^2 dt per body axis since the last Q
        self._force_sq = np.zeros(3)  # the same of the specific force less 1 g down
        self._clock_started = False
        self._t_update = self.initial.t
        self._next_nhc = np.inf
        self._buf_w: list[np.ndarray] = []
        self._buf_f: list[np.ndarray] = []
        self._buf_dt: list[float] = []
        self.nis_gnss = np.nan  # NIS of the last GNSS update and its dof (NaN between them)
        self.nis_gnss_dof = np.nan
        p0 = np.zeros(self.n_states)
        p0[0:3] = cfg["initial_position_std"]
        p0[3:6] = cfg["initial_velocity_std"]
        p0[6:9] = np.radians(cfg["initial_attitude_std"])
        p0[9:12] = tun["accel_bias_std"]
        p0[12:15] = tun["gyro_bias_std"]
        p0[15:17] = CLOCK_INIT_STD
        p0[IONO:IONO + self._n_iono] = 1.0  # unit-variance quantities (``SHARED_TERMS``)
        if self._sf is not None:
            p0[self._sf] = tun["gyro_z_scale_factor_std"]
        if self._mz is not None:
            p0[self._mz:self._mz + 2] = tun["accel_z_misalignment_std"]
        self._p0 = np.diag(p0**2)

    def _tuning(self, cfg: dict) -> dict:
        """P0, Q and R figures: the config's numbers where given, else those of ``tuning``:
        ``paper`` (``PAPER_TUNING``) or ``datasheet`` (module docstring; the paper's values
        when the dataset has no IMU datasheet)."""
        base = dict(PAPER_TUNING)
        sheet = ImuDatasheet.from_datasheet(self.datasheet)
        if cfg["tuning"] == "datasheet" and sheet is not None:
            g, a = sheet.gyro, sheet.accel
            gravity = STANDARD_GRAVITY
            gnss = self.datasheet.get("gnss") or {}
            base.update(
                # at least a tactical grade's: the mechanisation's own error (sensor_datasheet)
                accel_noise=max(a.noise_density, ACCEL_NOISE_FLOOR),
                gyro_noise=max(g.noise_density, GYRO_NOISE_FLOOR),
                # the accelerometers' scale factor and misalignment under gravity act as a bias
                accel_bias_std=float(np.sqrt(a.bias**2 + (gravity * a.scale_factor) ** 2
                                             + (gravity * a.misalignment) ** 2)),
                gyro_bias_std=g.bias, accel_bias_walk=a.bias_walk, gyro_bias_walk=g.bias_walk,
                gyro_scale_factor=float(np.hypot(g.scale_factor, g.misalignment)),
                accel_scale_factor=float(np.hypot(a.scale_factor, a.misalignment)),
                gyro_z_scale_factor_std=g.scale_factor,
                accel_z_misalignment_std=a.misalignment,
                pseudorange_correlation_time=float(gnss.get("carrier_smoothing") or 0.0),
                iono_scale_std=float(np.hypot(*_iono_residual(gnss))),
                range_bias_channels=RANGE_BIAS_CHANNELS)
        return {k: (cfg[k] if cfg[k] is not None else base[k]) for k in TUNED_KEYS}

    def _range_budget(self, gnss: dict) -> RangeBudget:
        """The pseudoranges' error split (``toolbox.range_budget``) of the receiver datasheet
        ``gnss``: the ionosphere's common and field fractions scaled so that together they
        make ``iono_scale_std`` (the datasheet's, or the config's number), the signal-in-space
        error (``SIS_ERROR_M`` without a datasheet), the inflation of
        ``pseudorange_correlation_time``."""
        common, field = _iono_residual(gnss)
        total = float(np.hypot(common, field))
        wanted = self.tuning["iono_scale_std"]
        common, field = ((common * wanted / total, field * wanted / total) if total > 0.0
                         else (wanted, 0.0))
        return replace(range_budget(gnss), iono_common=common, iono_field=field, sis=self._sis,
                       inflation=self._pr_inflation)

    # -- inputs --------------------------------------------------------------------------------
    def _imu_sample(self, t: float, row: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        """Body rate and specific force over the interval ending at t, and its length."""
        dt = t - self._t_imu if self._t_imu is not None else 0.0
        w, f = row[self._gyro_idx], row[self._accel_idx]
        if self._increments and dt > 0:
            w, f = w / dt, f / dt
        return w, f, dt

    def process_noise(self, dt: float, c_bn: np.ndarray) -> np.ndarray:
        """Discrete Q over ``dt`` (s) on the tangent/error state (white accelerometer and gyro
        noise, bias random walks, the receiver clock, the ionosphere state), with the gyro
        scale-factor and misalignment errors of the rates turned since the last call
        (``gyro_scale_factor`` s: PSD s^2 w^2 ``SCALE_FACTOR_TIME_S`` per body axis, rotated
        by the attitude C_b^n), and the accelerometers' on the specific force less the 1 g
        of a level car (under gravity alone the error is constant: a bias the states
        carry)."""
        tun = self.tuning
        q = np.zeros((self.n_states, self.n_states))
        q_accel = np.full(3, tun["accel_noise"] ** 2 * dt)
        q_accel += tun["accel_scale_factor"] ** 2 * SCALE_FACTOR_TIME_S * self._force_sq
        self._force_sq = np.zeros(3)
        q[3:6, 3:6] = (c_bn * q_accel) @ c_bn.T
        q_gyro = np.full(3, tun["gyro_noise"] ** 2 * dt)
        sf2 = np.full(3, tun["gyro_scale_factor"] ** 2)
        if self._sf is not None:  # the state carries the z axis's scale factor
            sf2[2] = max(sf2[2] - tun["gyro_z_scale_factor_std"] ** 2, 0.0)
        q_gyro += sf2 * SCALE_FACTOR_TIME_S * self._rate_sq
        self._rate_sq = np.zeros(3)
        q[6:9, 6:9] = (c_bn * q_gyro) @ c_bn.T
        q[9:12, 9:12] = np.eye(3) * tun["accel_bias_walk"] ** 2 * dt
        q[12:15, 12:15] = np.eye(3) * tun["gyro_bias_walk"] ** 2 * dt
        q[15:17, 15:17] = gnss_model.clock_noise(dt)
        if self._iono:
            iono = slice(IONO, IONO + self._n_iono)
            q[iono, iono] = np.eye(self._n_iono) * (
                1.0 - np.exp(-2.0 * dt / IONO_CORRELATION_TIME_S))
        if self._channels is not None:
            ch = slice(self._channels.first, self._channels.first + self._channels.n)
            q[ch, ch] = np.diag(self._channels.transition(dt)[1])
        return q

    def _measurement_noise(self, ep: gnss_model.RawEpoch) -> np.ndarray:
        """R of an epoch's pseudoranges and range rates: the receiver's reported variances
        (the config's when the stream has none), less what states carry: the ionosphere's
        residual shared by the satellites (``_iono_gains``) and each satellite's slowly
        varying error (``_range_bias_sigma``); the rest (tracking noise and multipath after the
        carrier smoothing) scaled by the correlated-noise inflation of
        ``pseudorange_correlation_time``."""
        cfg = self.config
        var = np.where(np.isfinite(ep.pseudorange_std), ep.pseudorange_std,
                       cfg["pseudorange_std"]) ** 2
        if self._iono:
            var = var - np.sum(self._iono_gains(ep) ** 2, axis=0)
        if self._channels is not None:
            var = var - self._range_bias_sigma(ep) ** 2
        var = np.maximum(var, PSEUDORANGE_STD_FLOOR**2)
        var = var * self._pr_inflation**2
        rr = np.where(np.isfinite(ep.range_rate_std), ep.range_rate_std, cfg["range_rate_std"])
        return np.diag(np.concatenate([var, rr**2]))

    def _budget_terms(self, ep: gnss_model.RawEpoch) -> tuple[np.ndarray, np.ndarray]:
        """The ionosphere states' coefficients (n_iono, m), m, on the epoch's pseudoranges
        and each satellite's own drive-long 1-sigma (``RangeBudget.sigmas``), computed once
        per set of pseudoranges (an update asks several times)."""
        key = ep.pseudorange.tobytes()
        if self._terms_key != key:
            shared, own, _ = self._budget.sigmas(ep, self.config["pseudorange_std"])
            self._terms = (shared[self._iono_used], own)
            self._terms_key = key
        return self._terms

    def _range_bias_sigma(self, ep: gnss_model.RawEpoch) -> np.ndarray:
        """Prior 1-sigma (m) of each satellite's range-error state: the signal-in-space error,
        the ionosphere field's remainder at its pierce point and the troposphere's residual
        (``RangeBudget.sigmas``)."""
        return self._budget_terms(ep)[1]

    def _iono_gains(self, ep: gnss_model.RawEpoch) -> np.ndarray:
        """Coefficients (n_iono, m), m, of the ionosphere states on the epoch's pseudoranges
        (``iono_field.residual_terms``)."""
        return self._budget_terms(ep)[0]

    def _channel_rows(self, ep: gnss_model.RawEpoch, t: float, p: np.ndarray
                      ) -> tuple[gnss_model.RawEpoch, np.ndarray, np.ndarray]:
        """The epoch's satellites that have a range-error channel, their state indices and
        which of them are new to their channel (reset in ``p``); without channels, the epoch
        and empty index arrays."""
        if self._channels is None:
            return ep, np.zeros(0, dtype=int), np.zeros(0, dtype=bool)
        idx, new = self._channels.assign(ep.sv, t, self._range_bias_sigma(ep), p)
        keep = idx >= 0
        return gnss_model.select(ep, keep), idx[keep], new[keep]

    def _nhc_noise(self, c_bn: np.ndarray, v: np.ndarray, rate: np.ndarray, f: np.ndarray,
                   pos: np.ndarray) -> np.ndarray:
        """R of the two NHC rows (module docstring) at the estimate's attitude C_b^n, NED
        velocity, compensated body rate and specific force (rad/s, m/s^2) and position."""
        if self._nhc_physics is None:
            sigma = self.config["nhc_std"]
            if sigma is None:
                sigma = constraints.NonholonomicNoise.floor
            return np.eye(2) * sigma**2
        pitch = dcm_to_euler(c_bn)[1]
        forward_accel = f[0] - float(normal_gravity(pos[0], pos[2])) * np.sin(pitch)
        lateral, vertical = self._nhc_physics.sigma(float((c_bn.T @ v)[0]), float(rate[2]),
                                                    float(forward_accel))
        return np.diag([lateral**2, vertical**2])

    def on_imu(self, t: float, row: np.ndarray) -> None:
        w, f, dt = self._imu_sample(t, row)
        if dt > 0:
            self.inertial_step(w, f, dt)
        self._w_prev, self._f_prev, self._t_imu = w, f, t
        if self.config["nhc"] and t >= self._next_nhc:
            self.update(t, None)
            self._next_nhc += 1.0 / self.config["nhc_rate"]

    def on_gnss_raw(self, t: float, block: np.ndarray) -> None:
        cols = self.columns["gnss_raw"]
        ep = gnss_model.raw_epoch(gnss_model.single_frequency(block, cols), cols)
        if not self._clock_started:
            self.start_clock(t, ep)
            self._clock_started = True
        self.update(t, ep if len(block) else None)
        # NHC alone if the next epoch (expected 1 / nhc_rate later) has not come within half
        # an interval of its time
        self._next_nhc = t + 1.5 / self.config["nhc_rate"]

    def _clock_from_residuals(self, ep: gnss_model.RawEpoch, pos_ecef: np.ndarray,
                              vel_ecef: np.ndarray) -> tuple[float, float]:
        pr, rate, _ = gnss_model.predict(ep.sat_pos, ep.sat_vel, pos_ecef, vel_ecef)
        return (float(np.median(ep.pseudorange - pr)), float(np.median(ep.range_rate - rate)))

    def _output(self, pos: np.ndarray, v: np.ndarray, q: np.ndarray, biases: np.ndarray,
                clock: np.ndarray, p: np.ndarray) -> np.ndarray:
        """A solution row; the attitude sigmas are those of the Euler angles
        (``nav_error.euler_covariance`` of the psi block) with the datasheet's accelerometer
        misalignment added (the filter finds the attitude of the accelerometer triad, whose
        misalignment to the car's body no measurement observes); the NIS of the last GNSS
        update is written once, NaN in the rows after it."""
        roll, pitch, yaw = quat_to_euler(q)
        std = np.sqrt(np.maximum(np.diag(p)[:6], 0.0))
        p_euler = nav_error.euler_covariance(roll, pitch, yaw, p[6:9, 6:9])
        std_att = np.sqrt(np.maximum(np.diag(p_euler), 0.0) + self._triad_misalignment**2)
        nis = (self.nis_gnss, self.nis_gnss_dof)
        self.nis_gnss = self.nis_gnss_dof = np.nan
        return np.concatenate([[np.degrees(pos[0]), np.degrees(pos[1]), pos[2], *v, roll, pitch,
                                yaw], std, std_att, biases, clock, nis])

    def _gate(self, nu: np.ndarray, s_diag: np.ndarray) -> np.ndarray:
        """Which of m pseudorange innovations ``nu`` (variances ``s_diag``) pass the chi-square
        gate of one degree of freedom at ``gate_probability`` (all when it is off): a
        non-line-of-sight delay of tens of metres fails it (Groves 2013, section 17.3.1).
        The variance is H P H^T plus the reported (not inflated) R: the correlated-noise
        inflation sets an epoch's weight in the long run, the innovation of one epoch is
        distributed with the error's own variance."""
        if self._gate_p is None:
            return np.ones(len(nu), dtype=bool)
        return gating.rows_passing(nu, s_diag, float(self._gate_p))

    def _record_nis(self, nu: np.ndarray, s: np.ndarray) -> None:
        """NIS nu^T S^-1 nu of the GNSS rows of an update and its dof (SPEC section 8)."""
        self.nis_gnss = gating.normalised_innovation_squared(nu, s)
        self.nis_gnss_dof = float(len(nu))

    def inertial_step(self, w: np.ndarray, f: np.ndarray, dt: float) -> None:
        """Buffer the IMU interval ending now (its start sample first); the filters integrate
        a buffer in one compiled call."""
        self._rate_sq += w**2 * dt
        self._force_sq += (f + np.array([0.0, 0.0, STANDARD_GRAVITY])) ** 2 * dt
        if not self._buf_dt:
            self._buf_w, self._buf_f = [self._w_prev], [self._f_prev]
        self._buf_w.append(w)
        self._buf_f.append(f)
        self._buf_dt.append(dt)

    def _take_buffer(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Body rates and specific forces at the m + 1 sample times (m + 1, 3) and the m
        interval lengths of the buffer, which is emptied."""
        out = np.array(self._buf_w), np.array(self._buf_f), np.array(self._buf_dt)
        self._buf_dt = []
        return out

    # -- filter-specific -----------------------------------------------------------------------

    def start_clock(self, t: float, ep: gnss_model.RawEpoch) -> None:
        raise NotImplementedError

    def update(self, t: float, ep: gnss_model.RawEpoch | None) -> None:
        raise NotImplementedError


def _iono_residual(receiver: dict) -> tuple[float, float]:
    """The broadcast ionosphere's relative residual from the receiver's datasheet
    (``simulator.datasheet.iono_residual_fractions``): its part common to the satellites and
    the 1-sigma of the field's (``KLOBUCHAR_RESIDUAL`` and 0 without a datasheet)."""
    if "iono_scale" not in receiver:
        return KLOBUCHAR_RESIDUAL, 0.0
    return iono_residual_fractions(receiver)


def _antenna_ecef(pos: np.ndarray, v: np.ndarray, c_bn: np.ndarray, lever: np.ndarray,
                  w_eb: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Antenna ECEF position and velocity of states (..., 3) and the NED-to-ECEF rotation."""
    lat, lon = pos[..., 0], pos[..., 1]
    off, voff = gnss_model.antenna_offset(c_bn, lever, w_eb)
    c_ne = ned_to_ecef_matrix(lat, lon)
    r = geodetic_to_ecef(lat, lon, pos[..., 2]) + np.einsum("...ij,...j->...i", c_ne, off)
    return r, np.einsum("...ij,...j->...i", c_ne, v + voff), c_ne


def _block_diagonal(blocks: list[np.ndarray]) -> np.ndarray:
    """The block-diagonal matrix of square blocks."""
    n = sum(len(b) for b in blocks)
    out = np.zeros((n, n))
    i = 0
    for b in blocks:
        out[i:i + len(b), i:i + len(b)] = b
        i += len(b)
    return out


def _earth_rate_body(c_bn: np.ndarray, lat: np.ndarray) -> np.ndarray:
    """C_n^b w_ie^n of states (..., 3, 3), (...)."""
    w_ie = earth_rate_ned(lat).reshape(np.shape(lat) + (3,))
    return np.einsum("...ji,...j->...i", c_bn, w_ie)


# ----------------------------------------------------------------------------------------------
# tc_ukf
# ----------------------------------------------------------------------------------------------
# the UKF's nominal state: one flat vector (k points: rows of a (k, 19) array)
POS, VEL, QUAT, BA, BG, CLOCK = (slice(0, 3), slice(3, 6), slice(6, 10), slice(10, 13),
                                 slice(13, 16), slice(16, 18))
N_NOMINAL = 18


@njit(cache=True)
def _propagate_points(x: np.ndarray, w: np.ndarray, f: np.ndarray, dt: np.ndarray,
                      sf_col: int, mz_col: int) -> None:
    """Integrate every point (rows of x, the ``TcUkf`` nominal layout) in place through the
    buffered IMU intervals: one RK4 step of Chan eqs. 1-3 per interval, bias-corrected rates at
    its start (row j of w, f), end (row j + 1) and their mean at its middle; cb' = d."""
    nav = np.empty(10)
    work = np.empty((5, 10))
    rates = np.empty((6, 3))  # w0, w_mid, w1, f0, f_mid, f1
    total = 0.0
    for j in range(dt.shape[0]):
        total += dt[j]
    for i in range(x.shape[0]):
        nav[:] = x[i, 0:10]
        for j in range(dt.shape[0]):
            for a in range(3):
                rates[0, a] = w[j, a] - x[i, 13 + a]
                rates[2, a] = w[j + 1, a] - x[i, 13 + a]
                if a == 2 and sf_col >= 0:  # the z gyro reads (1 + s) times the rate
                    rates[0, a] /= 1.0 + x[i, sf_col]
                    rates[2, a] /= 1.0 + x[i, sf_col]
                rates[1, a] = 0.5 * (rates[0, a] + rates[2, a])
                rates[3, a] = f[j, a] - x[i, 10 + a]
                rates[5, a] = f[j + 1, a] - x[i, 10 + a]
                if a == 2 and mz_col >= 0:  # the z accelerometer reads m . (f_x, f_y) more
                    rates[3, a] -= x[i, mz_col] * f[j, 0] + x[i, mz_col + 1] * f[j, 1]
                    rates[5, a] -= x[i, mz_col] * f[j + 1, 0] + x[i, mz_col + 1] * f[j + 1, 1]
                rates[4, a] = 0.5 * (rates[3, a] + rates[5, a])
            rk4_step(nav, rates[0], rates[1], rates[2], rates[3], rates[4], rates[5], dt[j], work)
        x[i, 0:10] = nav
        x[i, 16] += x[i, 17] * total


@njit(cache=True)
def _boxminus(xs: np.ndarray, ref: np.ndarray, rm: float, rt: float) -> np.ndarray:
    """Tangent vectors (k, 17) of the states xs (k, 18) around ``ref`` (18,): NED position
    displacement (m), velocity, the rotation vector of q_i * conj(q_ref) (the NED-frame attitude
    error of ``nav_error``), biases, clock."""
    k = xs.shape[0]
    out = np.empty((k, ref.shape[0] - 1))
    lat0, lon0, h0 = ref[0], ref[1], ref[2]
    a2, b2, c2, d2 = ref[6], -ref[7], -ref[8], -ref[9]
    for i in range(k):
        out[i, 0] = (xs[i, 0] - lat0) * (rm + h0)
        out[i, 1] = (xs[i, 1] - lon0) * (rt + h0) * np.cos(lat0)
        out[i, 2] = h0 - xs[i, 2]
        a1, b1, c1, d1 = xs[i, 6], xs[i, 7], xs[i, 8], xs[i, 9]
        w = a1 * a2 - b1 * b2 - c1 * c2 - d1 * d2
        x = a1 * b2 + b1 * a2 + c1 * d2 - d1 * c2
        y = a1 * c2 - b1 * d2 + c1 * a2 + d1 * b2
        z = a1 * d2 + b1 * c2 - c1 * b2 + d1 * a2
        if w < 0:
            w, x, y, z = -w, -x, -y, -z
        s = np.sqrt(x * x + y * y + z * z)
        scale = 2.0 * np.arctan2(s, w) / s if s > 1e-12 else 2.0
        out[i, 6], out[i, 7], out[i, 8] = x * scale, y * scale, z * scale
        for j in range(3):
            out[i, 3 + j] = xs[i, 3 + j] - ref[3 + j]
        for j in range(ref.shape[0] - 10):  # biases, clock (and the ionosphere state)
            out[i, 9 + j] = xs[i, 10 + j] - ref[10 + j]
    return out


def boxplus(x: np.ndarray, dx: np.ndarray) -> np.ndarray:
    """States (k, 18) of the nominal state ``x`` (18,) moved by tangent vectors dx (k, 17), or
    one state (18,) for one dx (17,) (the inverse of ``boxminus``; ``nav_error`` convention for
    position and attitude)."""
    if np.ndim(dx) == 1:
        return boxplus(x, dx[None, :])[0]
    d_lat, d_lon, d_h = geodetic_rates(x[0], x[2], dx[:, 0:3])
    out = np.empty((len(dx), len(x)))
    out[:, 0], out[:, 1], out[:, 2] = x[0] + d_lat, x[1] + d_lon, x[2] + d_h
    out[:, VEL] = x[VEL] + dx[:, 3:6]
    out[:, QUAT] = quat_multiply(rotvec_to_quat(dx[:, 6:9]), x[QUAT])
    out[:, 10:] = x[10:] + dx[:, 9:]
    return out


def boxminus(xs: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Tangent vectors (k, 17) of the states xs (k, 18) around the nominal state x (18,)."""
    rm, rt = radii_of_curvature(x[0])
    return _boxminus(np.ascontiguousarray(xs), x, float(rm), float(rt))


def _fx(points: np.ndarray, noise: None, w: np.ndarray, f: np.ndarray, dt: np.ndarray,
        inv_tau: np.ndarray, sf_col: int, mz_col: int) -> np.ndarray:
    """The UKF's transition of the whole point set (``SigmaPointFilter.propagate`` hook); the
    Gauss-Markov states after the nominal 18 decay with their 1 / correlation times
    ``inv_tau``."""
    points = np.ascontiguousarray(points)
    _propagate_points(points, w, f, dt, sf_col, mz_col)
    points[:, N_NOMINAL:] *= np.exp(-float(dt.sum()) * inv_tau)
    return points


class TcUkf(_TightlyCoupled):
    """Tightly coupled total-state UKF (Chan et al.; see the module docstring), on the shared
    sigma-point driver ``estimators.toolbox.ukf.SigmaPointFilter`` with this module's
    ``boxplus``/``boxminus`` hooks (17-dimensional tangent space, quaternion in the state).

    Config: ``nhc`` (bool), ``alpha``, ``beta`` (sigma-point spread and prior, 0.99 and 2),
    and the noise and prior keys of ``DEFAULTS``.
    """

    name = "tc_ukf"
    defaults = {**DEFAULTS, "alpha": 0.99, "beta": 2.0}
    config_help = {**CONFIG_HELP,
                   "alpha": ("", "spread of the sigma points (Wan and van der Merwe 2000)"),
                   "beta": ("", "prior-distribution weight, 2 for a Gaussian")}

    def setup(self) -> None:
        super().setup()
        init = self.initial
        x0 = np.zeros(N_NOMINAL + self.n_states - N_STATES)
        x0[POS], x0[VEL], x0[QUAT] = init.position, init.velocity, init.quaternion
        self.ukf = SigmaPointFilter(x0, self._p0, points="symmetric",
                                    alpha=self.config["alpha"], beta=self.config["beta"],
                                    boxplus=boxplus, boxminus=boxminus)
        self._propagated = False  # points moved since the covariance was last formed
        self._channel = np.zeros(0, dtype=int)  # range-error states of the epoch's satellites

    # -- propagation ---------------------------------------------------------------------------
    def _flush(self) -> None:
        """Move the sigma points (drawn at the last update) through the buffered IMU samples;
        the driver sets the mean (paper steps 2-3)."""
        if self._buf_dt:
            sf_col = -1 if self._sf is None else self._sf + 1  # nominal: tangent index + 1
            mz_col = -1 if self._mz is None else self._mz + 1
            self.ukf.propagate(_fx, *self._take_buffer(), self._inv_tau, sf_col, mz_col)
            self._propagated = True

    def _predict(self, t: float) -> None:
        """Covariance of the propagated points plus Q over the interval (paper step 3)."""
        self._flush()
        if self._propagated:
            self.ukf.covariance(self.process_noise(t - self._t_update,
                                                   quat_to_dcm(self.ukf.x[QUAT])))
            self._t_update = t
            self._propagated = False

    # -- measurements --------------------------------------------------------------------------
    def start_clock(self, t: float, ep: gnss_model.RawEpoch) -> None:
        if len(ep.sv) == 0:
            return
        self._predict(t)
        x = self.ukf.x
        c_bn = quat_to_dcm(x[QUAT])
        r, v, _ = _antenna_ecef(x[POS], x[VEL], c_bn, self._lever, np.zeros(3))
        x[CLOCK] = self._clock_from_residuals(ep, r, v)
        p = self.ukf.p
        p[15:17, :] = 0.0
        p[:, 15:17] = 0.0
        p[15:17, 15:17] = np.diag(np.square(CLOCK_INIT_STD))
        self.ukf.sigma = None  # drawn again from the new clock

    def _observe(self, pts: np.ndarray, ep: gnss_model.RawEpoch | None, nhc: bool
                 ) -> np.ndarray:
        """Predicted measurements of every point (paper step 4): pseudoranges, range rates
        (eqs. 7-8) and the NHC body y, z velocities; shape (k, m)."""
        c_bn = quat_to_dcm(pts[:, QUAT])
        parts = []
        if ep is not None:
            w_eb = self._w_prev[None, :] - pts[:, BG] - _earth_rate_body(c_bn, pts[:, 0])
            r, v, _ = _antenna_ecef(pts[:, POS], pts[:, VEL], c_bn, self._lever, w_eb)
            pr, rate, _ = gnss_model.predict(ep.sat_pos, ep.sat_vel, r, v, pts[:, 16],
                                             pts[:, 17])
            if self._iono:
                pr = pr + pts[:, N_NOMINAL:N_NOMINAL + self._n_iono] @ self._iono_gains(ep)
            if self._channels is not None:  # nominal index: tangent + 1 (the quaternion's 4)
                pr = pr + pts[:, self._channel + 1]
            parts += [pr, rate]
        if nhc:
            rate = self._w_prev[None, :] - pts[:, BG]
            v_b = constraints.body_velocity_points(c_bn, pts[:, VEL], rate, self._nhc_point)
            parts.append(v_b[:, 1:3])
        return np.concatenate(parts, axis=1)

    def update(self, t: float, ep: gnss_model.RawEpoch | None) -> None:
        nhc = bool(self.config["nhc"])
        if ep is None and not nhc:
            return
        self._predict(t)
        if ep is not None:
            ep, self._channel, new = self._channel_rows(ep, t, self.ukf.p)
            self.ukf.x[self._channel[new] + 1] = 0.0
            self.ukf.sigma = None  # drawn from the reset channels
            if len(ep.sv) == 0:
                ep = None
                if not nhc:
                    return
        if ep is not None and self._gate_p is not None:
            ep = self._gated(ep)
        z = [] if ep is None else [ep.pseudorange, ep.range_rate]
        if nhc:
            z.append(np.zeros(2))
        # the driver draws the points of N(x_bar, P^xx + Q), P^xy without R, P -= K P^yy K^T
        nu, p_yy = self.ukf.update(self._observe, np.concatenate(z),
                                   self.measurement_noise(ep, nhc), ep, nhc)
        if ep is not None:
            k = 2 * len(ep.sv)
            self._record_nis(nu[:k], p_yy[:k, :k])

    def _gated(self, ep: gnss_model.RawEpoch) -> gnss_model.RawEpoch:
        """The epoch without the pseudoranges that fail the gate (``_gate``), their
        innovations' variances from the sigma points drawn for the update (a satellite that
        fails keeps no row here, its range rate included)."""
        m = len(ep.sv)
        z_hat, p_zz = self.ukf.predict_measurement(self._observe, ep, False)
        s_pr = (np.diag(p_zz)[:m]
                + np.diag(self._measurement_noise(ep))[:m] / self._pr_inflation**2)
        keep = self._gate(ep.pseudorange - z_hat[:m], s_pr)
        self._channel = self._channel[keep]
        return gnss_model.select(ep, keep)

    def measurement_noise(self, ep: gnss_model.RawEpoch | None, nhc: bool) -> np.ndarray:
        """R of an update at the current state: the epoch's pseudoranges and range rates
        (``ep``, None for an NHC-only update), then the two NHC rows if ``nhc``."""
        blocks = [] if ep is None else [self._measurement_noise(ep)]
        if nhc:
            x = self.ukf.x
            blocks.append(self._nhc_noise(quat_to_dcm(x[QUAT]), x[VEL], self._w_prev - x[BG],
                                          self._f_prev - x[BA], x[POS]))
        return _block_diagonal(blocks)

    def solution(self, t: float) -> np.ndarray:
        """The mean of the propagated points; the std columns are those of the covariance
        formed at the last GPS or NHC update (the points' spread is formed only there, as in
        the paper's step 3)."""
        self._flush()
        x = self.ukf.x
        return self._output(x[POS], x[VEL], x[QUAT], x[10:16], x[CLOCK], self.ukf.p)


# ----------------------------------------------------------------------------------------------
# tc_ekf
# ----------------------------------------------------------------------------------------------
def error_dynamics(pos: np.ndarray, v: np.ndarray, c_bn: np.ndarray, f_b: np.ndarray
                   ) -> np.ndarray:
    """System matrix F (17 x 17) of the error state (Chan et al. eqs. 4-6 in the psi
    convention of ``nav_error``; see the module docstring)."""
    lat, h = pos[0], pos[2]
    rm, rt = radii_of_curvature(lat)
    sl, cl, tl = np.sin(lat), np.cos(lat), np.tan(lat)
    w_ie = OMEGA_E_RAD_S * np.array([cl, 0.0, -sl])
    w_en = np.array([v[1] / (rt + h), -v[0] / (rm + h), -v[1] * tl / (rt + h)])
    # d w_ie / d dr_n and d w_en / d dv (latitude and velocity errors)
    dwie_dr = np.zeros((3, 3))
    dwie_dr[:, 0] = OMEGA_E_RAD_S * np.array([-sl, 0.0, -cl]) / (rm + h)
    dwen_dv = np.array([[0.0, 1.0 / (rt + h), 0.0], [-1.0 / (rm + h), 0.0, 0.0],
                        [0.0, -tl / (rt + h), 0.0]])
    f = np.zeros((N_STATES, N_STATES))
    f[0:3, 3:6] = np.eye(3)  # eq. 4
    f_n = c_bn @ f_b
    f[3:6, 6:9] = -skew(f_n)  # eq. 5
    f[3:6, 9:12] = -c_bn
    f[3:6, 3:6] = -skew(2.0 * w_ie + w_en) + skew(v) @ dwen_dv
    f[3:6, 0:3] = skew(v) @ (2.0 * dwie_dr)
    f[6:9, 6:9] = -skew(w_ie + w_en)  # eq. 6
    f[6:9, 12:15] = -c_bn
    f[6:9, 0:3] = -dwie_dr
    f[6:9, 3:6] = -dwen_dv
    f[15, 16] = 1.0  # clock: cb' = d
    return f


@njit(cache=True)
def _strapdown_block(q: np.ndarray, v: np.ndarray, pos: np.ndarray, dth: np.ndarray,
                     dv: np.ndarray, dth_prev: np.ndarray, dv_prev: np.ndarray, dt: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``strapdown.propagate`` through a block of increments (m, 3), carrying the previous
    interval's increments for the coning and sculling terms; returns the final (q, v, pos)."""
    for j in range(dt.shape[0]):
        q, v, pos = propagate(q, v, pos, dth[j], dv[j], dth_prev, dv_prev, dt[j])
        dth_prev, dv_prev = dth[j], dv[j]
    return q, v, pos


class TcEkf(_TightlyCoupled):
    """Tightly coupled error-state EKF (Chan et al. eqs. 4-6; see the module docstring).

    Config: ``nhc`` (bool) and the noise and prior keys of ``DEFAULTS``.
    """

    name = "tc_ekf"

    def setup(self) -> None:
        super().setup()
        init = self.initial
        self._q = init.quaternion
        self._v = np.array(init.velocity, dtype=float)
        self._pos = np.array(init.position, dtype=float)
        self._ba = np.zeros(3)
        self._bg = np.zeros(3)
        self._clock = np.zeros(2)
        self._extra = np.zeros(self.n_states - N_STATES)  # ionosphere, range-error estimates
        self._err = ErrorState(self._p0)
        self._dth_prev = np.zeros(3)
        self._dv_prev = np.zeros(3)

    def inertial_step(self, w: np.ndarray, f: np.ndarray, dt: float) -> None:
        super().inertial_step(w, f, dt)
        if sum(self._buf_dt) >= 1.0 / COVARIANCE_RATE_HZ - 1e-9:
            self._flush()

    def _flush(self) -> None:
        """Strapdown through the buffered IMU intervals (bias-corrected increments: the
        trapezoid of the rates, or the increments themselves), then the covariance over them."""
        if not self._buf_dt:
            return
        w, f, dt = self._take_buffer()
        if self._increments:  # the intervals' mean rates
            w_c, f_c = w[1:] - self._bg, f[1:] - self._ba
        else:
            w_c = 0.5 * (w[1:] + w[:-1]) - self._bg
            f_c = 0.5 * (f[1:] + f[:-1]) - self._ba
        if self._sf is not None:  # the z gyro reads (1 + s) times the rate
            w_c[:, 2] /= 1.0 + self._extra[-1]
        if self._mz is not None:  # the z accelerometer reads m . (f_x, f_y) more
            f_c[:, 2] -= f_c[:, :2] @ self._extra[self._mz - N_STATES:self._mz - N_STATES + 2]
        dth, dv = w_c * dt[:, None], f_c * dt[:, None]
        self._q, self._v, self._pos = _strapdown_block(self._q, self._v, self._pos, dth, dv,
                                                       self._dth_prev, self._dv_prev, dt)
        self._dth_prev, self._dv_prev = dth[-1], dv[-1]
        total = float(dt.sum())
        self._clock[0] += self._clock[1] * total
        c_bn = quat_to_dcm(self._q)
        fm = np.zeros((self.n_states, self.n_states))
        fm[:N_STATES, :N_STATES] = error_dynamics(self._pos, self._v, c_bn,
                                                  dv.sum(axis=0) / total)
        extra = np.arange(N_STATES, self.n_states)  # first-order Gauss-Markov states
        fm[extra, extra] = -self._inv_tau
        if self._sf is not None:  # psi' = -C_b^n [0, 0, w_z] ds
            fm[6:9, self._sf] = -c_bn[:, 2] * float(w_c[:, 2] @ dt) / total
        if self._mz is not None:  # dv' = -C_b^n [0, 0, dm . (f_x, f_y)]
            f_xy = dt @ f_c[:, :2] / total
            fm[3:6, self._mz] = -c_bn[:, 2] * f_xy[0]
            fm[3:6, self._mz + 1] = -c_bn[:, 2] * f_xy[1]
        self._extra *= np.exp(-total * self._inv_tau)
        fm *= total
        phi = np.eye(self.n_states) + fm + 0.5 * fm @ fm
        self._err.predict(phi, self.process_noise(total, c_bn))

    def start_clock(self, t: float, ep: gnss_model.RawEpoch) -> None:
        if len(ep.sv) == 0:
            return
        r, v, _ = _antenna_ecef(self._pos, self._v, quat_to_dcm(self._q), self._lever,
                                np.zeros(3))
        self._clock = np.array(self._clock_from_residuals(ep, r, v))

    def update(self, t: float, ep: gnss_model.RawEpoch | None) -> None:
        self._flush()
        nhc = bool(self.config["nhc"])
        n = self.n_states
        dz, rows, noise = [], [], []
        c_bn = quat_to_dcm(self._q)
        if ep is not None:
            ep, channel, new = self._channel_rows(ep, t, self._err.p)
            self._extra[channel[new] - N_STATES] = 0.0
            if len(ep.sv) == 0:
                ep = None
        if ep is not None:
            w_eb = self._w_prev - self._bg - _earth_rate_body(c_bn, self._pos[0])
            r, v, c_ne = _antenna_ecef(self._pos, self._v, c_bn, self._lever, w_eb)
            pr, rate, los = gnss_model.predict(ep.sat_pos, ep.sat_vel, r, v, self._clock[0],
                                               self._clock[1])
            u = los @ c_ne  # lines of sight in NED, (m, 3)
            m = len(pr)
            h_pr = np.zeros((m, n))
            h_pr[:, 0:3] = -u
            h_pr[:, 6:9] = u @ skew(c_bn @ self._lever)
            h_pr[:, 15] = 1.0
            if self._iono:
                gains = self._iono_gains(ep)
                pr = pr + self._extra[:self._n_iono] @ gains
                h_pr[:, IONO:IONO + self._n_iono] = gains.T
            if self._channels is not None:
                pr = pr + self._extra[channel - N_STATES]
                h_pr[np.arange(m), channel] = 1.0
            h_rr = np.zeros((m, n))
            h_rr[:, 3:6] = -u
            h_rr[:, 16] = 1.0
            # the antenna's lever-arm velocity C_b^n (w_eb x l): psi turns it, the gyro-bias
            # error changes w (Groves eq. 14.110's lever-arm term, linearised)
            _, v_lever = gnss_model.antenna_offset(c_bn, self._lever, w_eb)
            h_rr[:, 6:9] = u @ skew(v_lever)
            h_rr[:, 12:15] = -u @ (c_bn @ skew(self._lever))
            r_gnss = self._measurement_noise(ep)
            dz_pr = pr - ep.pseudorange
            s_pr = (np.einsum("ij,jk,ik->i", h_pr, self._err.p, h_pr)
                    + np.diag(r_gnss)[:m] / self._pr_inflation**2)
            keep = np.concatenate([self._gate(dz_pr, s_pr), np.ones(m, dtype=bool)])
            dz.append(np.concatenate([dz_pr, rate - ep.range_rate])[keep])
            rows.append(np.vstack([h_pr, h_rr])[keep])
            noise.append(r_gnss[np.ix_(keep, keep)])
        if nhc:
            rate = self._w_prev - self._bg
            z_nhc, h_nhc = constraints.nonholonomic(self._q, self._v, n, rate,
                                                    self._nhc_point, slice(12, 15))
            dz.append(z_nhc)
            rows.append(h_nhc)
            noise.append(self._nhc_noise(c_bn, self._v, rate, self._f_prev - self._ba,
                                         self._pos))
        if not dz:
            return
        s = self._err.update(np.concatenate(dz), np.vstack(rows), _block_diagonal(noise))
        if ep is not None:  # closed loop: the error estimate was zero, the innovation is -dz
            k = len(dz[0])
            self._record_nis(dz[0], s[:k, :k])
        dx = self._err.feedback()
        self._q, self._v, self._pos = nav_error.correct(self._q, self._v, self._pos, dx[0:9])
        self._ba = self._ba - dx[9:12]
        self._bg = self._bg - dx[12:15]
        self._clock = self._clock - dx[15:17]
        self._extra -= dx[N_STATES:]

    def solution(self, t: float) -> np.ndarray:
        self._flush()
        return self._output(self._pos, self._v, self._q, np.concatenate([self._ba, self._bg]),
                            self._clock, self._err.p)


