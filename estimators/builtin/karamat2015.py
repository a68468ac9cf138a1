"""The 3D RISS/GPS integration of Karamat et al. 2015 (``riss3d_tc_ekf``).

Karamat, Atia, Noureldin, "An Enhanced Error Model for EKF-Based Tightly-Coupled Integration of
GPS and Land Vehicle's Motion Sensors", Sensors 15, 2015 (``seeds/002_...``; "the paper" below).

The reduced inertial sensor system (RISS) is one vertical gyro, a forward and a lateral
accelerometer and the odometer. Frames: the paper's local frame is ENU and its body frame is
x transversal (right), y forward, z up. landnav's body frame is FRD, so the inputs are mapped once,
on arrival: ``w_z = -gyro_z`` (the up-axis rate), ``f_y = accel_x`` (forward), ``f_x = accel_y``
(lateral, right). The paper's pitch (nose up) and roll (eq. 3; right side down positive) are the
FRD Euler pitch and roll, its azimuth A (clockwise from north) the yaw. The state's gyro bias
``b_z`` is on the up axis, so the solution's ``gyro_bias_z`` (FRD, down axis) is ``-b_z``.

Mechanisation (eqs. 1-9), once per odometer interval (the odometer speed of an interval is its
mean speed, so the distance is exact; the gyro and accelerometer samples of the interval are
averaged, the azimuth is integrated to the interval's middle for the velocity):

* eq. 1: dA/dt = -(w_z - b_z - omega_e sin(lat) - v_e tan(lat) / (R_N + h)). Our copy prints
  -(w_z - b_z) - omega_e sin(lat) - ..., which would double the Earth rate a level gyro at rest
  senses (it reads +omega_e sin(lat) about the up axis) instead of removing it; the bracketed
  form is the paper's own eq. 20 (its F71 and F74 are positive) and Groves eq. 5.44;
* eq. 2: p = asin((f_y - a_od - b_y) / g). The paper derives a_od "from the vehicle speed
  measurements" without saying how; differencing 10 Hz wheel-tick speeds gives metres per second
  squared of noise, so a_od is the difference of two consecutive ``tilt_window`` / 2 averages of
  the speed divided by their spacing, and f_y is averaged over the same ``tilt_window``, so both
  lag alike (by a quarter of the window);
* eq. 3: r = -asin((f_x - b_x + v_o (w_z - b_z)) / (g cos p));
* eqs. 4-6: v_e = v_o sin A cos p, v_n = v_o cos A cos p, v_u = v_o sin p;
* eqs. 7-9: position from v_n / (R_M + h), v_e / ((R_N + h) cos(lat)), v_u.

Error state (the ordering of the paper's H, eqs. 46 and 57; its F of eq. 42 orders the same
states differently): ``dN, dE, dh, dv_e, dv_n, dv_u, dA, da_od, db_z, dc_b, dc_d, dr, dp, db_x,
db_y, dv_o``. The position errors are carried as north and east metres (dN = (R_M + h) d lat,
dE = (R_N + h) cos(lat) d lon) instead of radians: the same states rescaled, so that the
covariance holds numbers of like size (``system_matrix`` gives F in the paper's radians and the
filter rescales it). Errors are estimate minus truth (``estimators.toolbox.kalman``), which flips
the sign of the paper's clock column in eq. 46. ``model: simplified`` is the earlier model the
paper improves on (its refs. 14, 28): the first eleven states, no tilt-error, accelerometer-bias
or speed-error states and no accelerometer update; pitch and roll are then eqs. 2-3 from the
plain averaged accelerometers.

System model: F of eqs. 13, 16, 17, 20, 24, 28, 31, 32 (``system_matrix``; the paper drops the
terms over (R + h)^2 and so does it), first-order Gauss-Markov tilt errors, accelerometer biases,
odometer-acceleration error and gyro bias (eqs. 33-38), random-walk clock drift (eqs. 40-41,
its noise from the TCXO Allan parameters of the shared ``gnss_model.clock_noise``), discretised
over each odometer interval with Phi = I + F dt + (F dt)^2 / 2 and Q_d = G Q G^T dt (the
Gauss-Markov diagonal in closed form, ``estimators.toolbox.gauss_markov``).

Velocity: the paper's error model treats the velocities as states driven by eqs. 22, 26 and 30
(the time derivatives of eqs. 4-6), while its mechanisation recomputes them from the odometer
(eqs. 4-6). Recomputing them each step throws the filter's velocity corrections away, and the
heading then diverged in the first sharp turn of every drive we tried (the filter explains the
persistent innovation with a huge azimuth correction). So the direction of the horizontal
velocity is propagated as eqs. 22 and 26 do (turned by dA/dt each step, corrected by the
filter) and its magnitude is the odometer's, v_o cos p (eqs. 4-5); v_u is eq. 6, so its error
after each step is eq. 6's, dv_u = sin p dv_o + v_o cos p dp, in the speed-error and
pitch-error states (enhanced model; eq. 31 is this relation's derivative without the pitch
term): carried as an independent state, each Doppler correction of v_u was thrown away by
eq. 6 at the next step but kept in the covariance, and the same innovation then pulled the
height through the v_u-h correlation at every epoch (4 m/s of height drift with three
satellites while the mechanised v_u was within 0.2 m/s of the truth). Integrating
eqs. 22/26 fully instead lets the a_od corrections accumulate into a speed error no measurement
anchors (1 m/s in a 60 s one-satellite window). The azimuth state is observed only through the
acceleration terms of eqs. 24/28 and the gyro bias and drifted up to 17 deg from the direction
of travel, so the direction of travel (the horizontal velocity's, against it while reversing)
gives F's sin A, cos A and the reported yaw above 1 m/s. A wheel at a standstill reads zero
whatever its scale error, so the speed is exactly zero while the odometer reads zero. After a
stop the velocity starts along the last direction of travel turned by the azimuth state since
(along the azimuth state alone, which drifts from it, a restart turned the heading by tens of
degrees), and a signed speed below zero (reversing) scales the body's forward axis, not the
last velocity, which already points backwards. The
odometer's own speed noise (``odometer_speed_noise``) is in the mechanised velocity the rates
are predicted from, so it enters the Doppler rows' R through the forward axis.

The point mechanised: eqs. 4-6 put the velocity along the body's forward axis, which holds on a
car at its rear axle (its wheels do not steer), not at an IMU ahead of it, whose velocity leaves
the body axis in every curve by the yaw rate times that distance (Rajamani 2012, eq. 2.29; 1.74 m
on the automotive preset, 3 deg in a 30 m curve). So the mechanised position and velocity are the
rear axle's (the datasheet's ``vehicle.rear_axle``, ``toolbox.installation``; ``nhc_point: imu``
or a rigid body: the IMU itself), and the IMU's, which the GNSS measurements are predicted from
and the solution reports, add the lever arm: C(A) r and C(A) (w x r) with the body heading A and
the up-axis rate. The lever arm's dependence on the heading error (1.74 m times it, centimetres)
is left out of H. The paper does not say where its RISS was installed.

Measurements: pseudoranges and pseudorange rates (eqs. 45-49; ``coupling: tight``), or the
receiver's 3-D fixes (position and velocity; ``coupling: loose``; a loosely coupled filter has
nothing while fewer than four satellites are seen, as the paper's LC comparisons assume), and the
accelerometer update (eqs. 50-58; ``model: enhanced``) once a second. Closed loop: after each
update the estimated errors are removed from the navigation state and sensor-error estimates.
The Gauss-Markov tilt and odometer-acceleration corrections decay as their models do.

``frozen_states`` (an ablation, empty by default) holds named states of the enhanced model at
zero: no initial uncertainty, no process noise and no row of F (eq. 32 couples the speed error to
a_od), so no update moves them; with ``bx, by`` the
enhanced model runs without its accelerometer-bias states, which the reproduction uses to
attribute the enhanced model's gain to the states that give it (docs/reproduction_karamat2015.md).

The Gauss-Markov parameters are images lost from our copy of the paper; chosen here from the
IMU300CC values of its Table 1 (``GM_PARAMETERS``; docs/reproduction_karamat2015.md). That is
``tuning: paper``, which the reproduction (``simulator/reproduce/karamat2015.py``) names so that
its figures do not move. ``tuning: datasheet`` (the default) takes what a user knows of the
dataset's sensors (``toolbox.sensor_datasheet``): the gyro and accelerometer biases are random
constants with their turn-on biases as prior (the accelerometers' with scale factor and
misalignment under 1 g) plus the datasheet's bias walk (a Gauss-Markov bias of 1 h pulled
the estimate towards zero while its variance shrank), a zero-rate update while the wheels
stand still (``zero_rate_update``: the gyro's mean rate is its bias plus the Earth rate's up
component, with the gyro's white noise; not in the paper), the azimuth's white noise the
gyro's noise density plus its scale factor and misalignment times the turn rate over
``SCALE_FACTOR_TIME_S``; the broadcast ionosphere's residual shared by the satellites as
four Gauss-Markov states of 30 min (its part common to them, its field's value and north and
east gradient at the zenith pierce point; each pseudorange's row their coefficients,
``toolbox.range_budget``, as ``fgo_tc`` carries them: as white R it held an error the
position does not get), the pseudoranges' R the rest of the reported variance scaled by the
correlated-noise inflation of the receiver's carrier smoothing
(``gnss_model.correlated_noise_inflation``), and a chi-square gate (1 dof, 0.999,
``gate_probability``) against H P H^T plus that uninflated rest, which drops the NLOS ranges
of a canyon; after the gate each pseudorange's expected reflected-signal (NLOS) delay, from
the probability its C/N0 deficit announces, is taken off and its variance added to R
(``gnss_model.nlos_delay``, as ``fgo_tc``; the reflected ranges that pass the gate, all
delayed, sank the height and clock together: the SUMO canyon's height 10 -> 2.0 over seeds
1-3; with a zero-mean NLOS share in the gate too it passed more reflected ranges), the range
rates'
with the rear axle's sideways motion that eqs. 4-5 leave out (the tyres' slip in a turn,
``toolbox.constraints.NonholonomicNoise``, along the body's right axis: in the sharp junction
turns of a SUMO city, 60 deg/s at 5 m/s, the rear axle moves up to 6 deg off the heading, and
the Doppler rows, taken as exact about it, turned the velocity's direction by 2-4 deg after
each turn), the gyro's white noise and scale factor on the velocity's direction as on the
azimuth (both turn by the same rate, eqs. 1, 22, 26), and the reported yaw's sigma that of
the velocity's direction it is (``_yaw_sigma``; the azimuth state's, reported before, is not
the heading's: at a stop the heading's error was 0.5-1.5 deg against an azimuth sigma of
0.12 deg). A gate that trusts the filter's covariance locks the filter out when its error
outgrows that covariance (after an outage: the altitude runaway and heading jump of a turn with
two satellites are not in Q): every returning range fails, only the Doppler rows pass, and these
keep P small while the position stays tens of metres off. So after ``REACQUIRE_EPOCHS`` (3)
epochs in a row in which most ranges fail (NLOS strikes satellites one by one, a wrong
prediction all of them), the position and clock-bias variances grow by what makes the median
range one sigma (covariance matching, ``gating.matching_variance``) and the ranges are gated
again: the consistent ones pass, a range far beyond them stays out. ``nis_gnss`` and
``nis_gnss_dof`` give the NIS of each GNSS update (SPEC section
8). At a standstill the reported heading is the last direction of travel turned by the
azimuth state since (the azimuth state itself was reported before, tens of degrees off). No
velocity, roll or pitch sigma is written: the mechanisation recomputes the velocity from the
odometer and the tilt from the accelerometers at every step (eqs. 2-6), so the covariance of
the velocity and tilt states does not describe the reported values.

Public names
------------
RissTcEkf, system_matrix, riss_rates, STATES, GM_PARAMETERS.
"""

