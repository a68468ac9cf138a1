"""``ins_lkf``: the linearised Kalman filter INS/GPS of Tan et al., "Land-vehicle MEMS INS/GPS
positioning during GPS signal blockage periods", VNU J. Sci., Math.-Phys. 23 (2007/2008).

What the paper gives and what is chosen here:

* Linearised KF, eqs. 1-5: x' = F x + G u, Phi = I + F dt (eq. 3), Q_k = Phi G Q G^T Phi^T dt
  (eq. 4), GPS position measurements with R = diag(sigma_lat^2, sigma_lon^2, sigma_h^2) (eq. 5).
  The KF runs every 0.5 s on 64 Hz IMU increments and 1 Hz GPS (section 5). Here the
  covariance is propagated at every batch of increments (at least 10 Hz, ``ins_filter``) with the
  second-order Phi and trapezoidal Q_d of ``ins_error.discretise``, the finer form of eqs. 3-4;
  the aiding updates of outages run every ``update_interval`` = 0.5 s.
* State: the paper prints eight states (three velocity errors, three gyro drifts, two attitude
  errors), but its GPS position measurement needs position errors and its heading aiding needs
  a heading error. A consistent model is used instead: the 15-state NED error model of
  ``toolbox.ins_error`` (position, velocity, three attitude errors, accelerometer and gyro
  biases).
* Closed loop while GPS aids, open loop during outages (section 5, "the closed loop KF is
  utilized when the GPS signal is available and the open loop KF is applied when GPS is
  outage"): an epoch without a fix opens the loop (``kalman.ErrorState.set_closed_loop``); the
  next fix closes it and feeds the open-loop estimate back before its own update.
  ``open_loop_outages: false`` stays closed through outages (not the paper's design; the
  default with ``tuning: datasheet``, below).
* Velocity constraint, eqs. 6-7 (``nhc``): zero lateral and vertical body velocity. Eq. 6 prints
  V_x^b = 0, which would stop the car: the lateral axis is y (V_y^b = 0, V_z^b = 0). Used
  during outages only (section 5: "utilizes the vehicle motion constraints and the
  magnetometer measurement during GPS outages"). Applied where it holds, at the rear axle from
  the datasheet's ``vehicle.rear_axle``, with the car's physics as its noise
  (``constraints.NonholonomicNoise``, as ``ins_odo_ekf``; the forward speed is the INS's, Tan's
  filter has no odometer); on a rigid body (no rear axle in the datasheet) at the IMU with
  1-sigma 0.1 m/s (chosen).
* GNSS antenna lever arm (``gnss.antenna_lever_arm``) in the position update, and the IMU's
  ``mounting`` rotated out of the samples (``toolbox.installation``).
* Height constraint, section 3.2 (``height_constraint``): the height stays at the last
  GPS-aided height through the outage, 1-sigma 2 m (the paper asks for "a realistic measurement
  uncertainty" and prints none).
* Heading aiding, section 4 and eq. 8 (``mag_heading``): a magnetometer heading during outages,
  1-sigma 2 deg (chosen). The paper does not say how the magnetometer was calibrated or where
  the declination came from: it is calibrated against GPS (``aiding.MagneticHeading``: the
  Earth field in NED and the hard iron learnt from the GPS-aided attitude while driving, which
  calibrates the declination in). Section 4 also names the GPS heading for in-motion alignment:
  the GPS course is used as a heading measurement while GPS aids and the car moves faster than
  ``course_speed`` (1-sigma 2 deg).
* The 60 s standstill at the start ("in order to estimate the determined errors", section 5)
  is used as it is known from the protocol: zero-velocity and zero-angular-rate updates during
  the first ``standstill`` seconds, none if the initial state moves faster than 0.5 m/s and
  ended early by a GPS speed over 0.5 m/s (so a drive that starts moving sooner is not held
  still).
* Noise (Tan prints no Q): the BP3010's ADXRS300 gyro and ADXL210E accelerometer data-sheet
  densities (0.1 deg/s/sqrt(Hz), 0.2 mg/sqrt(Hz)); the initial bias uncertainties are the
  ``bp3010`` preset's (0.5 deg/s, 10 mg), in-run Gauss-Markov biases of 0.01 deg/s and 1 mg with
  300 s correlation time (chosen).
* ``tuning`` (default ``datasheet``): where the noise comes from. ``paper``: the values above,
  which the reproduction (``simulator.reproduce.tan2008``) asks for so that its figures stay
  put. ``datasheet``: from what a user knows of the sensors (``toolbox.datasheet``, as
  ``ins_odo_ekf``): the IMU's noise densities, in-run bias instability and turn-on bias range
  (P0), its scale factors as bias process noise; the fix's error as three Gauss-Markov states
  of the drive-long part of the fix's reported accuracy (30 min; unit states whose gain at
  each fix is ``toolbox.datasheet.FixSplit``'s: per unit DOP the smallest report so far
  less the budget's smoothed part, capped at the budget's correlated part: on open sky the
  budget alone was above the report, and the filter too cautious horizontally) plus the
  white equivalent of its smoothed noise, behind a chi-square gate (0.999), and the fix's
  velocity (Tan uses positions only, and with the white equivalent of the smoothed position
  noise alone the velocity's sigma was ten times its error). What the fix reports of its
  own accuracy (``std_*`` of ``gnss_fix``, the receiver's least squares with its reflected
  signals; ``toolbox.datasheet.FixAccuracy``) is taken as ``ins_odo_ekf`` takes it: the
  position's 1-sigma beyond its drive-long and smoothed parts (reflected signals) as three unit
  NLOS states after the fix's (``datasheet.fix_position_rows``), the velocity's 1-sigma as its
  noise. In a street canyon the reflected fixes sink by 20-50 m at a VDOP of 1.5-2.9, reporting
  20-37 m for it; with the DOPs' 3 m the filter followed them down under a 3.5 m sigma and held
  the offset in its 30-minute fix-error states (the unseen canyon's height (error / sigma)^2 9.6
  and 13.5 on seeds 1 and 2, 0.59 and 1.1 with the report; ``urban_canyon``'s height 8.6 and 14,
  vertical velocity 18 and 18, then 0.19 and 0.60, 1.4 and 0.41). A fix
  without the columns has its velocity noise raised per axis to the innovations' scatter by
  covariance matching instead (``gating.FixNoiseMatching``: the reflected Doppler is 0.2-0.6
  m/s at the same DOPs; the unseen canyon's seed 1 had velocity north and east 6.4 and 7.7,
  roll and pitch 3.5 and 3.4 without it, 1.3, 0.72, 0.66 and 1.2 with it); the
  magnetometer heading's variance from the datasheet's field disturbance (correlated over its
  ``disturbance_time``), noise and soft iron over the learnt horizontal field (with the
  paper's 2 deg the unseen garage's yaw reached (error / sigma)^2 1170). With the paper's
  white 3 / 5 m R the quickstart's drive-long +3 m fix height offset was averaged into a
  confident height (down (error / sigma)^2 60) and the 70 mg turn-on accelerometer bias of its
  IMU, against a 10 mg prior, into a confident tilt (roll 23). Three of the paper's protocol
  choices are off by default with this tuning (``PAPER_DESIGN``, ``DATASHEET_DESIGN``; each
  can be asked for): the initial standstill's zero-velocity updates (0.01 m/s), which run
  until a fix reports the car moving, up to a second after it moved off at 1.5 m/s^2 (the
  quickstart's roll error went from 1 to 13 deg at the start, roll (error / sigma)^2 150-200
  with the datasheet's noise: the cause of the earlier datasheet attempt's failure); and the
  height hold (the last aided height as a measurement at every update: its error is the
  state's own, taken as new information twenty times in ten seconds). The third is the open
  loop in outages: over a short outage the linearisation about the free INS holds (the
  quickstart's 17 s tunnel: the same figures to two digits either way), but over the
  parking garage's 234 s it does not: the open-loop estimate ended the outage with a 53 m
  height error under a 3.5 m sigma, and the fixes' gate then refused every returning fix
  (seed 1: height (error / sigma)^2 66, vertical velocity 28; closed through the outage 0.36
  and 0.24). With this tuning the loop stays closed through outages. Its white noise is at
  least a tactical grade's (``toolbox.sensor_datasheet``, as ``tc_ekf``): an ``ideal`` IMU's
  datasheet of zeros gave the filter no noise for the strapdown's own discretisation error,
  and ``urban_canyon``'s roll and pitch sigma collapsed (seed 1: roll 221, pitch 71; with
  the floor 1.8 and 1.8).

Public classes
--------------
TanLinearisedKF.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from estimators.base import Estimator
from estimators.toolbox import aiding
from estimators.toolbox.constraints import NonholonomicNoise, height, nonholonomic
from estimators.toolbox.datasheet import (
    NLOS_TIME_CONSTANT_S,
    FixAccuracy,
    FixSplit,
    fix_error_model,
    fix_position_rows,
    fix_velocity_sigma,
    imu_error_model,
)
from estimators.toolbox.gating import FixNoiseMatching
from estimators.toolbox.ins_error import BG, N_STATES
from estimators.toolbox.ins_filter import SOLUTION_COLUMNS, InsFilter, InsNoise
from estimators.toolbox.installation import Installation
from estimators.toolbox.sensor_datasheet import ACCEL_NOISE_FLOOR, GYRO_NOISE_FLOOR
from simulator.errors import InputError

G0 = 9.80665  # standard gravity, m/s^2 (datasheet mg)
DEG = math.pi / 180.0
TUNINGS = ("datasheet", "paper")
GATE_PROBABILITY = 0.999  # chi-square gate of the fixes with the datasheet tuning


class TanLinearisedKF(Estimator):
    """Linearised KF INS/GPS with outage constraints and magnetometer heading (Tan et al. 2008)."""

    name = "ins_lkf"
    needs = ("imu", "gnss_fix")
    uses = ("mag",)
    paper = ("Tan et al. 2008 (VNU J. Sci.): linearised KF INS/GPS, closed loop with GPS, open "
             "loop with NHC, height and magnetometer aiding in outages")
    defaults = {"nhc": True, "height_constraint": None, "mag_heading": True,
                "update_interval": 0.5, "standstill": None, "course_speed": 5.0,
                "open_loop_outages": None, "tuning": "datasheet"}
    # the defaults left None: the paper's design with ``tuning: paper``, else the datasheet's
    PAPER_DESIGN = {"height_constraint": True, "standstill": 60.0, "open_loop_outages": True}
    DATASHEET_DESIGN = {"height_constraint": False, "standstill": 0.0,
                        "open_loop_outages": False}
    config_help = {
        "nhc": ("", "zero lateral and vertical body velocity during outages (eqs. 6-7)"),
        "height_constraint": ("", "hold the last GPS-aided height during outages (section "
                                  "3.2); default: on with tuning paper, off with datasheet"),
        "mag_heading": ("", "magnetometer heading during outages (eq. 8)"),
        "update_interval": ("s", "period of the aiding updates in outages"),
        "standstill": ("s", "zero-velocity and zero-rate updates over the first seconds; "
                            "default: 60 with tuning paper, 0 with datasheet"),
        "course_speed": ("m/s", "speed above which the GPS course aids the heading"),
        "open_loop_outages": ("", "open the loop during outages (the paper's design); "
                                  "default: on with tuning paper, off with datasheet"),
        "tuning": ("", "datasheet (noise from the dataset's datasheet) or paper (the values "
                       "chosen for the reproduction)"),
    }
    output_columns = SOLUTION_COLUMNS

    NOISE = InsNoise(accel_noise=0.2e-3 * G0, gyro_noise=0.1 * DEG,
                     accel_bias_sigma=1e-3 * G0, gyro_bias_sigma=0.01 * DEG,
                     accel_bias_tau=300.0, gyro_bias_tau=300.0)
    P0_SIGMA = np.r_[[3.0, 3.0, 5.0], [0.3] * 3, [2 * DEG, 2 * DEG, 5 * DEG],
                     [10e-3 * G0] * 3, [0.5 * DEG] * 3]
    R_POSITION = np.diag([3.0, 3.0, 5.0]) ** 2  # m^2 (eq. 5)
    R_NHC = np.eye(2) * 0.1**2  # (m/s)^2
    R_HEIGHT = np.array([[2.0**2]])  # m^2
    R_HEADING = np.array([[(2 * DEG) ** 2]])  # rad^2, magnetometer and GPS course
    R_ZUPT = np.eye(3) * 0.01**2  # (m/s)^2
    ZARU_FLOOR = 0.01 * DEG  # rad/s, added to the white noise of the batch-mean rate
    MAG_SOLVE_INTERVAL = 10.0  # s between re-solving the magnetometer calibration
    MOVING_SPEED = 0.5  # m/s: a GPS speed above it ends the initial standstill early

    def setup(self) -> None:
        if self.config["tuning"] not in TUNINGS:
            raise InputError(f"ins_lkf: config tuning must be one of {', '.join(TUNINGS)}, "
                             f"got {self.config['tuning']!r}")
        design = (self.PAPER_DESIGN if self.config["tuning"] == "paper"
                  else self.DATASHEET_DESIGN)
        for key, value in design.items():
            if self.config[key] is None:
                self.config[key] = value
        site = Installation.from_datasheet(self.datasheet)
        self._fix_model = None
        noise, p0, markov = self.NOISE, self.P0_SIGMA, {}
        if self.config["tuning"] == "datasheet":
            sheet = imu_error_model(self.datasheet)
            # white noise at least a tactical grade's: the strapdown's own error (sensor_datasheet)
            noise = replace(sheet, accel_noise=max(sheet.accel_noise, ACCEL_NOISE_FLOOR),
                            gyro_noise=max(sheet.gyro_noise, GYRO_NOISE_FLOOR))
            p0 = self.P0_SIGMA.copy()
            p0[9:12], p0[12:15] = noise.accel_bias_initial, noise.gyro_bias_initial
            self._fix_model = fix_error_model(self.datasheet)
            self._fix_split = FixSplit(self._fix_model)
            # the fix's correlated error, then its reflected (NLOS) error as unit states
            markov = dict(extra_sigma=np.ones(6),  # unit states: their gains at each fix
                          extra_tau=np.r_[np.full(3, self._fix_model.correlated_tau),
                                          np.full(3, NLOS_TIME_CONSTANT_S)])
        self._noise = noise
        c = self.columns["gnss_fix"]
        self._dop = [c.get("hdop"), c.get("vdop")]
        self._accuracy = FixAccuracy(c)
        self.ins = InsFilter(self.initial, self.columns["imu"], self.imu_output == "increment",
                             p0, noise, mounting=site.mounting, **markov)
        self._antenna = site.antenna
        self._rear = site.rear_axle
        self._slip = None if self._rear is None else NonholonomicNoise(site.wheelbase or 2.7)
        self._r_nhc = self.R_NHC.copy()
        c = self.columns["gnss_fix"]
        self._fix_idx = [c["lat"], c["lon"], c["alt"]]
        self._fix, self._speed, self._course = c["fix"], c["speed"], c["course"]
        self._vel_idx = [c["vn"], c["ve"], c["vd"]]
        self._t0 = self.initial.t
        moving = np.linalg.norm(self.initial.velocity) > self.MOVING_SPEED
        self._still_until = self._t0 + (0.0 if moving else self.config["standstill"])
        self._next_cycle = self._t0 + self.config["update_interval"]
        self._outage = False
        self._h_ref = 0.0
        self._mag = aiding.MagneticHeading()
        self._mag_row: np.ndarray | None = None
        self._mag_idx = ([self.columns["mag"][k] for k in ("mag_x", "mag_y", "mag_z")]
                         if "mag" in self.columns else None)
        self._moving_fix = False
        self._next_solve = self._t0
        # per NED axis, the fix velocity's noise matched to its innovations (datasheet tuning,
        # a fix that does not report its accuracy)
        self._velocity_matching = [FixNoiseMatching() for _ in range(3)]

    def on_imu(self, t: float, row: np.ndarray) -> None:
        self.ins.add_imu(t, row)
        if t >= self._next_cycle:
            self._next_cycle += self.config["update_interval"]
            self._cycle(t)

    def on_mag(self, t: float, row: np.ndarray) -> None:
        self._mag_row = row

    def _cycle(self, t: float) -> None:
        """The periodic KF step (every ``update_interval``): standstill updates at the start,
        outage aiding in open loop, magnetometer calibration while GPS aids."""
        ins = self.ins
        ins.flush()
        cfg = self.config
        if t < self._still_until:
            ins.update(*aiding.zero_velocity(ins.v, ins.n_states), self.R_ZUPT)
            if ins.mean_rate_dt > 0:  # the batch mean's noise: density^2 / duration
                r = (self._noise.gyro_noise**2 / ins.mean_rate_dt + self.ZARU_FLOOR**2) * np.eye(3)
                ins.update(*aiding.zero_rate(ins.q, ins.pos[0], ins.mean_rate, ins.n_states), r)
            return
        mag = self._magnetometer()
        if not self._outage:
            if mag is not None and self._moving_fix:
                self._mag.learn(mag, ins.q)
                if t >= self._next_solve:
                    self._mag.solve()
                    self._next_solve = t + self.MAG_SOLVE_INTERVAL
            return
        q = ins.corrected()[0]  # levels the magnetometer with the best roll and pitch
        if cfg["nhc"]:
            dz, h = nonholonomic(ins.q, ins.v, ins.n_states, ins.mean_rate, self._rear, BG)
            if self._slip is not None:
                lateral, vertical = self._slip.sigma_of_state(ins.q, ins.v, ins.mean_rate,
                                                              ins.mean_force)
                self._r_nhc[0, 0], self._r_nhc[1, 1] = lateral * lateral, vertical * vertical
            ins.update(dz, h, self._r_nhc)
        if cfg["height_constraint"]:
            ins.update(*height(ins.pos[2], self._h_ref, ins.n_states), self.R_HEIGHT)
        if cfg["mag_heading"] and mag is not None:
            yaw = self._mag.heading(mag, q)
            if yaw is not None:
                ins.update(*aiding.heading(ins.q, yaw, ins.n_states), self._mag_variance())

    def _mag_variance(self) -> np.ndarray:
        """The magnetometer heading's variance (rad^2): the paper's R_HEADING, or with
        ``tuning: datasheet`` the datasheet's magnetometer errors over the learnt horizontal
        field B_h: its disturbance (correlated over ``disturbance_time``, so white-equivalent
        at the update interval: variance times 2 T / interval, the Gauss-Markov PSD 2 sigma^2
        T, Brown & Hwang, 4th ed., section 2.9), white noise and the soft iron
        the calibration leaves out (``aiding.MagneticHeading``), each as an angle."""
        if self._fix_model is None:
            return self.R_HEADING
        sheet = self.datasheet.get("mag") or {}
        b_h = float(np.hypot(*self._mag.field_ned[:2]))
        interval = self.config["update_interval"]
        disturbance = float(sheet.get("disturbance") or 0.0) / b_h
        held = max(1.0, 2 * float(sheet.get("disturbance_time") or 0.0) / interval)
        var = (disturbance**2 * held + (float(sheet.get("noise") or 0.0) / b_h) ** 2
               + float(sheet.get("soft_iron") or 0.0) ** 2)
        return np.array([[max(var, self.R_HEADING[0, 0])]])

    def _magnetometer(self) -> np.ndarray | None:
        if self._mag_idx is None or self._mag_row is None:
            return None
        return self._mag_row[self._mag_idx]

    def on_gnss_fix(self, t: float, row: np.ndarray) -> None:
        ins = self.ins
        valid = row[self._fix] >= 1 and math.isfinite(row[self._fix_idx[0]])
        if not valid:
            if not self._outage and t >= self._still_until:
                ins.flush()
                self._outage = True
                self._h_ref = float(ins.pos[2])
                ins.set_closed_loop(not self.config["open_loop_outages"])
            self._moving_fix = False
            return
        ins.flush()
        if self._outage:
            self._outage = False
            ins.set_closed_loop(True)
        values = row[self._fix_idx]
        pos = np.array([math.radians(values[0]), math.radians(values[1]), values[2]])
        if self._fix_model is None:
            dz, h = aiding.gnss_position(ins.q, ins.pos, pos, self._antenna)
            if math.isfinite(values[2]):
                ins.update(dz, h, self.R_POSITION)
            else:  # a 2-D fix: horizontal rows only
                ins.update(dz[:2], h[:2], self.R_POSITION[:2, :2])
        else:
            self._datasheet_fix(row, pos)
        speed = float(row[self._speed])
        if speed > self.MOVING_SPEED:  # the car moved off: the standstill is over
            self._still_until = min(self._still_until, t)
        self._moving_fix = speed > self.config["course_speed"]
        if self._moving_fix and t >= self._still_until and self._fix_model is None:
            ins.update(*aiding.heading(ins.q, float(row[self._course]), ins.n_states),
                       self.R_HEADING)

    def _datasheet_fix(self, row: np.ndarray, pos: np.ndarray) -> None:
        """The fix as the antenna plus its drive-long error (three unit Gauss-Markov states,
        their gain the part of the fix's reported accuracy, ``fix_position_rows``) and a white
        remainder, gated (``tuning: datasheet``)."""
        ins, model = self.ins, self._fix_model
        dops = [float(row[i]) if i is not None else math.nan for i in self._dop]
        dz, h = aiding.gnss_position(ins.q, ins.pos, pos, self._antenna, ins.n_states)
        std_pos, std_vel = self._accuracy.read(row)
        r = fix_position_rows(self._fix_split, std_pos, *dops, dz, h, ins.extra[:6], N_STATES)
        rows = slice(0, 3) if math.isfinite(pos[2]) else slice(0, 2)
        ins.gated_update(dz[rows], h[rows], r[rows, rows], GATE_PROBABILITY)
        v_fix = row[self._vel_idx]
        if np.isfinite(v_fix).all():
            dz_v, h_v = aiding.gnss_velocity(ins.v, v_fix, ins.n_states, ins.q, ins.mean_rate,
                                             self._antenna)
            sigma = fix_velocity_sigma(model, std_vel, *dops)
            if not np.isfinite(std_vel).all():  # no accuracy reported: matched to innovations
                nu = dz_v - h_v @ ins.kf.x
                hph = np.einsum("ij,jk,ik->i", h_v, ins.kf.p, h_v)
                for k, matching in enumerate(self._velocity_matching):
                    matching.add(nu[k:k + 1], hph[k:k + 1, None], float(sigma[k]) ** 2)
                sigma = sigma * np.sqrt([m.scale for m in self._velocity_matching])
            ins.gated_update(dz_v, h_v, np.diag(sigma**2), GATE_PROBABILITY)

    def solution(self, t: float) -> list[float]:
        self.ins.flush()
        return self.ins.solution_row()
