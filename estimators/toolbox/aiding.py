"""Aiding measurements of a loosely coupled INS error-state filter, each written once: the
measurement residual dz = h(nominal) - z and its Jacobian H over the error state of
``estimators.toolbox.ins_error`` ([dr, dv, psi, dba, dbg], estimate minus truth; with
C_b^n(estimate) = (I + [psi x]) C_b^n(true)).

* ``gnss_position``: receiver position, with the antenna lever arm l^b: r_a = r + C_b^n l^b, so
  H = [I, 0, -[(C_b^n l^b) x], 0, 0] (Park et al. 2019, eq. 8 without a lever arm; the lever-arm
  term as in Groves 2013, chapter 14);
* ``gnss_velocity``: NED velocity, H = [0, I, 0, 0, 0] (Park et al. 2019, eq. 8); with the
  lever arm the antenna moves at v_a = v + C_b^n (w^b x l^b), so H = [0, I, -[(C_b^n (w x l))
  x], 0, C_b^n [l x]] (w the compensated body rate, the gyro-bias error entering through it;
  Groves 2013, eq. 14.122, the Earth rate's part of w neglected);
* ``ground_speed`` and ``course``: GNSS speed sqrt(vn^2 + ve^2) and course atan2(ve, vn) (Park
  et al. 2019, eqs. 38-41);
* ``odometer``: body-frame velocity [v_odo, 0, 0] (Park et al. 2019, eqs. 10-14; the lateral and
  vertical rows are the non-holonomic constraint of ``constraints.nonholonomic``, dropped with
  ``nhc=False``), at the IMU or, with a lever arm, at the rear axle where the wheels measure and
  the constraint holds (``constraints.body_velocity``); Park's eq. 12 prints -C_n^b (v^n x) for
  an attitude error of the opposite sign to ours, the same Jacobian;
* ``path_speed``: the speed of a point along its own path, sign(v_x) |C_n^b v^n + w x r|, with
  H = sign(v_x) (v_b / |v_b|)^T H_vb: what an odometer that counts a point's travelled
  distance reads (the simulated one counts the centre of gravity's path,
  ``installation.Installation.odometer``). Its body-x component, the ``odometer`` row, is short
  of it by the factor cos(beta) of the point's side slip beta: at the centre of gravity of a
  car in a steady turn of radius R, beta = l_r / R (the rear axle rolls without sliding),
  0.75 % in an 11 m parking helix and 3.7 % backing into a bay on a 5 m radius, an error the
  same sign through every turn;
* ``zero_velocity`` (ZUPT) and ``zero_rate`` (ZARU, the compensated gyro output equals the Earth
  rate at standstill; Groves 2013, chapter 15);
* ``barometric_height``: the barometer's altitude minus its offset from the ellipsoidal height,
  a height measurement (``constraints.height``);
* ``heading``: the yaw of C_b^n, atan2(C_21, C_11) (Tan et al. 2008, eq. 8, whose printed
  C(1,2)/C(2,2) is a transposed index), with H = [.., -C_11 C_31 / d, -C_21 C_31 / d, 1, ..],
  d = C_11^2 + C_21^2;
* ``MagneticHeading``: a magnetometer heading calibrated against the GNSS-aided attitude.

Public names
------------
gnss_position, gnss_velocity, ground_speed, course, odometer, path_speed, zero_velocity, zero_rate,
barometric_height, heading, MagneticHeading.
"""

from __future__ import annotations

import numpy as np

from estimators.toolbox.constraints import body_velocity, height
from estimators.toolbox.ins_error import BG, N_STATES
from simulator.earth import OMEGA_E_RAD_S, quat_to_dcm, radii_of_curvature, skew, wrap_angle


def gnss_position(q: np.ndarray, pos: np.ndarray, pos_gnss: np.ndarray,
                  lever_arm: np.ndarray | None = None, n_states: int = N_STATES
                  ) -> tuple[np.ndarray, np.ndarray]:
    """GNSS antenna position.

    Parameters
    ----------
    q : (4,) body-to-NED quaternion; pos : (3,) latitude, longitude (rad), height (m) of the IMU.
    pos_gnss : (3,) the receiver's latitude, longitude (rad), height (m).
    lever_arm : (3,), optional
        Antenna position in the body frame (FRD) relative to the IMU, m.

    Returns
    -------
    dz : (3,) predicted minus measured antenna position in NED, m; h : (3, n_states).
    """
    rn, re = radii_of_curvature(pos[0])
    h_mat = np.zeros((3, n_states))
    h_mat[:, 0:3] = np.eye(3)
    dz = np.array([(pos[0] - pos_gnss[0]) * (rn + pos[2]),
                   (pos[1] - pos_gnss[1]) * (re + pos[2]) * np.cos(pos[0]),
                   pos_gnss[2] - pos[2]])
    if lever_arm is not None:
        arm_n = quat_to_dcm(q) @ np.asarray(lever_arm, dtype=float)
        dz += arm_n
        h_mat[:, 6:9] = -skew(arm_n)
    return dz, h_mat