from __future__ import annotations

import math

import numpy as np

from estimators.base import Estimator
from estimators.toolbox import gating, gnss_model
from estimators.toolbox.constraints import NonholonomicNoise
from estimators.toolbox.datasheet import SCALE_FACTOR_TIME_S
from estimators.toolbox.gauss_markov import gauss_markov_discrete
from estimators.toolbox.installation import Installation
from estimators.toolbox.iono_field import SHARED_TERMS
from estimators.toolbox.kalman import ErrorState
from estimators.toolbox.range_budget import (
    CORRELATION_TIME_S,
    PSEUDORANGE_FLOOR_M,
    RangeBudget,
    range_budget,
)
from estimators.toolbox.sensor_datasheet import ImuDatasheet
from simulator.datasheet import Cn0Template, cn0_template
from simulator.earth import (
    OMEGA_E_RAD_S,
    geodetic_to_ecef,
    ned_to_ecef_matrix,
    normal_gravity,
    radii_of_curvature,
    wrap_angle,
)
from simulator.errors import InputError
from simulator.units import DEG, DEG_RT_H, MILLI_G

STATES = ("N", "E", "h", "ve", "vn", "vu", "A", "ao", "bz", "cb", "cd",
          "r", "p", "bx", "by", "vo")
_I = {name: i for i, name in enumerate(STATES)}
REACQUIRE_EPOCHS = 3  # epochs with most pseudoranges gated out before the covariance is matched
DEFAULT_WHEELBASE_M = 2.7  # a saloon's, where the datasheet gives none
SIMPLIFIED_STATES = 11  # the earlier model: position, velocity, azimuth, a_od, b_z, clock

# Gauss-Markov models (steady-state sigma, correlation time s) of the filter, chosen from the
# IMU300CC of the paper's Table 1: the gyro and accelerometer biases start at the Table 1
# turn-on values (P0) and wander as a slow Gauss-Markov process whose noise equals an in-run
# instability of 1 % (gyro) and 3 % (accelerometers) of them over 300 s; the tilt errors and
# the odometer-derived acceleration error are short-correlated (a few seconds of vehicle
# dynamics the accelerometer tilt of eqs. 2-3 cannot tell from gravity). The odometer-derived
# acceleration's error was measured on the scenario's ABS wheel speed (difference of 1 s means):
# std 0.04 m/s^2, correlated for less than 0.5 s, and its integral over 60 s only 0.014 m/s,
# so its correlation time is one odometer step; a 10 s one (first tried) let the filter believe
# the along-track velocity wanders by 1 m/s in 20 s, and single-satellite Doppler updates then
# pushed it there.
GM_PARAMETERS = {
    "bz": (0.02 * DEG * math.sqrt(3600.0 / 300.0), 3600.0),  # rad/s
    "bx": (1.0 * MILLI_G * math.sqrt(3600.0 / 300.0), 3600.0),  # m/s^2
    "by": (1.0 * MILLI_G * math.sqrt(3600.0 / 300.0), 3600.0),
    "ao": (0.04, 0.1),  # m/s^2: measured on the derived a_od (std 0.04, correlated < 0.5 s)
    "r": (1.0 * DEG, 10.0),  # rad
    "p": (1.0 * DEG, 10.0),
}
_P0_SIGMA = {"N": 3.0, "E": 3.0, "h": 5.0, "ve": 0.3, "vn": 0.3, "vu": 0.3, "A": 1.0 * DEG,
             "ao": 0.1, "bz": 2.0 * DEG,  # Table 1: gyro bias 2 deg/s (data sheet)
             "cb": 30.0, "cd": 3.0, "r": 1.0 * DEG, "p": 1.0 * DEG,
             "bx": 30.0 * MILLI_G, "by": 30.0 * MILLI_G,  # Table 1: accelerometer bias 30 mg
             "vo": 0.2}
