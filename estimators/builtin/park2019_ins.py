"""``ins_odo_ekf``: the INS/GPS/odometer EKF with the non-holonomic constraint, the baseline of
Park et al., "MEMS 3D DR/GPS Integrated System for Land Vehicle Application Robust to GPS
Outages", IEEE Access 7, 2019, section II-A (eqs. 1-14).

* Mechanisation, eqs. 1-3: NED position, velocity and quaternion attitude with Earth rate,
  transport rate and WGS-84 gravity (``toolbox.strapdown``; Park integrates trapezoidally, the
  toolbox's two-sample form is the same to first order).
* Error state, eq. 4: position, velocity, attitude errors, accelerometer and gyro biases, 15
  states. The system matrix F_0 of eq. 5 is "described in [1]" (Titterton & Weston); here it is
  ``toolbox.ins_error`` (the same NED error model; attitude error sign per ``nav_error``). Park
  gives no bias model or Q: the biases are first-order Gauss-Markov (chosen: accelerometer
  sigma 5 mg, gyro sigma 0.05 deg/s, both tau 600 s: the temperature drifts of Table 1 over a
  few kelvin), the white noises are Table 1's RMS noise densities (0.19 mg/sqrt(Hz),
  0.02 deg/s/sqrt(Hz)), the initial bias uncertainties Table 1's zero-point offsets (70 mg,
  1 deg/s).
* GPS, eqs. 6-8: position and NED velocity of the receiver's 3-D fixes (1-sigma 2.5 m
  horizontal, 5 m vertical, 0.1 m/s horizontal and 0.2 m/s vertical velocity: chosen, Park
  prints no R; white, although the receiver's fix error is correlated over its 100 s carrier
  smoothing: see ``fix_error_states`` below).
* Odometer with NHC, eqs. 9-14: body velocity [v_odo, 0, 0], "used sequentially after the GPS
  measurement update". 1-sigma (chosen): on the odometer row sqrt(0.1^2 + (0.03 v_odo)^2)
  m/s, since eq. 4 has no scale-factor state and an unmodelled scale error is
  speed-proportional: 3 % is the range Park's section III-E studies (scale factors 0.97 to
  1.03). (A first version with 0.1 m/s alone trusted the odometer over GPS: on Park's garage
  drive, true scale factor 1.03, its errors with GPS were 6-10 m against a claimed 0.5 m.)
  Park does not say at what rate; here at every odometer sample (10 Hz), so that it also aids
  during outages, which is the point of the comparison in Park's Table 3; ``odometer_period``
  (s) spaces the updates (1: once a second, the GPS rate, the other reading of
  "sequentially"). With ``nhc: false`` only the forward (odometer) row is used.
* Where the constraint holds (issue 14; Park is silent, his IMU sat in a car whose geometry is
  not printed): at the rear axle, where the wheels do not steer (the kinematic bicycle model),
  not at the IMU, which in a turn moves sideways at the yaw rate times its distance ahead of
  the rear axle (11 deg of slip in an 8 m turn for the automotive car's 1.74 m). The rear axle
  from the IMU is the datasheet's ``vehicle.rear_axle`` (``toolbox.installation``); the
  odometer row and the NHC rows are the velocity of that point, C_n^b v^n + w x r, with the
  attitude and gyro-bias Jacobians (``toolbox.constraints.body_velocity``). Their noise is the
  car's physics as a user knows it before any drive (``constraints.NonholonomicNoise``): the
  rear tyres' slip of the linear bicycle model with Gillespie's cornering coefficient, the body's
  pitch on its springs under braking and the suspension travel on a class B road, each in
  quadrature with the 0.1 m/s floor of the rigid case. On a ``rigid`` body (no rear axle in the
  datasheet), or with ``nhc_point: imu``, the constraint is at the IMU with 0.1 m/s, the
  paper's situation.
* GNSS antenna lever arm (the datasheet's ``gnss.antenna_lever_arm``): the fix is the antenna's
  position r + C_b^n l and velocity v + C_b^n (w x l) (``aiding.gnss_position``,
  ``aiding.gnss_velocity``). IMU mounting (``imu.mounting``): the samples are rotated into the
  car's frame before the strapdown (``InsFilter(mounting=...)``), so the filter navigates the
  car and its bias estimates are on the car's axes. The vehicle model does not tilt the IMU on
  the body: the body itself pitches and rolls on its suspension, which is the attitude the
  strapdown tracks.
* Options beyond the paper's 15 states, off by default (the SPEC's 15-state filter):
  ``fix_error_states``, three Gauss-Markov states of the fix's correlated error (steady-state
  sigma 2.5, 2.5, 5 m, the white R's values, with the datasheet's ``carrier_smoothing``, the
  receiver's carrier-smoothing time, 100 s for the ``automotive`` receiver) and a white 0.5 /
  1 m remainder, for the overconfidence of a white R against fix errors correlated over 100 s
  (position NEES 44.5, median of Park's garage's ten seeds); ``odometer_scale_state``, a
  random-constant odometer scale factor (1-sigma 3 %) in place of its speed-proportional
  noise. Both together: NEES 5.8 at the same RMS outside outages (2.7 m) on Park's garage, but
  6.7 m on parking_garage.yaml, against 3.3 m: the filter's position sigma at a garage exit is
  too small for its error (the garage's own overconfidence), so the first fix's innovation is
  partly taken as fix error, which then decays over 100 s (docs/reproduction_park2019_ins.md).

* ``tuning`` (default ``datasheet``): where its noise comes from. ``paper``: the values above
  (Park's Table 1 and the choices named), which the reproduction (``simulator.reproduce.
  park2019``) asks for explicitly so that its figures stay put. ``datasheet``: from what a
  user knows of the sensors (``toolbox.datasheet``): the IMU's noise densities, in-run bias
  instability and turn-on bias range, its scale factors as bias process noise; the fix's
  error as three Gauss-Markov states of its drive-long error (correlation time 30 min; the
  +1 to +7 m height offset of a single-frequency fix is this error, docs/gnss-errors.md):
  unit states whose gain at each fix is the part of the fix's reported accuracy beyond the
  budget's smoothed noise, capped at the budget's correlated part
  (``toolbox.datasheet.FixSplit``; sized by the budget alone, 2.2 m of range error, the
  position was too cautious on open sky, where the report is smaller), plus the white
  equivalent of its smoothed noise, and its velocity at 0.05 m/s per range rate times the
  DOP, each behind a chi-square gate (0.999; after five rejections in a row the next fix is
  taken); the odometer's tick quantisation or speed cut-off, its age (latency plus half the counting
  interval) times the acceleration, and the 3 % scale as above (``fix_error_states`` is
  implied, and so is ``odometer_scale_state``: the ``automotive`` odometer reads 0.991 of the
  distance, a constant that white 3 % noise at 10 Hz averaged away, so that the unseen canyon's
  dead reckoning between reflected fixes claimed 0.04 m/s against a 0.1 m/s north velocity
  error, vn (error / sigma)^2 3.7-3.8 on seeds 1-2, 1.9-2.4 with the state). The fix's own
  accuracy (``std_*``, ``toolbox.datasheet.FixAccuracy``) sets its velocity noise, and its
  position 1-sigma beyond its drive-long and smoothed parts (reflected signals) is carried
  by three unit NLOS states after the fix's (``FixSplit``): the canyon's height went from
  6.0-6.5 to 0.14-0.39 (seeds 1-2).
  With a datasheet that gives the gyros' scale factor, three yaw-response states follow the
  15 (``InsFilter``'s: the z gyro's scale factor and the x and y gyros' misalignment towards
  z, random constants of the datasheet's 1-sigma; ``yaw_response_states: false`` leaves them
  out). Without them the scale factor was bias process noise of independent increments: on
  parking_garage.yaml's helices (0.36 rad/s for 50 s, 0.5 % = 0.1 deg/s) the yaw sigma grew
  at a third of the error's rate and the yaw's mean (error / sigma)^2 was 11-16 over seeds
  1-3; with them 8.7-9.8. The odometer row is the speed of the centre of gravity along its
  path (``aiding.path_speed``), what the odometer counts, not that point's body-x velocity,
  short of it by cos(beta) of its side slip, beta = l_r / R in a turn of radius R (0.75 % in
  the 11 m helix, 3.7 % backing on 5 m; one sign through every turn, taken for a yaw error):
  with it, yaw 3.1 on seed 1. And the odometer and NHC rows pass the fixes' chi-square gate
  (``odometer_gate``, kept apart from the fixes' rejection count): the car's physics is the
  constraint's noise in steady motion, not where the path's curvature jumps (the garage's
  reverse into a bay, entered over 0.5 m of clothoid: the truth's rear axle slides there at
  up to 0.6 m/s for 1.5 s, docs/vehicle.md); seed 1's yaw 1.05, every axis 0.15-1.45.
  Causes of the velocity's overconfidence in the stop-and-go of a city (``sumo_city_canyon`` seed
  1: vn, ve, vd (error / sigma)^2 8.7, 15, 5.4 with velocity errors of a few cm/s under sigmas of
  1-2 cm/s), each a systematic error taken as white noise at the odometer's 50 Hz: (1) the
  odometer's speed is 30 ms old (``odometer_delay_s``: the CAN speed's latency and half its
  counting window), which at 2 m/s^2 of braking is 0.06 m/s along the track; its prediction is now
  taken back by the delay times the acceleration, the window's spread left as noise. (2) The body
  squats on its springs, so the rear axle's velocity leaves its x axis by k a (k about 0.005 rad
  per m/s^2 in the simulator's car): a random-constant state, prior
  ``NonholonomicNoise.pitch_compliance``, in the vertical row, which carried it as white noise.
  (3) The odometer row and the two NHC rows pass separate gates, each taking the next row after
  ``ODOMETER_GATE_ESCAPE_S`` of rejections (not after five rows, 0.1 s at 50 Hz): where a
  junction's path curvature jumps the truth's rear axle slides sideways at up to 0.8 m/s for 2-3 s
  (the body's side slip follows the curvature at once, docs/vehicle.md), which the five-row escape
  took in after 0.1 s (roll error 1.7 deg against a sigma of 0.09). With the three: seed 1's vn,
  ve, vd 3.3, 4.8, 0.48, roll 3.0 (3.7 before), yaw 3.3 (2.5 before); what is left is the
  junctions' slides. Tried and not kept: the rear tyres' slip D v a_y as a random-constant state
  too (yaw 6.1: it took the slides for slip).

The filter is closed loop (errors fed back after each update).

Public classes
--------------
ParkInsOdometer.
"""