def gnss_velocity(v: np.ndarray, v_gnss: np.ndarray, n_states: int = N_STATES,
                  q: np.ndarray | None = None, rate_body: np.ndarray | None = None,
                  lever_arm: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """NED velocity of the antenna: dz = v_a - v_gnss (m/s), H = [0, I, 0 ...] at the IMU; with
    ``lever_arm`` (antenna from the IMU, body FRD, m; needs ``q`` and the compensated body rate
    ``rate_body``, rad/s) the lever-arm terms of the module docstring."""
    h_mat = np.zeros((3, n_states))
    h_mat[:, 3:6] = np.eye(3)
    dz = np.asarray(v, float) - np.asarray(v_gnss, float)
    if lever_arm is not None:
        arm = np.asarray(lever_arm, dtype=float)
        c_bn = quat_to_dcm(q)
        turn_n = c_bn @ np.cross(rate_body, arm)
        dz += turn_n
        h_mat[:, 6:9] = -skew(turn_n)
        if n_states > BG.start:
            h_mat[:, BG] = c_bn @ skew(arm)
    return dz, h_mat


def ground_speed(v: np.ndarray, speed: float, n_states: int = N_STATES
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Horizontal speed: dz = |v_ne| - speed (m/s). Undefined at standstill (H is zero there)."""
    s = float(np.hypot(v[0], v[1]))
    h_mat = np.zeros((1, n_states))
    if s > 0.0:
        h_mat[0, 3:5] = v[0] / s, v[1] / s
    return np.array([s - speed]), h_mat


def course(v: np.ndarray, course_rad: float, n_states: int = N_STATES
           ) -> tuple[np.ndarray, np.ndarray]:
    """Course over ground: dz = atan2(ve, vn) - course, wrapped to (-pi, pi] (rad)."""
    s2 = float(v[0] ** 2 + v[1] ** 2)
    h_mat = np.zeros((1, n_states))
    if s2 > 0.0:
        h_mat[0, 3:5] = -v[1] / s2, v[0] / s2
    return np.array([float(wrap_angle(np.arctan2(v[1], v[0]) - course_rad))]), h_mat


def odometer(q: np.ndarray, v: np.ndarray, speed: float, nhc: bool = True,
             n_states: int = N_STATES, rate_body: np.ndarray | None = None,
             lever_arm: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Odometer speed along body x, with the non-holonomic rows (Park et al. 2019, eqs. 13-14),
    at the IMU or at the point ``lever_arm`` (from the IMU, body FRD, m; the rear axle) moving
    with the compensated body rate ``rate_body`` (rad/s; ``constraints.body_velocity``).

    Returns
    -------
    dz : (3,) or (1,) estimated body velocity minus [speed, 0, 0], m/s; h : (3 or 1, n_states).
    """
    bias = BG if n_states > BG.start else None
    v_b, h = body_velocity(q, v, n_states, rate_body, lever_arm, bias)
    v_b[0] -= speed
    if not nhc:
        return v_b[:1], h[:1]
    return v_b, h


def path_speed(q: np.ndarray, v: np.ndarray, speed: float, n_states: int = N_STATES,
               rate_body: np.ndarray | None = None, lever_arm: np.ndarray | None = None
               ) -> tuple[np.ndarray, np.ndarray]:
    """Signed speed of a point along its path (module docstring): ``odometer``'s arguments.

    Returns
    -------
    dz : (1,) estimated minus measured speed, m/s; h : (1, n_states). At a standstill (the
    point's estimated speed under 1 mm/s) the body-x row of ``odometer``, whose direction is
    defined.
    """
    bias = BG if n_states > BG.start else None
    v_b, h = body_velocity(q, v, n_states, rate_body, lever_arm, bias)
    norm = float(np.sqrt(v_b @ v_b))
    if norm < 1e-3:
        return np.array([v_b[0] - speed]), h[:1]
    sign = 1.0 if v_b[0] >= 0.0 else -1.0
    return np.array([sign * norm - speed]), (sign / norm) * (v_b @ h)[None, :]


def zero_velocity(v: np.ndarray, n_states: int = N_STATES) -> tuple[np.ndarray, np.ndarray]:
    """ZUPT: the vehicle stands still, dz = v (m/s)."""
    return gnss_velocity(v, np.zeros(3), n_states)


def zero_rate(q: np.ndarray, lat: float, gyro_compensated: np.ndarray,
              n_states: int = N_STATES) -> tuple[np.ndarray, np.ndarray]:
    """ZARU: at standstill the bias-compensated gyro output (rad/s, body) is the Earth rate.

    dz = w_compensated - C_n^b w_ie^n; the compensated output is w_true - dbg, so H = -I on the
    gyro-bias block (the attitude error's effect, of order 1e-5 psi, is neglected).
    """
    w_ie = OMEGA_E_RAD_S * np.array([np.cos(lat), 0.0, -np.sin(lat)])
    h_mat = np.zeros((3, n_states))
    h_mat[:, BG] = -np.eye(3)
    return np.asarray(gyro_compensated, float) - quat_to_dcm(q).T @ w_ie, h_mat


def barometric_height(h_estimate: float, baro_altitude: float, offset: float,
                      n_states: int = N_STATES) -> tuple[np.ndarray, np.ndarray]:
    """Barometric height: the baro altitude minus its (calibrated) offset from the ellipsoidal
    height is a height measurement (``constraints.height``)."""
    return height(h_estimate, baro_altitude - offset, n_states)


def heading(q: np.ndarray, heading_rad: float, n_states: int = N_STATES
            ) -> tuple[np.ndarray, np.ndarray]:
    """External heading (magnetometer, GNSS dual antenna): dz = yaw(q) - heading, wrapped."""
    c = quat_to_dcm(q)
    d = c[0, 0] ** 2 + c[1, 0] ** 2
    h_mat = np.zeros((1, n_states))
    h_mat[0, 6:9] = -c[0, 0] * c[2, 0] / d, -c[1, 0] * c[2, 0] / d, 1.0
    yaw = np.arctan2(c[1, 0], c[0, 0])
    return np.array([float(wrap_angle(yaw - heading_rad))]), h_mat


class MagneticHeading:
    """Magnetometer heading calibrated against the GNSS-aided attitude.

    Model: m^b = C_n^b B^n + b (the Earth's field B^n, constant over a drive, and a hard-iron
    offset b; soft iron is neglected). While GNSS aids the attitude, ``learn(m, q)`` accumulates
    the normal equations of the six unknowns [B^n, b] (linear in them); once the heading has
    varied enough for them to be well conditioned, ``heading(m, q)`` removes b, levels the
    field with the estimate's roll and pitch and returns the heading of the body's x axis
    relative to the learned field's direction, i.e. with the declination (and any constant
    misalignment) calibrated in. This is the "calibrated against GPS" choice for Tan et al.
    2008, section 4 (the paper does not say how its magnetometer was calibrated).

    With small roll and pitch the vertical field and the vertical hard iron are seen only as
    their sum; a weak prior b ~ N(0, ``hard_iron_sigma``^2) against the sample noise
    ``noise_sigma`` separates them (an error in the vertical hard iron moves the levelled
    heading only by its product with the tilt).

    Parameters
    ----------
    min_condition : float
        Largest condition number of the horizontal part (north and east field, x and y hard
        iron) of the normal matrix accepted before a heading is given: the heading must have
        varied (turns) for them to separate.
    noise_sigma, hard_iron_sigma : float
        Sample noise and prior hard-iron spread, T.
    """

    def __init__(self, min_condition: float = 1e3, noise_sigma: float = 0.5e-6,
                 hard_iron_sigma: float = 20e-6):
        self._ata = np.diag([0.0, 0.0, 0.0, *[(noise_sigma / hard_iron_sigma) ** 2] * 3])
        self._aty = np.zeros(6)
        self._count = 0
        self._max_cond = min_condition
        self.field_ned: np.ndarray | None = None
        self.hard_iron: np.ndarray | None = None

    def learn(self, m_body: np.ndarray, q: np.ndarray) -> None:
        """Add one magnetometer sample (T, body) taken at attitude q."""
        a = np.hstack([quat_to_dcm(q).T, np.eye(3)])
        self._ata += a.T @ a
        self._aty += a.T @ np.asarray(m_body, float)
        self._count += 1

    def solve(self) -> bool:
        """Update the calibration from what was learned; True when it is usable."""
        horizontal = self._ata[np.ix_([0, 1, 3, 4], [0, 1, 3, 4])]
        if self._count < 12 or np.linalg.cond(horizontal) > self._max_cond:
            return self.field_ned is not None
        x = np.linalg.solve(self._ata, self._aty)
        self.field_ned, self.hard_iron = x[:3], x[3:]
        return True

    def heading(self, m_body: np.ndarray, q: np.ndarray) -> float | None:
        """Calibrated magnetic heading (rad, from true north) of a sample at attitude q, whose
        roll and pitch levels the field; None before calibration."""
        if self.field_ned is None:
            return None
        c_bn = quat_to_dcm(q)
        yaw = np.arctan2(c_bn[1, 0], c_bn[0, 0])
        # the field in the yaw-free (levelled) frame: rotate body -> NED, then undo the yaw
        m_n = c_bn @ (np.asarray(m_body, float) - self.hard_iron)
        cy, sy = np.cos(yaw), np.sin(yaw)
        m_lev = np.array([cy * m_n[0] + sy * m_n[1], -sy * m_n[0] + cy * m_n[1]])
        # the field's horizontal direction is at atan2(B_e, B_n) in NED; in the levelled frame
        # it appears at that minus the heading
        mag_dir = np.arctan2(self.field_ned[1], self.field_ned[0])
        return float(wrap_angle(mag_dir - np.arctan2(m_lev[1], m_lev[0])))