# white-noise densities (per second) of the states without a Gauss-Markov model
# (m/s)^2/s: unmodelled motion; v_u = v_o sin p (eq. 6) takes the noise of the accelerometer
# pitch of eq. 2 directly (about 0.5 deg, 0.1 m/s at 14 m/s), which eq. 31 does not model
_Q_WHITE = {"ve": 1e-4, "vn": 1e-4, "vu": 0.05,
            "A": (2.25 * DEG_RT_H) ** 2,  # Table 1: gyro random walk 2.25 deg/sqrt(h)
            "vo": 1e-4}  # (m/s)^2/s


def system_matrix(lat: float, h: float, ve: float, vn: float, azimuth: float, pitch: float,
                  ao: float, wz_corrected: float, n_states: int = len(STATES)) -> np.ndarray:
    """The continuous error dynamics F of the paper, in its units (position errors d lat,
    d lon in rad, ordered ``d lat, d lon, dh, ...`` as ``STATES``).

    Parameters
    ----------
    lat : latitude, rad; h : height, m; ve, vn : east and north velocity, m/s;
    azimuth, pitch : rad; ao : odometer-derived acceleration, m/s^2;
    wz_corrected : the up-axis gyro rate minus its estimated bias, w_z - b_z, rad/s.
    n_states : 16 (enhanced) or 11 (simplified, the first eleven states).

    Entries (paper's F_ab in brackets, its state numbers): eq. 13 (F15), eq. 16 (F24, F21),
    eq. 17 (F36), eq. 20 (F79, F71, F74), eq. 24 (F48, F47, F45, F49, F41, F44), eq. 28 (F58,
    F57, F54, F59, F51), eq. 31 (F68), eq. 32 (F14,8), eqs. 33-38 and 40-41 (the Gauss-Markov
    and clock rows). With errors as estimate minus truth, eq. 20 reads dA' = +db_z + (omega_e
    cos(lat) + v_e sec^2(lat) / (R_N + h)) d lat + tan(lat) / (R_N + h) dv_e, as printed.
    """
    i = _I
    rm, rn = (float(x) for x in radii_of_curvature(lat))
    tan_lat, cos_lat = math.tan(lat), math.cos(lat)
    sec2 = 1.0 / (cos_lat * cos_lat)
    cos_p = math.cos(pitch)
    sin_a, cos_a = math.sin(azimuth), math.cos(azimuth)
    a_dot = -wz_corrected + OMEGA_E_RAD_S * math.sin(lat) + ve * tan_lat / (rn + h)
    da_dlat = OMEGA_E_RAD_S * cos_lat + ve * sec2 / (rn + h)  # d(A')/d lat
    da_dve = tan_lat / (rn + h)  # d(A')/d v_e
    f = np.zeros((n_states, n_states))
    f[i["N"], i["vn"]] = 1.0 / (rm + h)  # eq. 13
    f[i["E"], i["ve"]] = 1.0 / ((rn + h) * cos_lat)  # eq. 16
    f[i["E"], i["N"]] = ve * tan_lat / ((rn + h) * cos_lat)
    f[i["h"], i["vu"]] = 1.0  # eq. 17
    f[i["A"], i["bz"]] = 1.0  # eq. 20
    f[i["A"], i["N"]] = da_dlat
    f[i["A"], i["ve"]] = da_dve
    # eq. 24: v_e' = a_od sin A cos p + v_n A'
    f[i["ve"], i["ao"]] = sin_a * cos_p
    f[i["ve"], i["A"]] = ao * cos_a * cos_p
    f[i["ve"], i["vn"]] = a_dot
    f[i["ve"], i["bz"]] = vn
    f[i["ve"], i["N"]] = vn * da_dlat
    f[i["ve"], i["ve"]] = vn * da_dve
    # eq. 28: v_n' = a_od cos A cos p - v_e A'
    f[i["vn"], i["ao"]] = cos_a * cos_p
    f[i["vn"], i["A"]] = -ao * sin_a * cos_p
    f[i["vn"], i["ve"]] = -a_dot - ve * da_dve
    f[i["vn"], i["bz"]] = -ve
    f[i["vn"], i["N"]] = -ve * da_dlat
    f[i["vu"], i["ao"]] = math.sin(pitch)  # eq. 31
    f[i["cb"], i["cd"]] = 1.0  # eq. 40
    for name, (_, tau) in GM_PARAMETERS.items():  # eqs. 33-38
        if i[name] < n_states:
            f[i[name], i[name]] = -1.0 / tau
    if n_states > i["vo"]:
        f[i["vo"], i["ao"]] = 1.0  # eq. 32
    return f


def riss_rates(x: np.ndarray, wz: float) -> np.ndarray:
    """Time derivatives of the RISS quantities in the derivative form the paper linearises
    (eqs. 1, 7-9, 22, 26, 30, 32), for checking ``system_matrix`` by numerical differentiation.

    ``x`` holds ``lat (rad), lon (rad), h, ve, vn, vu, A, ao, bz, cb, cd, r, p, bx, by, vo``
    (the Gauss-Markov states enter as their mean dynamics -x / tau); ``wz`` is the up-axis gyro
    rate, rad/s.
    """
    lat, _, h, ve, vn, _, az, ao, bz, _, cd, _, p, _, _, _ = x
    rm, rn = (float(v) for v in radii_of_curvature(lat))
    a_dot = -(wz - bz) + OMEGA_E_RAD_S * math.sin(lat) + ve * math.tan(lat) / (rn + h)
    out = np.zeros(len(STATES))
    out[0] = vn / (rm + h)
    out[1] = ve / ((rn + h) * math.cos(lat))
    out[2] = x[5]
    out[3] = ao * math.sin(az) * math.cos(p) + vn * a_dot
    out[4] = ao * math.cos(az) * math.cos(p) - ve * a_dot
    out[5] = ao * math.sin(p)
    out[6] = a_dot
    out[9] = cd
    for name, (_, tau) in GM_PARAMETERS.items():
        out[_I[name]] = -x[_I[name]] / tau
    out[15] = ao
    return out