from __future__ import annotations

import math

import numpy as np

from estimators.base import Estimator
from estimators.toolbox import aiding
from estimators.toolbox.config_help import shared_help
from estimators.toolbox.constraints import NonholonomicNoise
from estimators.toolbox.datasheet import (
    NLOS_TIME_CONSTANT_S,
    FixAccuracy,
    FixSplit,
    fix_error_model,
    fix_position_rows,
    fix_velocity_sigma,
    imu_error_model,
    odometer_delay_s,
    odometer_speed_sigma,
    odometer_window_s,
)
from estimators.toolbox.ins_filter import SOLUTION_COLUMNS, InsFilter, InsNoise
from estimators.toolbox.installation import Installation
from simulator.earth import quat_to_dcm
from simulator.errors import InputError

G0 = 9.80665  # standard gravity, m/s^2 (datasheet mg)
DEG = math.pi / 180.0
NHC_POINTS = ("rear_axle", "imu")
TUNINGS = ("datasheet", "paper")
GATE_PROBABILITY = 0.999  # chi-square gate of the fixes with the datasheet tuning
ODOMETER_GATE_ESCAPE_S = 5.0  # odometer or NHC rows rejected this long: the next one is taken


class ParkInsOdometer(Estimator):
    """15-state INS/GPS/odometer EKF with NHC (Park et al. 2019, eqs. 1-14)."""

    name = "ins_odo_ekf"
    needs = ("imu", "odometer", "gnss_fix")
    paper = "Park et al. 2019 (IEEE Access), eqs. 1-14: INS/GPS/odometer EKF with NHC"
    defaults = {"tuning": "datasheet", "nhc": True, "nhc_point": "rear_axle",
                "fix_error_states": False, "odometer_scale_state": False,
                "odometer_period": 0.0, "yaw_response_states": True, "odometer_gate": True}
    config_help = {
        "tuning": ("", "datasheet: noise from the manifest's datasheet (default); paper: the "
                       "values chosen for the reproduction of Park et al."),
        **shared_help("nhc", "nhc_point"),
        "fix_error_states": ("", "three Gauss-Markov states of the GNSS fix's correlated error"),
        "odometer_scale_state": ("", "an odometer scale-factor state"),
        "odometer_period": ("s", "least time between two odometer updates (0: every sample; "
                                 "1: once a second, at the GPS rate)"),
        "yaw_response_states": ("", "with tuning datasheet: three states of the gyros' "
                                    "response to the yaw rate (z scale factor, x and y "
                                    "misalignment)"),
        "odometer_gate": ("", "with tuning datasheet: the odometer and NHC rows behind the "
                              "fixes' chi-square gate (0.999)"),
    }
    output_columns = SOLUTION_COLUMNS

    NOISE = InsNoise(accel_noise=0.19e-3 * G0, gyro_noise=0.02 * DEG,
                     accel_bias_sigma=5e-3 * G0, gyro_bias_sigma=0.05 * DEG,
                     accel_bias_tau=600.0, gyro_bias_tau=600.0)
    P0_SIGMA = np.r_[[5.0, 5.0, 5.0], [0.5] * 3, [2 * DEG, 2 * DEG, 5 * DEG],
                     [70e-3 * G0] * 3, [1.0 * DEG] * 3]
    R_POSITION = np.diag([2.5, 2.5, 5.0]) ** 2  # m^2
    FIX_SIGMA = np.array([2.5, 2.5, 5.0])  # correlated fix error, steady-state 1-sigma, m
    R_POSITION_WHITE = np.diag([0.5, 0.5, 1.0]) ** 2  # m^2, its white remainder
    R_VELOCITY = np.diag([0.1, 0.1, 0.2]) ** 2  # (m/s)^2
    R_ODOMETER = 0.1**2  # (m/s)^2, each body axis: white noise
    ODOMETER_SCALE_SIGMA = 0.03  # unmodelled odometer scale-factor error, 1-sigma

    def setup(self) -> None:
        if self.config["nhc_point"] not in NHC_POINTS:
            raise InputError(f"ins_odo_ekf: config nhc_point must be one of "
                             f"{', '.join(NHC_POINTS)}, got {self.config['nhc_point']!r}")
        if self.config["tuning"] not in TUNINGS:
            raise InputError(f"ins_odo_ekf: config tuning must be one of {', '.join(TUNINGS)}, "
                             f"got {self.config['tuning']!r}")
        self._sheet = self.config["tuning"] == "datasheet"
        self._t_odometer = -np.inf  # time of the last odometer update
        site = Installation.from_datasheet(self.datasheet)
        gnss = self.datasheet.get("gnss") or {}
        if self._sheet:
            noise, p0, fix_sigma, fix_tau = self._datasheet_model()
            self._fix_states = scale_state = True
        else:
            # the receiver's fix error is correlated over its carrier-smoothing time (the
            # datasheet's carrier_smoothing; code_correlation_time in datasets made before it):
            # three Gauss-Markov states of that time constant
            noise, p0, fix_sigma = self.NOISE, self.P0_SIGMA, self.FIX_SIGMA
            fix_tau = float(gnss.get("carrier_smoothing") or gnss.get("code_correlation_time")
                            or 0.0)
            self._fix_states = self.config["fix_error_states"] and fix_tau > 0
            scale_state = self.config["odometer_scale_state"]
        sigma, taus = [], []
        if self._fix_states:
            sigma, taus = list(fix_sigma), [fix_tau] * 3
        if self._sheet:  # the reflected fixes' error, unit states scaled by the fix's excess
            sigma += [1.0] * 3
            taus += [NLOS_TIME_CONSTANT_S] * 3
        scale_index = None
        if scale_state:  # a random constant (tau = inf)
            scale_index = len(sigma)
            sigma.append(self.ODOMETER_SCALE_SIGMA)
            taus.append(np.inf)
        # the constraint where it holds: the rear axle, with the car's slip as its noise; at the
        # IMU (a rigid body, or asked for) with the white 0.1 m/s of the paper's situation
        self._rear = site.rear_axle if self.config["nhc_point"] == "rear_axle" else None
        self._slip = (NonholonomicNoise(site.wheelbase or 2.7) if self._rear is not None
                      else None)
        self._body_index = None  # the car body's squat state (datasheet tuning)
        if self._sheet and self._slip is not None:  # a random constant of the car's prior
            self._body_index = len(sigma)
            sigma.append(self._slip.pitch_compliance)
            taus.append(np.inf)
        markov = dict(extra_sigma=np.array(sigma), extra_tau=np.array(taus)) if sigma else {}
        if (self._sheet and self.config["yaw_response_states"]
                and noise.yaw_response_sigma.any()):  # an IMU with scale factors
            markov["yaw_response_sigma"] = noise.yaw_response_sigma
        self.ins = InsFilter(self.initial, self.columns["imu"], self.imu_output == "increment",
                             p0, noise, mounting=site.mounting, **markov)
        self._scale_index = scale_index  # the odometer scale's index among the extra states
        c = self.columns["gnss_fix"]
        self._fix_idx = [c["lat"], c["lon"], c["alt"], c["vn"], c["ve"], c["vd"]]
        self._fix = c["fix"]
        self._dop = [c.get("hdop"), c.get("vdop")]
        self._accuracy = FixAccuracy(c)
        self._speed = self.columns["odometer"]["speed"]
        self._antenna = site.antenna
        # the odometer's own point (the datasheet tuning): the speed along the path it counts
        self._odo_point = site.odometer if self._sheet else None
        n_rows = 3 if self.config["nhc"] else 1
        self._r_odo = np.eye(n_rows) * self.R_ODOMETER
        self._r_fix = np.zeros((6, 6))
        self._r_fix[:3, :3] = self.R_POSITION_WHITE if self._fix_states else self.R_POSITION
        self._r_fix[3:, 3:] = self.R_VELOCITY

    def _datasheet_model(self) -> tuple[InsNoise, np.ndarray, np.ndarray, float]:
        """The IMU noise, P0 and fix-error states of ``tuning: datasheet`` (module docstring):
        from the datasheet's IMU (``toolbox.datasheet.imu_error_model``), receiver
        (``fix_error_model``; the states' size is set again at the first fix from its DOPs)
        and odometer (its speed quantisation and latency, ``odometer_speed_sigma``)."""
        imu = imu_error_model(self.datasheet)
        p0 = self.P0_SIGMA.copy()
        p0[9:12], p0[12:15] = imu.accel_bias_initial, imu.gyro_bias_initial
        self._fix_model = fix_error_model(self.datasheet)
        self._fix_split = FixSplit(self._fix_model)
        self._odo_sigma = odometer_speed_sigma(self.datasheet)
        self._odo_still_sigma = odometer_speed_sigma(self.datasheet, 0.0)
        odo_rate = float((self.datasheet.get("odometer") or {}).get("rate") or 10.0)
        self._odo_escape = max(5, math.ceil(ODOMETER_GATE_ESCAPE_S * odo_rate))
        # unit states: their gain at each fix is the drive-long part of its reported accuracy
        return imu, p0, np.ones(3), self._fix_model.correlated_tau

    def on_imu(self, t: float, row: np.ndarray) -> None:
        self.ins.add_imu(t, row)

    def on_gnss_fix(self, t: float, row: np.ndarray) -> None:
        values = row[self._fix_idx]
        if row[self._fix] < 2 or not np.isfinite(values[:3]).all():
            return
        # a receiver (or a recording) may leave a velocity component out (NaN): those rows
        # are not used
        keep = np.r_[np.ones(3, dtype=bool), np.isfinite(values[3:6])]
        ins = self.ins
        ins.flush()
        pos = np.array([math.radians(values[0]), math.radians(values[1]), values[2]])
        n = ins.n_states
        dz_p, h_p = aiding.gnss_position(ins.q, ins.pos, pos, self._antenna, n)
        if self._fix_states and not self._sheet:  # the antenna plus its correlated error
            dz_p += ins.extra[:3]
            h_p[:, ins.extra_start:ins.extra_start + 3] = np.eye(3)
        dz_v, h_v = aiding.gnss_velocity(ins.v, np.nan_to_num(values[3:6]), n, ins.q,
                                         ins.mean_rate, self._antenna)
        if not self._sheet:
            ins.update(np.concatenate([dz_p, dz_v])[keep], np.vstack([h_p, h_v])[keep],
                       self._r_fix[np.ix_(keep, keep)])
            return
        dops = [float(row[i]) if i is not None else math.nan for i in self._dop]
        model = self._fix_model
        # the fix's drive-long error and the error it reports beyond it
        # (reflections): unit states, their gains from its reported accuracy
        std_pos, std_vel = self._accuracy.read(row)
        r_p = fix_position_rows(self._fix_split, std_pos, *dops, dz_p, h_p, ins.extra[:6],
                                ins.extra_start)
        # a fix that does not fit (a reflected signal's metres) is left out, not averaged in
        ins.gated_update(dz_p, h_p, r_p, GATE_PROBABILITY)
        rows = keep[3:]
        if rows.any():  # the fix's own velocity accuracy, else the datasheet's at its DOPs
            sigma_v = fix_velocity_sigma(model, std_vel, *dops)
            ins.gated_update(dz_v[rows], h_v[rows], np.diag(sigma_v[rows] ** 2),
                             GATE_PROBABILITY)

    def on_odometer(self, t: float, row: np.ndarray) -> None:
        if t < self._t_odometer + self.config["odometer_period"] - 1e-6:
            return
        self._t_odometer = t
        ins = self.ins
        ins.flush()
        speed = float(row[self._speed])
        dz, h = aiding.odometer(ins.q, ins.v, speed, self.config["nhc"], ins.n_states,
                                ins.mean_rate, self._rear)
        forward = dz[0] + speed  # the constraint point's body-x velocity, m/s
        if self._odo_point is not None:
            dz[:1], h[:1] = aiding.path_speed(ins.q, ins.v, speed, ins.n_states,
                                              ins.mean_rate, self._odo_point)
        r = self._r_odo
        scale_sigma = self.ODOMETER_SCALE_SIGMA
        if self._scale_index is not None:  # odometer reads (1 + k) v: dz = v_x - speed / (1 + k)
            k = ins.extra[self._scale_index]
            dz[0] = dz[0] + speed - speed / (1.0 + k)
            h[0, ins.extra_start + self._scale_index] = speed / (1.0 + k) ** 2
            scale_sigma = 0.0
        if not self._sheet:
            r[0, 0] = self.R_ODOMETER + (scale_sigma * speed) ** 2
            if self._slip is not None and len(r) == 3:
                lateral, vertical = self._slip.sigma_of_state(ins.q, ins.v, ins.mean_rate,
                                                              ins.mean_force)
                r[1, 1], r[2, 2] = lateral * lateral, vertical * vertical
            ins.update(dz, h, r)
            return
        # its resolution (or cut-off); the speed is the mean over a window odometer_delay_s
        # old at this speed (older where a CAN speed's tooth edges are sparse): the
        # prediction taken back by the acceleration times the delay, the window's spread as
        # noise
        accel = ins.mean_force[0] + quat_to_dcm(ins.q)[2, 0] * G0
        dz[0] -= accel * odometer_delay_s(self.datasheet, speed)
        sigma = self._odo_sigma if speed != 0.0 else self._odo_still_sigma
        r[0, 0] = (sigma**2 + (odometer_window_s(self.datasheet, speed) * accel) ** 2
                   + (scale_sigma * speed) ** 2)
        if len(r) == 3 and self._slip is not None:
            pitch_accel = accel
            if self._body_index is not None:  # the squat as a state (module docstring)
                b = ins.extra_start + self._body_index
                squat = ins.extra[self._body_index]
                g_squat = forward * accel
                dz[2] -= squat * g_squat
                h[2, b] = -g_squat
                pitch_accel = 0.0
            lateral, vertical = self._slip.sigma(forward, float(ins.mean_rate[2]), pitch_accel)
            r[1, 1], r[2, 2] = lateral * lateral, vertical * vertical
        if not self.config["odometer_gate"]:
            ins.update(dz, h, r)
            return
        # each aid behind its own gate: a slide of the rear axle refuses the NHC rows while
        # the odometer's speed still counts
        keep = np.zeros(len(dz), dtype=bool)
        keep[0] = ins.passes(dz[:1], h[:1], r[:1, :1], GATE_PROBABILITY, self._odo_escape,
                             kind="odometer")
        if len(r) == 3:
            keep[1:] = ins.passes(dz[1:], h[1:], r[1:, 1:], GATE_PROBABILITY,
                                  self._odo_escape, kind="nhc")
        if keep.any():
            ins.update(dz[keep], h[keep], r[np.ix_(keep, keep)])

    def solution(self, t: float) -> list[float]:
        self.ins.flush()
        return self.ins.solution_row()