class RissTcEkf(Estimator):
    """3D RISS/GPS augmented error-state EKF (Karamat et al. 2015); see the module docstring."""

    name = "riss3d_tc_ekf"
    needs = ("imu", "odometer")
    uses = ("gnss_raw", "gnss_fix")
    paper = ("Karamat et al. 2015, Sensors 15: 3D RISS/GPS tightly coupled augmented EKF "
             "(eqs. 1-58)")
    # model: enhanced | simplified; coupling: tight | loose; tilt_window: s, the averaging of
    # eq. 2's accelerometer and odometer acceleration; accel_update_interval: s between the
    # accelerometer updates of eqs. 50-58
    # odometer_speed_noise: m/s, 1-sigma white noise of one odometer speed sample (a 48-tooth
    # ABS wheel at 10 Hz quantises the speed in steps of 0.43 m/s)
    # nhc_point: where the velocity lies along the body (eqs. 4-6): rear_axle (the datasheet's)
    # or imu
    # tuning: datasheet (P0, Q and R from the dataset's datasheet; module docstring) or paper
    # (the IMU300CC figures of Table 1, white R); gate_probability: the pseudoranges' chi-square
    # gate (None: 0.999 with the datasheet tuning, off with the paper's)
    defaults = {"model": "enhanced", "coupling": "tight", "tilt_window": 2.0,
                "accel_update_interval": 1.0, "odometer_speed_noise": 0.2,
                "nhc_point": "rear_axle", "tuning": "datasheet", "gate_probability": None,
                "zero_rate_update": None, "frozen_states": ()}
    config_help = {
        "model": ("", "enhanced (eqs. 1-58) or simplified, the earlier model"),
        "coupling": ("", "tight (pseudoranges and rates) or loose (position and velocity fixes)"),
        "tilt_window": ("s", "averaging of eq. 2's accelerometer and odometer acceleration"),
        "accel_update_interval": ("s", "time between the accelerometer updates of eqs. 50-58"),
        "odometer_speed_noise": ("m/s", "1-sigma white noise of one odometer speed sample"),
        "nhc_point": ("", "where the velocity lies along the body: rear_axle or imu"),
        "tuning": ("", "datasheet: noise from the manifest's datasheet (default); paper: the "
                       "reproduction's values"),
        "gate_probability": ("", "chi-square gate on each pseudorange (e.g. 0.999); none: "
                                 "the tuning's default"),
        "zero_rate_update": ("", "observe the gyro bias while the wheels stand still (none: on "
                                 "with the datasheet tuning, off with the paper's)"),
        "frozen_states": ("", "states of the enhanced model (r, p, bx, by, vo) held at zero: "
                              "no initial uncertainty and no process noise (an ablation)"),
    }
    output_columns = ("lat", "lon", "alt", "vn", "ve", "vd", "roll", "pitch", "yaw",
                      "std_n", "std_e", "std_d", "std_yaw",
                      "gyro_bias_z", "accel_bias_x", "accel_bias_y", "clock_bias", "clock_drift",
                      "nis_gnss", "nis_gnss_dof")

    def setup(self) -> None:
        cfg = self.config
        problems = []
        if cfg["model"] not in ("enhanced", "simplified"):
            problems.append(f"model must be enhanced or simplified, got {cfg['model']!r}")
        if cfg["coupling"] not in ("tight", "loose"):
            problems.append(f"coupling must be tight or loose, got {cfg['coupling']!r}")
        if cfg["nhc_point"] not in ("rear_axle", "imu"):
            problems.append(f"nhc_point must be rear_axle or imu, got {cfg['nhc_point']!r}")
        if cfg["tuning"] not in ("datasheet", "paper"):
            problems.append(f"tuning must be datasheet or paper, got {cfg['tuning']!r}")
        extra = STATES[SIMPLIFIED_STATES:]
        frozen = list(cfg["frozen_states"] or ())
        if any(name not in extra for name in frozen):
            problems.append(f"frozen_states must be among {', '.join(extra)}, got {frozen!r}")
        if problems:
            raise InputError("config of riss3d_tc_ekf: " + "; ".join(problems))
        p0_sigma, q_white, gm = self._tuning(cfg["tuning"])
        # the zero-rate update's noise: the gyro's white noise (the azimuth's, either tuning)
        zero_rate = cfg["zero_rate_update"]
        if zero_rate is None:
            zero_rate = cfg["tuning"] == "datasheet"
        self._zero_rate_psd = q_white["A"] if zero_rate else 0.0
        for name in frozen:  # without uncertainty, noise or coupling: never corrected
            p0_sigma[name], q_white[name] = 0.0, 0.0
            if name in gm:
                gm[name] = (0.0, gm[name][1])
        self._enhanced = cfg["model"] == "enhanced"
        self._tight = cfg["coupling"] == "tight"
        self._n_nav = len(STATES) if self._enhanced else SIMPLIFIED_STATES
        # the ionosphere's residual shared by an epoch's satellites: unit-variance states after
        # the navigation's (``toolbox.range_budget``; datasheet tuning, tight coupling)
        self._iono_used = (self._budget.shared_in_use()
                           if self._budget is not None and self._tight
                           else np.zeros(len(SHARED_TERMS), dtype=bool))
        self._n_iono = int(self._iono_used.sum())
        self._iono_x = np.zeros(self._n_iono)  # their estimates
        self._n = self._n_nav + self._n_iono
        # F's rows of the frozen states are zeroed: eq. 32 (dv_o' = da_od) would otherwise pass
        # the a_od uncertainty into a frozen speed error, which the updates then correct
        self._frozen = np.array([_I[name] for name in frozen if _I[name] < self._n], dtype=int)
        # dv_u in the pitch and speed errors (eq. 6 linearised) needs one of them; without
        # either (the earlier model, or both frozen) it is eq. 31's integrating state
        self._vu_eq6 = self._enhanced and not {"p", "vo"} <= set(frozen)
        init = self.initial
        self._lat, self._lon, self._h = (float(v) for v in init.position)
        vn0, ve0, vd0 = (float(v) for v in init.velocity)
        self._roll, self._pitch, self._az = (float(v) for v in init.attitude)
        self._ve, self._vn, self._vu = ve0, vn0, -vd0
        self._vo = math.hypot(math.hypot(vn0, ve0), vd0)
        # sensor-error estimates (paper axes) and the decaying Gauss-Markov corrections
        self._bz = self._bx = self._by = 0.0
        self._c_ao = self._c_r = self._c_p = self._c_vo = 0.0
        self._cb = self._cd = 0.0
        self._clock_ready = False
        # the IMU from the mechanised point (body FRD, m): the rear axle's lever arm reversed
        rear = Installation.from_datasheet(self.datasheet).rear_axle
        self._arm = -rear if rear is not None and cfg["nhc_point"] == "rear_axle" else None
        self._slip = NonholonomicNoise(Installation.from_datasheet(self.datasheet).wheelbase
                                       or DEFAULT_WHEELBASE_M)
        self._wz = 0.0  # mean up-axis rate of the last interval, rad/s
        self._heading_offset = 0.0  # direction of travel minus azimuth state, while moving
        d_e, d_n, _, _ = self._arm_offset()
        self._lat, self._lon = self._moved(-d_n, -d_e)  # the rear axle at the start (at rest)
        self._filter = ErrorState(np.diag([p0_sigma[s] ** 2 for s in STATES[:self._n_nav]]
                                          + [1.0] * self._n_iono))
        # the reported yaw's variance at the last moving row and the azimuth state's then
        self._stop_heading_var = self._stop_az_var = float(self._filter.p[_I["A"], _I["A"]])
        self._q_white = np.array([q_white.get(s, 0.0) for s in STATES[:self._n_nav]]
                                 + [0.0] * self._n_iono)
        self._gm = [(_I[s], sig, tau) for s, (sig, tau) in gm.items() if _I[s] < self._n_nav]
        self._gm += [(self._n_nav + j, 1.0, CORRELATION_TIME_S)
                     for j in range(self._n_iono)]
        self._tau = {s: tau for s, (_, tau) in gm.items()}  # s; infinite: a random walk
        self.nis_gnss = self.nis_gnss_dof = math.nan
        self._rejecting = 0  # GNSS epochs in a row in which the gate rejected most ranges
        self._gm_index = np.array([g[0] for g in self._gm])
        self._noise_cache: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        # sums over the IMU samples of the current odometer interval
        c = self.columns["imu"]
        self._col_gz, self._col_fx, self._col_fy = c["gyro_z"], c["accel_x"], c["accel_y"]
        self._increments = self.imu_output == "increment"
        self._t_imu = init.t
        self._sum_wz = self._sum_ffwd = self._sum_flat = self._sum_dt = 0.0
        self._n_imu = 0
        self._col_speed = self.columns["odometer"]["speed"]
        self._t_odo = init.t
        self._t = init.t  # time of the navigation state
        self._half = 0  # odometer intervals in half a tilt window, set at the first interval
        self._speeds: list[float] = []
        self._ffwd: list[float] = []
        self._ao = 0.0
        self._t_accel_update = init.t
        if "gnss_raw" in self.columns:
            self._col_pr = self.columns["gnss_raw"]["pseudorange"]
        if "gnss_fix" in self.columns:
            g = self.columns["gnss_fix"]
            self._fix_cols = [g[k] for k in ("lat", "lon", "alt", "vn", "ve", "vd", "fix")]

    def _tuning(self, tuning: str) -> tuple[dict, dict, dict]:
        """P0 sigmas, white densities and Gauss-Markov models of ``tuning`` (``paper``: the
        module's Table 1 figures; ``datasheet``: the dataset's IMU and receiver datasheet,
        module docstring; the paper's when the dataset has none)."""
        p0, q_white, gm = dict(_P0_SIGMA), dict(_Q_WHITE), dict(GM_PARAMETERS)
        self._pr_inflation, self._gate_p = 1.0, self.config["gate_probability"]
        self._sf_psd = 0.0  # (rad/s)^2 s per (rad/s)^2 of turn rate: the gyro scale factor's
        sheet = ImuDatasheet.from_datasheet(self.datasheet)
        self._sheet_tuning = tuning == "datasheet" and sheet is not None
        self._cn0_template: Cn0Template | None = None
        self._budget: RangeBudget | None = None
        if not self._sheet_tuning:
            return p0, q_white, gm
        g, a = sheet.gyro, sheet.accel
        gravity = 9.80665
        accel_bias = math.sqrt(a.bias**2 + (gravity * a.scale_factor) ** 2
                               + (gravity * a.misalignment) ** 2)
        p0.update(bz=g.bias, bx=accel_bias, by=accel_bias)
        q_white["A"] = g.noise_density**2
        self._sf_psd = (g.scale_factor**2 + g.misalignment**2) * SCALE_FACTOR_TIME_S
        # a random constant (the turn-on bias, P0) plus the datasheet's walk: an infinite
        # correlation time, whose "sigma" is the walk's density (``_noise``). A Gauss-Markov
        # bias of 1 h pulled the estimate of a 2.5 deg/s turn-on bias towards zero by 0.0007
        # deg/s each second while its variance shrank as the model's steady state says
        # (0.18 deg/s off at 0.002 deg/s sigma after 480 s on the Crossbow unit)
        for name, walk in (("bz", g.bias_walk), ("bx", a.bias_walk), ("by", a.bias_walk)):
            gm[name] = (walk, math.inf)
        receiver = self.datasheet.get("gnss") or {}
        self._cn0_template = cn0_template(receiver)
        self._budget = range_budget(receiver, 1.0)
        self._pr_inflation = self._budget.inflation
        if self._gate_p is None:
            self._gate_p = 0.999
        return p0, q_white, gm

    # --- inputs -----------------------------------------------------------------------------
    def on_imu(self, t: float, row: np.ndarray) -> None:
        dt = t - self._t_imu
        if dt <= 0.0:
            return
        self._t_imu = t
        if self._increments:
            self._sum_wz -= row[self._col_gz]
            self._sum_ffwd += row[self._col_fx]
            self._sum_flat += row[self._col_fy]
        else:
            self._sum_wz -= row[self._col_gz] * dt
            self._sum_ffwd += row[self._col_fx] * dt
            self._sum_flat += row[self._col_fy] * dt
        self._sum_dt += dt

    def on_odometer(self, t: float, row: np.ndarray) -> None:
        speed = float(row[self._col_speed])
        self._mechanise(t, speed)

    def on_gnss_raw(self, t: float, rows: np.ndarray) -> None:
        if not self._tight:
            return
        self._catch_up(t)
        rows = rows[np.isfinite(rows[:, self._col_pr])]
        if len(rows) == 0:
            return
        self._update_ranges(gnss_model.raw_epoch(gnss_model.single_frequency(
            rows, self.columns["gnss_raw"]), self.columns["gnss_raw"]))

    def on_gnss_fix(self, t: float, row: np.ndarray) -> None:
        if self._tight:
            return
        lat, lon, alt, vn, ve, vd, fix = (row[k] for k in self._fix_cols)
        if fix < 2 or not math.isfinite(lat):  # 3-D fixes only: four satellites or more
            return
        self._catch_up(t)
        rm, rn = (float(v) for v in radii_of_curvature(self._lat))
        lat_i, lon_i, ve_i, vn_i = self._imu()
        dz = np.array([(lat_i - math.radians(lat)) * (rm + self._h),
                       (lon_i - math.radians(lon)) * (rn + self._h) * math.cos(self._lat),
                       self._h - alt, ve_i - ve, vn_i - vn, self._vu + vd])
        h = np.zeros((6, self._n))
        h[:, :6] = np.eye(6)
        r = np.diag([3.0**2, 3.0**2, 5.0**2, 0.1**2, 0.1**2, 0.15**2])
        forward = np.array([math.sin(self._az), math.cos(self._az), 0.0]) * math.cos(self._pitch)
        forward[2] = math.sin(self._pitch)  # east, north, up: the odometer noise (as on_raw)
        r[3:, 3:] += self.config["odometer_speed_noise"] ** 2 * np.outer(forward, forward)
        self._filter.update(dz, h, r)
        self._feedback()

    # --- mechanisation (eqs. 1-9) -------------------------------------------------------------
    def _catch_up(self, t: float) -> None:
        """Mechanise the IMU samples since the last odometer sample with the speed held."""
        if self._sum_dt > 0.0:
            self._mechanise(t, self._vo_raw_last(), count_speed=False)

    def _vo_raw_last(self) -> float:
        return self._speeds[-1] if self._speeds else self._vo + self._c_vo

    def _mechanise(self, t: float, speed: float, count_speed: bool = True) -> None:
        dt = t - self._t
        if dt <= 0.0:
            return
        n = self._sum_dt
        if n > 0.0:
            wz = self._sum_wz / n
            ffwd = self._sum_ffwd / n
            flat = self._sum_flat / n
        else:
            wz, ffwd, flat = self._wz, (self._ffwd[-1] if self._ffwd else 0.0), 0.0
        self._sum_wz = self._sum_ffwd = self._sum_flat = self._sum_dt = 0.0
        if count_speed:
            if not self._half:
                self._half = max(1, round(0.5 * self.config["tilt_window"] / (t - self._t_odo)))
                self._dt_odo = t - self._t_odo
            self._t_odo = t
            self._speeds.append(speed)
            self._ffwd.append(ffwd)
            keep = 2 * self._half
            if len(self._speeds) > keep:
                del self._speeds[0], self._ffwd[0]
        self._wz = wz
        lat, h = self._lat, self._h
        rm, rn = (float(v) for v in radii_of_curvature(lat))
        g = float(normal_gravity(lat, h))
        # odometer-derived acceleration and the matching accelerometer average (eq. 2)
        if len(self._speeds) == 2 * self._half:
            k = self._half
            ao_raw = (sum(self._speeds[k:]) - sum(self._speeds[:k])) / (k * k * self._dt_odo)
            ffwd_avg = sum(self._ffwd) / (2 * k)
        else:
            ao_raw, ffwd_avg = 0.0, ffwd
        decay = [math.exp(-dt / self._tau[s]) for s in ("ao", "r", "p", "bz", "bx", "by")]
        self._c_ao *= decay[0]
        self._c_r *= decay[1]
        self._c_p *= decay[2]
        self._bz *= decay[3]
        self._bx *= decay[4]
        self._by *= decay[5]
        ao = ao_raw - self._c_ao
        self._ao = ao
        # a wheel that does not turn reads zero whatever its scale error: at a standstill the
        # speed is exactly zero (the estimated speed error applies to a moving wheel only)
        vo = speed - self._c_vo if speed != 0.0 else 0.0
        backwards = self._vo < 0.0  # the last velocity points against the body's forward axis
        self._vo = vo
        wz_c = wz - self._bz
        pitch = _asin((ffwd_avg - ao - self._by) / g) - self._c_p  # eq. 2
        roll = -_asin((flat - self._bx + vo * wz_c) / (g * math.cos(pitch))) - self._c_r  # eq. 3
        a_dot = -wz_c + OMEGA_E_RAD_S * math.sin(lat) + self._ve * math.tan(lat) / (rn + h)  # 1
        az_mid = self._az + 0.5 * a_dot * dt
        self._az += a_dot * dt
        if abs(self._az) > math.pi:
            self._az = float(wrap_angle(self._az))
        cos_p = math.cos(pitch)
        # eqs. 4-5 with eqs. 22 and 26: the direction of the horizontal velocity turns with
        # the azimuth rate (the form the error model of eqs. 24 and 28 linearises, so that a
        # corrected direction persists), its magnitude is the odometer speed v_o cos p
        ve0, vn0 = self._ve, self._vn
        turn = a_dot * dt
        c_t, s_t = math.cos(turn), math.sin(turn)
        ue, un = ve0 * c_t + vn0 * s_t, vn0 * c_t - ve0 * s_t
        if backwards:  # the forward axis, which the signed speed then scales (reversing)
            ue, un = -ue, -un
        norm = math.hypot(ue, un)
        if norm < 0.1:  # too slow for a direction of its own: the last direction of travel
            # turned by the azimuth state since (``_heading``); the azimuth state alone drifts
            # from it by tens of degrees, which a restart after a stop turned into a jump of
            # the heading (57 deg in a garage)
            travel = az_mid + self._heading_offset
            ue, un, norm = math.sin(travel), math.cos(travel), 1.0
        self._ve = vo * cos_p * ue / norm
        self._vn = vo * cos_p * un / norm
        self._vu = vo * math.sin(pitch)  # eq. 6
        self._lat += 0.5 * (vn0 + self._vn) * dt / (rm + h)  # eq. 7
        self._lon += 0.5 * (ve0 + self._ve) * dt / ((rn + h) * math.cos(lat))  # eq. 8
        self._h += self._vu * dt  # eq. 9
        self._cb += self._cd * dt  # eq. 40
        self._pitch, self._roll = pitch, roll
        self._t = t
        self._predict(dt, rm, rn, wz_c)
        if self._zero_rate_psd and count_speed and speed == 0.0 and n > 0.0:
            self._update_zero_rate(wz, lat, n)
        if (self._enhanced and t - self._t_accel_update >= self.config["accel_update_interval"]
                - 1e-9):
            self._t_accel_update = t
            self._update_accelerometers(g, ffwd_avg, flat, wz)

    def _heading(self) -> float:
        """The direction of travel: the horizontal velocity's direction (against it while
        reversing) when moving; at a standstill the last one, turned since by the azimuth
        state (the azimuth state itself drifts from the heading by up to tens of degrees,
        module docstring)."""
        if self._moving():
            sign = 1.0 if self._vo > 0.0 else -1.0
            heading = math.atan2(sign * self._ve, sign * self._vn)
            self._heading_offset = float(wrap_angle(heading - self._az))
            return heading
        return float(wrap_angle(self._az + self._heading_offset))

    def _moving(self) -> bool:
        """Fast enough for the velocity's direction to be the heading."""
        return abs(self._vo) > 1.0 and math.hypot(self._ve, self._vn) > 0.5

    def _noise(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Gauss-Markov transition factors and the discrete process noise Q_d over ``dt``
        (cached: the odometer interval is nearly always the same)."""
        key = round(dt, 9)
        cached = self._noise_cache.get(key)
        if cached is None:
            q = self._q_white * dt
            sigma = np.array([g[1] for g in self._gm])
            tau = np.array([g[2] for g in self._gm])
            walk = np.isinf(tau)  # random walks: sigma is the density, unit/sqrt(s)
            phi_gm, q_gm = np.ones(len(tau)), sigma**2 * dt
            phi_gm[~walk], q_gm[~walk] = gauss_markov_discrete(tau[~walk], sigma[~walk], dt)
            q[self._gm_index] = q_gm
            q_d = np.diag(q)
            clock = slice(_I["cb"], _I["cd"] + 1)
            q_d[clock, clock] = gnss_model.clock_noise(dt)  # a TCXO (the shared clock model)
            cached = (phi_gm, q_d)
            if len(self._noise_cache) < 64:
                self._noise_cache[key] = cached
        return cached

    def _predict(self, dt: float, rm: float, rn: float, wz_c: float) -> None:
        f = np.zeros((self._n, self._n))
        f[:self._n_nav, :self._n_nav] = system_matrix(
            self._lat, self._h, self._ve, self._vn, self._heading(), self._pitch, self._ao,
            wz_c, self._n_nav)
        self._iono_x *= math.exp(-dt / CORRELATION_TIME_S)
        # rescale d lat, d lon (rad) to north and east metres: F_m = T F T^-1
        scale = np.ones(self._n)
        scale[0] = rm + self._h
        scale[1] = (rn + self._h) * math.cos(self._lat)
        f = f * scale[:, None] / scale[None, :]
        f[self._frozen] = 0.0
        fdt = f * dt
        phi = np.eye(self._n) + fdt + 0.5 * fdt @ fdt
        phi_gm, q_d = self._noise(dt)
        idx = self._gm_index
        phi[idx, idx] = phi_gm
        if self._sf_psd:
            q_d = q_d.copy()
            q_d[_I["A"], _I["A"]] += self._sf_psd * wz_c**2 * dt
        if self._sheet_tuning:
            q_d = self._direction_noise(q_d, dt, wz_c)
        if self._vu_eq6:
            phi, q_d = self._vertical_velocity_is_eq6(phi, q_d, dt)
        self._filter.predict(phi, q_d)

    def _direction_noise(self, q_d: np.ndarray, dt: float, wz_c: float) -> np.ndarray:
        """The horizontal velocity's direction turns by the same gyro rate as the azimuth
        (eqs. 22, 26), so the gyro's white noise and scale-factor error that the azimuth's
        white noise holds turn it too: Q gains q g g^T, g = (1 on A, v_n on v_e, -v_e on v_n)
        (F's b_z column for eqs. 24, 28), less the azimuth's own share already on the
        diagonal."""
        q = (self._q_white[_I["A"]] + self._sf_psd * wz_c**2) * dt
        g = np.zeros(self._n)
        g[_I["A"]], g[_I["ve"]], g[_I["vn"]] = 1.0, self._vn, -self._ve
        q_d = q_d + q * np.outer(g, g)
        q_d[_I["A"], _I["A"]] -= q
        return q_d

    def _vertical_velocity_is_eq6(self, phi: np.ndarray, q_d: np.ndarray, dt: float
                                  ) -> tuple[np.ndarray, np.ndarray]:
        """The vertical-velocity error after a step is that of eq. 6, which recomputes v_u =
        v_o sin p from the corrected speed and pitch: dv_u = sin p dv_o + v_o cos p dp, with
        the white noise of the accelerometer pitch on top. Eq. 31 is this relation's time
        derivative without its pitch term; propagating dv_u as an independent state instead
        kept each Doppler correction of v_u in the covariance while eq. 6 threw it away, and
        the same innovation then pulled the height through the v_u-h correlation at every
        epoch (about 4 m/s of height drift with three satellites). Returns T phi, T Q T^T +
        the white noise, with T the identity whose v_u row is that relation."""
        i = _I
        t = np.eye(self._n)
        t[i["vu"], i["vu"]] = 0.0
        t[i["vu"], i["vo"]] = math.sin(self._pitch)
        t[i["vu"], i["p"]] = self._vo * math.cos(self._pitch)
        q_d = t @ q_d @ t.T
        q_d[i["vu"], i["vu"]] += self._q_white[i["vu"]] * dt
        return t @ phi, q_d

    # --- measurement updates ------------------------------------------------------------------
    def _update_zero_rate(self, wz: float, lat: float, interval_s: float) -> None:
        """A car whose wheels stand still does not turn: the mean up-axis rate of the interval
        is the gyro bias plus the Earth rate's up component (eq. 1 at rest, dA/dt = 0), with
        the gyro's white noise averaged over the interval (a zero-rate update; not in the
        paper, ``zero_rate_update``)."""
        h = np.zeros((1, self._n))
        h[0, _I["bz"]] = 1.0
        dz = np.array([self._bz + OMEGA_E_RAD_S * math.sin(lat) - wz])
        self._filter.update(dz, h, np.array([[self._zero_rate_psd / interval_s]]))
        self._feedback()

    def _update_accelerometers(self, g: float, ffwd: float, flat: float, wz: float) -> None:
        """Eqs. 50-57: f_x = -g sin r cos p - v_o (w_z - b_z) + b_x (eq. 51) and f_y = g sin p +
        a_od + b_y (eq. 54), linearised in r, p, b_z, v_o, b_x, a_od, b_y (eqs. 53, 56)."""
        i = _I
        r, p, vo = self._roll, self._pitch, self._vo
        wz_c = wz - self._bz
        fx_est = -g * math.sin(r) * math.cos(p) - vo * wz_c + self._bx
        fy_est = g * math.sin(p) + self._ao + self._by
        h = np.zeros((2, self._n))
        h[0, i["r"]] = -g * math.cos(r) * math.cos(p)
        h[0, i["p"]] = g * math.sin(r) * math.sin(p)
        h[0, i["vo"]] = -wz_c
        h[0, i["bz"]] = vo
        h[0, i["bx"]] = 1.0
        h[1, i["p"]] = g * math.cos(p)
        h[1, i["ao"]] = 1.0
        h[1, i["by"]] = 1.0
        dz = np.array([fx_est - flat, fy_est - ffwd])
        sigma = 0.05  # m/s^2: accelerometer noise and vibration over an odometer interval
        self._filter.update(dz, h, np.eye(2) * sigma**2)
        self._feedback()

    def _update_ranges(self, epoch: gnss_model.RawEpoch) -> None:
        """Eqs. 45-49: dz = rho_RISS - rho_GPS and the same for the rates, predicted by the
        shared model (``estimators.toolbox.gnss_model``: Sagnac, broadcast corrections), with
        H = [-los^T C_n^e, +1 for the clock] (eqs. 46-49 with errors as estimate minus truth)."""
        lat, lon, ve, vn = self._imu()
        pos = geodetic_to_ecef(lat, lon, self._h).reshape(3)
        c_ne = ned_to_ecef_matrix(lat, lon)
        v_ecef = c_ne @ np.array([vn, ve, -self._vu])
        if not self._clock_ready:
            rho0, rate0, _ = gnss_model.predict(epoch.sat_pos, epoch.sat_vel, pos, v_ecef)
            self._cb = float(np.median(epoch.pseudorange - rho0))
            self._cd = float(np.median(epoch.range_rate - rate0))
            self._clock_ready = True
        rho, rate, los = gnss_model.predict(epoch.sat_pos, epoch.sat_vel, pos, v_ecef,
                                            self._cb, self._cd)
        jac = gnss_model.los_jacobians(los)  # [-los (ECEF), 1]
        d_ned = jac[:, :3] @ c_ne  # d rho / d (north, east, down) of the antenna
        m = len(rho)
        h = np.zeros((2 * m, self._n))
        h[:m, _I["N"]] = d_ned[:, 0]
        h[:m, _I["E"]] = d_ned[:, 1]
        h[:m, _I["h"]] = -d_ned[:, 2]  # d(down) = -dh
        h[:m, _I["cb"]] = 1.0
        h[m:, _I["ve"]] = d_ned[:, 1]
        h[m:, _I["vn"]] = d_ned[:, 0]
        h[m:, _I["vu"]] = -d_ned[:, 2]
        h[m:, _I["cd"]] = 1.0
        var_pr = np.where(np.isfinite(epoch.pseudorange_std), epoch.pseudorange_std**2, 9.0)
        if self._n_iono:  # the shared ionosphere: states, out of R
            gains = self._budget.sigmas(epoch)[0][self._iono_used]
            rho = rho + self._iono_x @ gains
            h[:m, self._n_nav:] = gains.T
            var_pr = np.maximum(var_pr - np.sum(gains**2, axis=0), PSEUDORANGE_FLOOR_M**2)
        dz = np.concatenate([rho - epoch.pseudorange, rate - epoch.range_rate])
        var_rate = np.where(np.isfinite(epoch.range_rate_std), epoch.range_rate_std**2, 0.01)
        nlos_mean, var_nlos = self._nlos_delay(epoch)
        r = np.diag(np.concatenate([var_pr * self._pr_inflation**2 + var_nlos, var_rate]))
        # the mechanised velocity carries the white noise of the last odometer speed: it enters
        # every predicted rate through the forward axis, so R gains sigma^2 g g^T
        forward = np.array([math.cos(self._az), math.sin(self._az), 0.0]) * math.cos(self._pitch)
        forward[2] = -math.sin(self._pitch)
        g = d_ned @ forward
        r[m:, m:] += self.config["odometer_speed_noise"] ** 2 * np.outer(g, g)
        if self._sheet_tuning and self._vo != 0.0:
            r[m:, m:] += self._side_slip_variance(d_ned)
        keep = np.ones(2 * m, dtype=bool)
        if self._gate_p is not None:
            keep[:m] = self._gate_ranges(dz[:m], h[:m], var_pr)
        dz[:m] += nlos_mean  # the expected reflected delay off the pseudorange, after the gate
        s = self._filter.update(dz[keep], h[keep], r[np.ix_(keep, keep)])
        self.nis_gnss = gating.normalised_innovation_squared(dz[keep], s)
        self.nis_gnss_dof = float(keep.sum())
        self._feedback()

    def _nlos_delay(self, epoch: gnss_model.RawEpoch) -> tuple[np.ndarray, np.ndarray]:
        """Each pseudorange's expected reflected-signal (NLOS) delay and its variance, from
        the probability that its C/N0 deficit below the receiver's template announces
        (``gnss_model.nlos_delay``, the receiver's own fix-accuracy model of an extra path,
        as ``fgo_tc``; ``tuning: datasheet`` with a template, C/N0 and elevations; zeros
        otherwise). The delay is taken off after the gate, which tests the raw innovation
        against the reported variance: taken off before, a direct signal whose C/N0 faded
        fails the gate by the delay it does not have."""
        m = len(epoch.sv)
        if (self._cn0_template is None or epoch.cn0 is None or epoch.elevation is None):
            return np.zeros(m), np.zeros(m)
        return gnss_model.nlos_delay(epoch.cn0, epoch.elevation, self._cn0_template)

    def _side_slip_variance(self, d_ned: np.ndarray) -> np.ndarray:
        """The range rates' covariance from the rear axle's sideways motion, which eqs. 4-5
        (the velocity along the heading) leave out: the tyres' slip in a turn and the body's
        other motion (``toolbox.constraints.NonholonomicNoise``: 3.5 deg of slip at 5 m/s^2 of
        lateral acceleration), sigma^2 g g^T with g the rates' gradient along the body's right
        axis."""
        lateral, _ = self._slip.sigma(self._vo, self._wz - self._bz, self._ao)
        heading = self._heading()
        g = d_ned @ np.array([-math.sin(heading), math.cos(heading), 0.0])
        return lateral**2 * np.outer(g, g)

    def _gate_ranges(self, dz: np.ndarray, h: np.ndarray, var_pr: np.ndarray) -> np.ndarray:
        """The pseudoranges passing the chi-square gate, each against H P H^T + its reported
        variance; after ``REACQUIRE_EPOCHS`` epochs in a row in which most of them failed, the
        position and clock-bias variances first grow by what makes the median range one sigma
        (``gating.matching_variance``; each range's row has a unit line of sight and a 1 on the
        clock, so half of it on each of the four states): without it a filter that left an
        outage further off than its covariance says rejected every returning range for good."""
        s_pr = np.einsum("ij,jk,ik->i", h, self._filter.p, h) + var_pr
        passing = gating.rows_passing(dz, s_pr, self._gate_p)
        self._rejecting = self._rejecting + 1 if 2 * passing.sum() < len(dz) else 0
        if self._rejecting >= REACQUIRE_EPOCHS:
            self._rejecting = 0
            grow = 0.5 * gating.matching_variance(dz, s_pr)
            states = [_I["N"], _I["E"], _I["h"], _I["cb"]]
            self._filter.p[states, states] += grow
            s_pr = np.einsum("ij,jk,ik->i", h, self._filter.p, h) + var_pr
            passing = gating.rows_passing(dz, s_pr, self._gate_p)
        return passing

    def _feedback(self) -> None:
        """Closed loop: remove the estimated errors (estimate minus truth) from the state."""
        dx = self._filter.feedback()
        i = _I
        rm, rn = (float(v) for v in radii_of_curvature(self._lat))
        self._lat -= dx[i["N"]] / (rm + self._h)
        self._lon -= dx[i["E"]] / ((rn + self._h) * math.cos(self._lat))
        self._h -= dx[i["h"]]
        self._ve -= dx[i["ve"]]
        self._vn -= dx[i["vn"]]
        self._vu -= dx[i["vu"]]
        self._az = float(wrap_angle(self._az - dx[i["A"]]))  # at most once a second
        self._c_ao += dx[i["ao"]]
        self._ao -= dx[i["ao"]]
        self._bz -= dx[i["bz"]]
        self._cb -= dx[i["cb"]]
        self._cd -= dx[i["cd"]]
        self._iono_x -= dx[self._n_nav:]
        if self._enhanced:
            self._c_r += dx[i["r"]]
            self._roll -= dx[i["r"]]
            self._c_p += dx[i["p"]]
            self._pitch -= dx[i["p"]]
            self._bx -= dx[i["bx"]]
            self._by -= dx[i["by"]]
            self._c_vo += dx[i["vo"]]
            self._vo -= dx[i["vo"]]

    # --- the IMU from the mechanised point ------------------------------------------------------
    def _arm_offset(self) -> tuple[float, float, float, float]:
        """East and north offset (m) and velocity (m/s) of the IMU from the mechanised rear axle:
        C(A) r and C(A) (w x r) with the body heading A (the direction of travel) and the
        up-axis rate, w_down = -(w_z - b_z); zero without a lever arm."""
        if self._arm is None:
            return 0.0, 0.0, 0.0, 0.0
        a = self._heading()
        fwd, right = (math.sin(a), math.cos(a)), (math.cos(a), -math.sin(a))  # east, north
        dx, dy = float(self._arm[0]), float(self._arm[1])
        w_down = -(self._wz - self._bz)
        vx, vy = -w_down * dy, w_down * dx
        return (dx * fwd[0] + dy * right[0], dx * fwd[1] + dy * right[1],
                vx * fwd[0] + vy * right[0], vx * fwd[1] + vy * right[1])

    def _moved(self, north: float, east: float) -> tuple[float, float]:
        """Latitude and longitude (rad) of the mechanised point moved by north, east metres."""
        rm, rn = (float(v) for v in radii_of_curvature(self._lat))
        return (self._lat + north / (rm + self._h),
                self._lon + east / ((rn + self._h) * math.cos(self._lat)))

    def _imu(self) -> tuple[float, float, float, float]:
        """Latitude, longitude (rad), east and north velocity (m/s) of the IMU."""
        d_e, d_n, dv_e, dv_n = self._arm_offset()
        lat, lon = self._moved(d_n, d_e)
        return lat, lon, self._ve + dv_e, self._vn + dv_n

    # --- output -------------------------------------------------------------------------------
    def solution(self, t: float) -> list[float]:
        rm, rn = (float(v) for v in radii_of_curvature(self._lat))
        lead = t - self._t  # IMU samples not yet mechanised: the velocity is held
        lat_i, lon_i, ve_i, vn_i = self._imu()
        lat = lat_i + vn_i * lead / (rm + self._h)
        lon = lon_i + ve_i * lead / ((rn + self._h) * math.cos(self._lat))
        p = self._filter.p
        i = _I
        clock = (self._cb, self._cd) if self._clock_ready else (math.nan, math.nan)
        accel = (self._by, self._bx) if self._enhanced else (math.nan, math.nan)
        return [math.degrees(lat), math.degrees(lon), self._h + self._vu * lead,
                vn_i, ve_i, -self._vu, self._roll, self._pitch, self._heading(),
                math.sqrt(p[i["N"], i["N"]]), math.sqrt(p[i["E"], i["E"]]),
                math.sqrt(p[i["h"], i["h"]]), self._yaw_sigma(),
                -self._bz, accel[0], accel[1], *clock, *self._take_nis()]

    def _yaw_sigma(self) -> float:
        """1-sigma of the reported yaw (``_heading``). ``tuning: paper``: the azimuth state's.
        ``tuning: datasheet``: while moving, the horizontal velocity's direction's, from the
        velocity states (d heading = (v_n dv_e - v_e dv_n) / v^2); at a standstill, that of the
        last moving row plus what the azimuth state's variance grew since."""
        p = self._filter.p
        p_az = p[_I["A"], _I["A"]]
        if not self._sheet_tuning:
            return math.sqrt(p_az)
        if self._moving():
            v2 = self._ve**2 + self._vn**2
            j = np.array([self._vn, -self._ve]) / v2
            block = p[_I["ve"]:_I["vn"] + 1, _I["ve"]:_I["vn"] + 1]
            self._stop_heading_var = float(j @ block @ j)
            self._stop_az_var = p_az
        return math.sqrt(self._stop_heading_var + max(0.0, p_az - self._stop_az_var))

    def _take_nis(self) -> tuple[float, float]:
        """The NIS of the last GNSS update and its dof, once (NaN in the rows after it)."""
        out = (self.nis_gnss, self.nis_gnss_dof)
        self.nis_gnss = self.nis_gnss_dof = math.nan
        return out


def _asin(x: float) -> float:
    return math.asin(min(1.0, max(-1.0, x)))
