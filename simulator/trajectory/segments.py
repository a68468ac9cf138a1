"""Parametric drives (trajectory kind ``segments``): the SPEC section 4 segment table turned into
exact road geometry and a jerk-limited speed profile.

A drive is described by two sets of piecewise polynomials (``RoadProfile``):

* along the road, as functions of the travelled distance s (m): curvature kappa(s) = dpsi/ds
  (rad/m, + right), road grade angle gamma(s) (rad, + climbing) and road bank (rad, + right side
  down);
* in time: the travelled distance s(t), piecewise cubic (constant jerk pieces).

Geometry choices (a navigation researcher would expect them; they are documented in docs/drives.md):

* ``turn`` and ``helix`` are entered and left through transition curves (curvature a smoothstep
  in s, a clothoid with rounded ends) whose
  length gives a lateral jerk of ``limits.lateral_jerk`` at the segment's speed, but at most half
  the turn angle each, so yaw rate and lateral acceleration are continuous.
* ``slope`` and ``helix`` change grade through vertical curves (grade angle a smoothstep in s) whose
  length gives a vertical acceleration of ``limits.vertical_accel``; every segment other than
  ``slope``, ``helix`` and ``speed_bump`` is level, so a slope climbs and returns to level.
* ``speed_bump`` is the smooth bump z = H 64 u^3 (1-u)^3 (u = s/L), crossed at the current speed.
* ``lane_change`` deflects the heading by c 140 u^3 (1-u)^3 with c solved so the lateral shift is
  ``offset`` exactly (heading and curvature continuous).
* ``accelerate`` changes speed with a trapezoidal acceleration (jerk ``limits.jerk``); a segment
  that says ``speed`` while the vehicle moves at another speed, and a ``stop`` or ``reverse``
  reached while moving, are preceded by such a change at ``limits.accel``.
* ``reverse`` backs the car up from standstill over ``length`` m of path, up to ``speed`` and
  back to standstill (jerk-limited, ``limits.accel``; a lower peak when ``length`` is too short
  to reach ``speed``). With ``angle`` the path starts with a clothoid - arc - clothoid curve as in
  ``turn`` (at ``radius``, then straight back for the rest of ``length``; without ``radius``,
  the curve fills the whole ``length``). The sign of ``angle`` is the steering direction, as
  for ``turn``: + steers right, so the rear swings right and the body heading changes by
  -``angle``.

Reversing is a direction sign d(t) = -1 on the time pieces of a ``reverse`` (``RoadProfile.
direction``; it switches only at standstill). s, the distance travelled, keeps increasing; the
road curves (heading psi(s), grade, bank) stay functions of s, so the body attitude is continuous,
and the velocity is d v along the body x axis (see ``kinematics``). The direction lives in time,
not in s, so that a switch falls exactly on the instant the speed profile reaches zero, whatever
the rounding of s(t) there.

Public names
------------
SEGMENT_FIELD, LIMITS_FIELD, REVERSE_SPEED, RoadProfile, build_road_profile.
"""

from __future__ import annotations

import bisect
import functools
import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from simulator.earth import G0_M_S2
from simulator.schema import (
    Context,
    Integer,
    ListOf,
    Number,
    OneKey,
    Path,
    Record,
    Text,
)
from simulator.trajectory.piecewise import PiecewisePolynomial

MAX_GRADE = 0.3  # steepest grade a car is allowed to drive (SPEC section 4)

LIMITS_FIELD = Record(
    {
        "lateral_accel": Number("m/s^2", 0.8 * G0_M_S2, gt=0,
                                doc="largest lateral acceleration a turn may ask for"),
        "grade": Number("", MAX_GRADE, gt=0, max=1.0, doc="steepest grade (rise/run)"),
        "accel": Number("m/s^2", 1.0, gt=0, doc="acceleration used for automatic speed changes"),
        "jerk": Number("m/s^3", 1.5, gt=0, doc="longitudinal jerk of speed changes"),
        "lateral_jerk": Number("m/s^3", 0.5, gt=0, doc="lateral jerk setting clothoid length"),
        "vertical_accel": Number("m/s^2", 0.5, gt=0,
                                 doc="vertical acceleration setting vertical-curve length"),
        "roll_gradient": Number("rad*s^2/m", np.radians(4.0) / G0_M_S2, min=0,
                                doc="body roll per lateral acceleration of a rigid body "
                                    "(vehicle: rigid; 4 deg/g)"),
    },
    default={},
)

_speed = Number("m/s", None, min=0, doc="speed through the segment (default: the current "
                                        "speed; a different one is reached before it)")
REVERSE_SPEED = 2.0  # default peak speed of a ``reverse``, m/s (a parking manoeuvre)
SEGMENT_FIELD = OneKey(
    {
        "stop": Record({"duration": Number("s", gt=0, doc="time standing still (a stop "
                                                         "reached while moving brakes first)")},
                       doc="stand still"),
        "accelerate": Record({"to_speed": Number("m/s", min=0, doc="speed at the end"),
                              "accel": Number("m/s^2", gt=0, doc="peak acceleration "
                                              "(jerk-limited by limits.jerk)")},
                             doc="change speed along a straight road"),
        "straight": Record({"length": Number("m", None, gt=0, doc="length (or give duration)"),
                            "duration": Number("s", None, gt=0,
                                               doc="time at the segment's speed (or give "
                                                   "length)"),
                            "speed": _speed}, doc="a straight level road"),
        "turn": Record({"angle": Number(angle=True, doc="heading change, + to the right"),
                        "radius": Number("m", gt=0, doc="radius of the circular arc between "
                                                        "the transition curves"),
                        "speed": _speed, "bank": Number(default=0.0, angle=True,
                                                        min=-45, max=45,
                                                        doc="road bank, + lowers the right "
                                                            "side")},
                       doc="a level turn entered and left through transition curves"),
        "slope": Record({"grade": Number("", doc="rise over run, + climbs (at most "
                                                 "limits.grade)"),
                         "length": Number("m", gt=0, doc="length of the sloped road"),
                         "speed": _speed},
                        doc="climb or descend at a grade and return to level"),
        "helix": Record({"turns": Number("", gt=0, doc="number of full turns"),
                         "radius": Number("m", gt=0, doc="radius of the helix"),
                         "rise": Number("m", doc="height change, + climbs (met exactly)"),
                         "speed": _speed,
                         "direction": Text("right", choices=["left", "right"],
                                           doc="turning direction"),
                         "bank": Number(default=0.0, angle=True, min=-45, max=45,
                                        doc="road bank, + lowers the right side")},
                        doc="a parking-ramp helix (grade from the rise over the turns)"),
        "speed_bump": Record({"height": Number("m", gt=0, max=0.5, doc="bump height"),
                              "length": Number("m", gt=0, doc="bump length along the road")},
                             doc="a speed bump (a raised-cosine height profile)"),
        "lane_change": Record({"offset": Number("m", doc="lateral offset, + to the right"),
                               "length": Number("m", gt=0, doc="length of the manoeuvre"),
                               "speed": _speed}, doc="move sideways by one lane"),
        "reverse": Record({"length": Number("m", gt=0, doc="distance backed up along the path"),
                           "angle": Number(default=0.0, angle=True,
                                           doc="steering direction and heading change: + "
                                               "steers right, the rear swings right, the "
                                               "heading changes by -angle"),
                           "radius": Number("m", None, gt=0,
                                            doc="arc radius; default: the curve fills length"),
                           "speed": Number("m/s", REVERSE_SPEED, gt=0,
                                           doc="peak reverse speed (magnitude)")}),
    },
    shared={"zone": Text(None, doc="name of the zone the segment lies in (tunnel, garage, "
                                   "parking, underground, underpass: no sky; others: "
                                   "environment.zones)")},
    what="segment",
)

MAX_REPEAT = 1000  # times one ``repeat`` block may be driven
MAX_SEGMENTS = 100_000  # segments of a drive once its repeats are written out

DRIVE_SEGMENT_FIELD = OneKey(
    {**SEGMENT_FIELD.variants,
     "repeat": Record({"times": Integer(min=1, max=MAX_REPEAT,
                                        doc="how many times the block is driven in a row"),
                       "segments": ListOf(SEGMENT_FIELD, min_len=1,
                                          doc="the segments of the block (any kind but repeat)")},
                      doc="drive a block of segments several times in a row (a loop, a protocol "
                          "repeated at the same place); a zone given here applies to the "
                          "block's segments that name none")},
    shared=SEGMENT_FIELD.shared, what="segment")


def expand_repeats(value: dict, path: Path, ctx: Context) -> dict:
    """Write every ``repeat`` block of a validated segment list out in place (post-check of the
    ``segments`` trajectory), so the resolved scenario lists plain segments only."""
    out: list[dict] = []
    for item in value["segments"]:
        (kind, body), = item.items()
        if kind != "repeat":
            out.append(item)
            continue
        block = [item_ if body.get("zone") is None or next(iter(item_.values())).get("zone")
                 else {k: {**v, "zone": body["zone"]} for k, v in item_.items()}
                 for item_ in body["segments"]]
        out.extend(block * body["times"])
    if len(out) > MAX_SEGMENTS:
        return ctx.error(path + ("segments",), f"the repeats write out {len(out)} segments, "
                                               f"more than {MAX_SEGMENTS}")
    return {**value, "segments": out}


@dataclass
class _PathPiece:
    """A stretch of road of ``length`` m; polynomials in local s (highest power first)."""

    length: float
    kappa: np.ndarray
    grade: np.ndarray
    bank: np.ndarray


@dataclass
class _TimePiece:
    """A stretch of time with constant jerk, driven forward (direction +1) or reversing (-1)."""

    duration: float
    jerk: float
    direction: float = 1.0


@dataclass
class RoadProfile:
    """Road geometry along s and the travelled distance in time, as piecewise polynomials."""

    distance_of_time: PiecewisePolynomial  # s(t), m
    curvature: PiecewisePolynomial  # kappa(s), rad/m, + right
    heading: PiecewisePolynomial  # psi(s) - psi0, rad
    grade: PiecewisePolynomial  # gamma(s), rad
    bank: PiecewisePolynomial  # road bank angle (s), rad
    duration_s: float
    zones: list[tuple[float, float, str]] = field(default_factory=list)
    # where the drive starts, for sources that fix it (a SUMO network, a recorded drive):
    # {lat, lon (deg), alt (m), heading (deg)}, replacing the scenario's start; None: use it
    start: dict | None = None
    # d(t): +1 driving forward, -1 reversing, piecewise constant in time, switching only at
    # standstill; None: forward throughout (SUMO and recorded drives)
    direction: PiecewisePolynomial | None = None
    # speed bumps as (start s, length, height), m: their shape is also in ``grade`` (a rigid
    # body rides over it); the vehicle model takes it out there and puts it under the wheels
    bumps: list[tuple[float, float, float]] = field(default_factory=list)
    # True: the car body's side slip lags the path over the rear axle's distance (the kinematic
    # bicycle model, ``simulator.vehicle.body.relaxed_slip``), for a path whose curvature
    # changes within metres (SUMO's junctions); False: the bicycle model's steady state at once
    slip_relaxation: bool = False

    def direction_at(self, t: np.ndarray) -> np.ndarray | float:
        """d(t), +1 forward and -1 reversing, at times t (the scalar 1.0 if never reversing)."""
        if self.direction is None:
            return 1.0
        return self.direction(t)

    def net_distance(self, t: np.ndarray) -> np.ndarray:
        """Signed distance along the body x axis since the start, int_0^t d v dt (m): what a
        wheel odometer with the gear direction counts. Exact: s(t) is re-based at each switch
        of d (the switch times are breaks of d, and the drive stands still at each)."""
        s = self.distance_of_time(t)
        if self.direction is None:
            return s
        x = self.direction.x
        d = self.direction.c[0]
        s_breaks = self.distance_of_time(x)
        base = np.concatenate([[0.0], np.cumsum(d * np.diff(s_breaks))])
        i = self.direction.piece_index(np.asarray(t, dtype=float))
        return base[i] + d[i] * (s - s_breaks[i])


_ZERO = np.zeros(1)


def _poly(*coeffs: float) -> np.ndarray:
    return np.asarray(coeffs, dtype=float)


def _ramp(start: float, end: float, length: float) -> np.ndarray:
    """Smoothstep from ``start`` to ``end`` over ``length``: value and slope continuous at both
    ends, so the rates and accelerations it drives are continuous too. Its mean is the mean of
    the two ends, as for a linear ramp."""
    d = end - start
    return _poly(-2 * d / length**3, 3 * d / length**2, 0.0, start)


def _speed_change(v0: float, v1: float, accel: float, jerk: float) -> list[_TimePiece]:
    """Jerk-limited change of speed: trapezoidal (or triangular) acceleration profile."""
    dv = v1 - v0
    if abs(dv) < 1e-12:
        return []
    sign = np.sign(dv)
    if abs(dv) >= accel**2 / jerk:
        tj, tc = accel / jerk, abs(dv) / accel - accel / jerk
    else:
        tj, tc = np.sqrt(abs(dv) / jerk), 0.0
    pieces = [_TimePiece(tj, sign * jerk), _TimePiece(tc, 0.0), _TimePiece(tj, -sign * jerk)]
    return [p for p in pieces if p.duration > 0]


def _distance_of(pieces: list[_TimePiece], v0: float) -> float:
    s, v, a = 0.0, v0, 0.0
    for p in pieces:
        t, j = p.duration, p.jerk
        s += v * t + a * t**2 / 2 + j * t**3 / 6
        v += a * t + j * t**2 / 2
        a += j * t
    return s


def _clothoid_turn(angle_rad: float, kappa0: float, v: float, lim: dict,
                   bank_rad: float) -> list[_PathPiece]:
    """Clothoid - arc - clothoid with total heading change ``angle_rad`` (sign = direction)."""
    k0, total = abs(kappa0), abs(angle_rad)
    lc = max(v**3 * k0 / lim["lateral_jerk"], 0.5)
    if lc * k0 >= total:  # the two clothoids alone cover the turn: curvature peaks at the apex
        lc = total / k0
    arc = total / k0 - lc
    k = np.sign(angle_rad) * k0
    bank_per_kappa = bank_rad / abs(k) if k else 0.0
    bank = bank_per_kappa * k
    pieces = [_PathPiece(lc, _ramp(0.0, k, lc), _ZERO, _ramp(0.0, bank, lc))]
    if arc > 1e-9:
        pieces.append(_PathPiece(arc, _poly(k), _ZERO, _poly(bank)))
    pieces.append(_PathPiece(lc, _ramp(k, 0.0, lc), _ZERO, _ramp(bank, 0.0, lc)))
    return pieces


def _grade_cuts(pieces: list[_PathPiece], gamma: float, lvc: float
                ) -> list[tuple[float, int, float, np.ndarray]]:
    """The pieces of a grade profile 0 -> gamma (over lvc) -> gamma -> 0 (over lvc) laid over
    path pieces: (length, index of the path piece, offset into it, grade coefficients)."""
    total = sum(p.length for p in pieces)
    ends = list(itertools.accumulate(p.length for p in pieces))
    cuts = sorted({0.0, lvc, total - lvc, total, *ends})
    cuts = [c for c in cuts if 0.0 <= c <= total]
    out, starts = [], [0.0, *ends]
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        if b - a < 1e-9:
            continue
        i = min(bisect.bisect_right(starts, a) - 1, len(pieces) - 1)
        if b <= lvc + 1e-12:
            g = _shift(_ramp(0.0, gamma, lvc), a)
        elif a >= total - lvc - 1e-12:
            g = _shift(_ramp(gamma, 0.0, lvc), a - (total - lvc))
        else:
            g = _poly(gamma)
        out.append((b - a, i, a - starts[i], g))
    return out


def _with_grade(pieces: list[_PathPiece], gamma: float, lvc: float) -> list[_PathPiece]:
    """Overlay a grade profile 0 -> gamma (over lvc) -> gamma -> 0 (over lvc) on path pieces."""
    return [_PathPiece(length, _shift(pieces[i].kappa, off), g, _shift(pieces[i].bank, off))
            for length, i, off, g in _grade_cuts(pieces, gamma, lvc)]


def _shift(coeffs: np.ndarray, offset: float) -> np.ndarray:
    """Coefficients of p(x + offset) given those of p(x) (highest power first).

    Horner's scheme on the polynomial x + offset, in the very operations (and order) of numpy's
    ``Polynomial(c)(Polynomial([offset, 1]))``, trailing zero coefficients trimmed as numpy
    trims them, so the result is bit for bit numpy's; on Python floats, since these polynomials
    have at most six coefficients (numpy's objects cost 50 times more here, and a helix's grade
    is solved with some sixty trial profiles)."""
    if offset == 0.0 or len(coeffs) == 1:
        return coeffs
    c = coeffs.tolist()
    acc = [c[0]]  # p's coefficients so far, lowest power first
    for ci in c[1:]:
        shifted = [a * offset for a in acc] + [0.0]  # acc * (x + offset)
        for j, a in enumerate(acc):
            shifted[j + 1] += a
        _trim(shifted)
        shifted[0] += ci
        acc = _trim(shifted)
    return np.array(acc[::-1])


def _trim(coeffs: list[float]) -> list[float]:
    """Drop trailing zero coefficients (highest powers), keeping one (numpy's ``trimseq``)."""
    while len(coeffs) > 1 and coeffs[-1] == 0.0:
        coeffs.pop()
    return coeffs


def _grade_ramp_length(v: float, gamma: float, lim: dict, available: float) -> float:
    return float(np.clip(v**2 * abs(gamma) / lim["vertical_accel"], 1.0, available / 2))


def _helix(seg: dict, v: float, lim: dict) -> list[_PathPiece]:
    """Path pieces of a helix whose grade meets its ``rise`` exactly."""
    shape = (seg["turns"], seg["radius"], seg["direction"], seg["bank"], v)
    gamma = _helix_grade(*shape, seg["rise"], tuple(sorted(lim.items())))
    turn, lvc = _helix_turn(*shape, lim, gamma)
    return _with_grade(turn, gamma, lvc)


def _helix_turn(turns: float, radius: float, direction: str, bank_deg: float, v: float,
                lim: dict, gamma: float) -> tuple[list[_PathPiece], float]:
    """The level turn of a helix climbing at ``gamma`` (its curvature cos(gamma) / radius, so
    that the radius holds in plan view) and the length of its vertical curves."""
    theta = 2 * np.pi * turns * (1 if direction == "right" else -1)
    kappa0 = np.cos(gamma) / radius
    turn = _clothoid_turn(theta, kappa0, v, lim, np.radians(bank_deg))
    total = sum(p.length for p in turn)
    return turn, _grade_ramp_length(v, gamma, lim, total)


@functools.lru_cache(maxsize=256)
def _helix_grade(turns: float, radius: float, direction: str, bank_deg: float, v: float,
                 rise: float, limits: tuple) -> float:
    """The grade (rad) at which a helix rises ``rise`` (bisection to machine precision). A pure
    function of the helix, its entry speed and the limits, kept for the helices met again (a
    garage's ramps, a campaign's runs)."""
    lim = dict(limits)

    def rise_error(gamma: float) -> float:  # the grade pieces alone, as ``_helix`` lays them
        turn, lvc = _helix_turn(turns, radius, direction, bank_deg, v, lim, gamma)
        cuts = _grade_cuts(turn, gamma, lvc)
        return sum(_rise_of(length, g) for length, _, _, g in cuts) - rise

    if abs(rise) < 1e-9:
        return 0.0
    bound = np.arctan(1.0) * np.sign(rise)
    return _bisect(rise_error, 1e-9 * np.sign(rise), bound)


# 8-point Gauss-Legendre as Python floats: the nodes shifted to [0, 2] (x + 1), the weights
_RISE_GL_NODES, _RISE_GL_WEIGHTS = np.polynomial.legendre.leggauss(8)
_RISE_GL_X1, _RISE_GL_W = (_RISE_GL_NODES + 1).tolist(), _RISE_GL_WEIGHTS.tolist()


def _rise_of(length: float, grade: np.ndarray) -> float:
    """Height gained over a piece of ``length`` with ``grade`` coefficients: integral of
    sin(gamma(s)) ds (Gauss-Legendre, 8 nodes). On Python floats, in the operations and order
    of numpy's polyval, sin and eight-term pairwise sum (the same bits, six times quicker for
    eight nodes)."""
    half = 0.5 * length
    coeffs = grade.tolist()
    terms = []
    for x, w in zip(_RISE_GL_X1, _RISE_GL_W, strict=True):
        s, gamma = half * x, 0.0
        for c in coeffs:
            gamma = gamma * s + c
        terms.append(w * math.sin(gamma))
    t = terms
    return half * (((t[0] + t[1]) + (t[2] + t[3])) + ((t[4] + t[5]) + (t[6] + t[7])))


def _bisect(f, a: float, b: float) -> float:
    """Root of f on [a, b] (f(a), f(b) of opposite signs) to machine precision by bisection
    (a scenario solves a handful of these; scipy.optimize would cost more to import)."""
    fa = f(a)
    if fa * f(b) > 0:
        raise ValueError("the manoeuvre cannot be built with these parameters")
    for _ in range(200):
        m = 0.5 * (a + b)
        if m in (a, b):
            break
        fm = f(m)
        if (fm < 0) == (fa < 0):
            a, fa = m, fm
        else:
            b = m
    return 0.5 * (a + b)


def _speed_bump(height: float, length: float) -> list[_PathPiece]:
    # z = H 64 u^3 (1-u)^3, so dz/ds = 192 H / L u^2 (1-u)^2 (1-2u), u = s / L
    u = np.polynomial.polynomial.Polynomial([0.0, 1.0 / length])
    dz = 192.0 * height / length * u**2 * (1 - u) ** 2 * (1 - 2 * u)
    return [_PathPiece(length, _ZERO, dz.coef[::-1], _ZERO)]


# 16-point Gauss-Legendre on [0, 1] and the heading deflection's shape 140 u^3 (1-u)^3 there
_LANE_GL_X, _LANE_GL_W = np.polynomial.legendre.leggauss(16)
_LANE_U = 0.5 * (_LANE_GL_X + 1)
_LANE_SHAPE = 140.0 * _LANE_U**3 * (1 - _LANE_U) ** 3  # integrates to 1 over [0, 1]


def _lane_change(offset: float, length: float) -> list[_PathPiece]:
    return [_PathPiece(length, _lane_change_curvature(offset, length), _ZERO, _ZERO)]


@functools.cache
def _lane_change_curvature(offset: float, length: float) -> np.ndarray:
    """Curvature coefficients of a lane change (heading c 140 u^3 (1-u)^3, c solved for the
    lateral shift), read-only; cached, since a drive repeats its manoeuvres."""
    def shift(c: float) -> float:
        return float(0.5 * length * np.sum(_LANE_GL_W * np.sin(c * _LANE_SHAPE))) - offset

    c = 0.0 if offset == 0 else _bisect(shift, 0.0, np.sign(offset) * 0.8)
    uu = np.polynomial.polynomial.Polynomial([0.0, 1.0 / length])
    kappa = (420.0 * c / length * uu**2 * (1 - uu) ** 2 * (1 - 2 * uu)).coef[::-1]
    kappa.flags.writeable = False
    return kappa


def _lateral_accel_problem(kind: str, v: float, radius: float, lim: dict) -> str | None:
    a_lat = v**2 / radius
    if a_lat > lim["lateral_accel"] * (1 + 1e-9):
        return (f"the {kind} asks for {a_lat:.2f} m/s^2 of lateral acceleration "
                f"({v:.1f} m/s on a {radius:g} m radius), over limits.lateral_accel = "
                f"{lim['lateral_accel']:.2f} m/s^2; slow down or widen the radius")
    return None


def _curve_length(theta: float, kappa0: float, v: float, lim: dict) -> float:
    return sum(p.length for p in _clothoid_turn(theta, kappa0, v, lim, 0.0))


def _reverse(seg: dict, lim: dict) -> tuple[list[_PathPiece], list[_TimePiece]] | str:
    """Path and time pieces of a ``reverse`` from standstill (time pieces with direction -1),
    or a sentence saying why the car cannot drive it.

    Speed: 0 -> peak -> 0 with the jerk-limited change of ``_speed_change`` at
    ``limits.accel``; the peak is ``speed``, or the speed whose up and down ramps alone cover
    ``length``. Path: the ``turn`` curve (``_clothoid_turn``) of heading change -``angle`` at
    ``radius`` (or at the radius that makes the curve exactly ``length`` long: the curve's
    length falls monotonically with its curvature), then straight for the rest.
    """
    length = seg["length"]

    def ramps(v: float) -> float:
        return 2 * _distance_of(_speed_change(0.0, v, lim["accel"], lim["jerk"]), 0.0)

    v = seg["speed"]
    if ramps(v) > length:
        v = _bisect(lambda vp: ramps(vp) - length, 1e-12, v)
    up = _speed_change(0.0, v, lim["accel"], lim["jerk"])
    cruise = max(length - ramps(v), 0.0) / v
    timing = [_TimePiece(p.duration, p.jerk, -1.0) for p in up]
    timing.append(_TimePiece(cruise, 0.0, -1.0))
    timing += [_TimePiece(p.duration, p.jerk, -1.0)
               for p in _speed_change(v, 0.0, lim["accel"], lim["jerk"])]

    pieces: list[_PathPiece] = []
    theta = -np.radians(seg["angle"])  # + steers right: the rear swings right, the nose left
    if theta != 0.0:
        if seg["radius"] is None:
            k0 = _bisect(lambda k: _curve_length(theta, k, v, lim) - length,
                         abs(theta) / length, 2 * abs(theta) / length)
        else:
            k0 = 1.0 / seg["radius"]
        problem = _lateral_accel_problem("reverse", v, 1.0 / k0, lim)
        if problem:
            return problem
        pieces = _clothoid_turn(theta, k0, v, lim, 0.0)
        curve = sum(p.length for p in pieces)
        if curve > length * (1 + 1e-9):
            return (f"a curve of {seg['angle']:g} deg at a radius of {1 / k0:g} m needs "
                    f"{curve:.2f} m of path, more than length = {length:g} m; lengthen it, "
                    "or leave out radius")
    rest = length - sum(p.length for p in pieces)
    if rest > 1e-9:
        pieces.append(_PathPiece(rest, _ZERO, _ZERO, _ZERO))
    return pieces, timing


def build_road_profile(segments: list[dict], limits: dict, ctx: Context | None = None,
                       path: Path = ("trajectory", "segments")) -> RoadProfile | None:
    """Turn validated segments into a ``RoadProfile``.

    With a ``Context``, every manoeuvre the car cannot drive is reported there (naming its
    segment) and None is returned if there was any; without one, a ValueError is raised.
    """
    path_pieces: list[_PathPiece] = []
    time_pieces: list[_TimePiece] = []
    zones: list[tuple[float, float, str]] = []
    bumps: list[tuple[float, float, float]] = []
    v = 0.0
    t = 0.0
    failed = False

    def fail(i: int, kind: str, message: str) -> None:
        nonlocal failed
        failed = True
        if ctx is None:
            raise ValueError(f"{'.'.join(map(str, path))}.{i}.{kind}: {message}")
        ctx.error(path + (i, kind), message)

    def drive_time(pieces: list[_TimePiece]) -> float:
        return sum(p.duration for p in pieces)

    def change_speed(target: float, accel: float) -> None:
        nonlocal v
        pieces = _speed_change(v, target, accel, limits["jerk"])
        dist = _distance_of(pieces, v)
        if dist > 0:
            path_pieces.append(_PathPiece(dist, _ZERO, _ZERO, _ZERO))
        time_pieces.extend(pieces)
        v = target

    for i, item in enumerate(segments):
        (kind, seg), = item.items()
        t_start = t + 0.0
        n_time = len(time_pieces)
        if seg.get("speed") is not None and kind != "reverse":
            change_speed(seg["speed"], limits["accel"])
        if kind == "stop":
            change_speed(0.0, limits["accel"])
            time_pieces.append(_TimePiece(seg["duration"], 0.0))
        elif kind == "accelerate":
            change_speed(seg["to_speed"], seg["accel"])
        elif kind == "reverse":
            change_speed(0.0, limits["accel"])
            built = _reverse(seg, limits)
            if isinstance(built, str):
                fail(i, kind, built)
                continue
            path_pieces.extend(built[0])
            time_pieces.extend(built[1])
        else:
            if v <= 0.0:
                fail(i, kind, f"the vehicle is standing still here; a {kind} needs speed "
                              "(add an accelerate segment or give speed)")
                continue
            if kind == "straight":
                if (seg["length"] is None) == (seg["duration"] is None):
                    fail(i, kind, "give exactly one of length or duration")
                    continue
                length = seg["length"] if seg["length"] is not None else seg["duration"] * v
                pieces = [_PathPiece(length, _ZERO, _ZERO, _ZERO)]
            elif kind == "turn":
                problem = _lateral_accel_problem("turn", v, seg["radius"], limits)
                if problem:
                    fail(i, kind, problem)
                    continue
                if seg["angle"] == 0:
                    fail(i, kind, "angle must not be zero")
                    continue
                pieces = _clothoid_turn(np.radians(seg["angle"]), 1.0 / seg["radius"], v,
                                        limits, np.radians(seg["bank"]))
            elif kind == "slope":
                if abs(seg["grade"]) > limits["grade"]:
                    fail(i, kind, f"grade {seg['grade']:g} is steeper than limits.grade = "
                                  f"{limits['grade']:g}")
                    continue
                gamma = float(np.arctan(seg["grade"]))
                pieces = _with_grade([_PathPiece(seg["length"], _ZERO, _ZERO, _ZERO)], gamma,
                                     _grade_ramp_length(v, gamma, limits, seg["length"]))
            elif kind == "helix":
                grade = abs(seg["rise"]) / (2 * np.pi * seg["radius"] * seg["turns"])
                problem = _lateral_accel_problem("helix", v, seg["radius"], limits)
                if grade > limits["grade"]:
                    problem = (f"a rise of {seg['rise']:g} m over {seg['turns']:g} turn(s) of "
                               f"radius {seg['radius']:g} m is a grade of {grade:.3f}, steeper "
                               f"than limits.grade = {limits['grade']:g}")
                if problem:
                    fail(i, kind, problem)
                    continue
                pieces = _helix(seg, v, limits)
            elif kind == "speed_bump":
                pieces = _speed_bump(seg["height"], seg["length"])
                bumps.append((sum(p.length for p in path_pieces), seg["length"],
                              seg["height"]))
            else:  # lane_change
                if abs(seg["offset"]) > 0.4 * seg["length"]:
                    fail(i, kind, "offset is too large for the length (at most 0.4 x length)")
                    continue
                pieces = _lane_change(seg["offset"], seg["length"])
            path_pieces.extend(pieces)
            time_pieces.append(_TimePiece(sum(p.length for p in pieces) / v, 0.0))
        t = t_start + drive_time(time_pieces[n_time:])
        if seg.get("zone"):
            zones.append((t_start, t, seg["zone"]))
    if failed:
        return None
    profile = _assemble(path_pieces, time_pieces, zones)
    profile.bumps = bumps
    return profile


def _ppoly(lengths: list[float], polys: list[np.ndarray]) -> PiecewisePolynomial:
    degree = max(len(p) for p in polys)
    c = np.zeros((degree, len(polys)))
    for j, p in enumerate(polys):
        c[degree - len(p):, j] = p
    x = np.concatenate([[0.0], np.cumsum(lengths)])
    return PiecewisePolynomial(c, x)


def _assemble(path_pieces: list[_PathPiece], time_pieces: list[_TimePiece],
              zones: list[tuple[float, float, str]]) -> RoadProfile:
    path_pieces = [p for p in path_pieces if p.length > 1e-9]
    if not path_pieces:
        path_pieces = [_PathPiece(1.0, _ZERO, _ZERO, _ZERO)]
    lengths = [p.length for p in path_pieces]
    curvature = _ppoly(lengths, [p.kappa for p in path_pieces])
    grade = _ppoly(lengths, [p.grade for p in path_pieces])
    bank = _ppoly(lengths, [p.bank for p in path_pieces])

    time_pieces = [p for p in time_pieces if p.duration > 1e-12]
    if not time_pieces:
        raise ValueError("the drive has no duration")
    c = np.zeros((4, len(time_pieces)))
    s = v = a = 0.0
    for j, p in enumerate(time_pieces):
        c[:, j] = [p.jerk / 6, a / 2, v, s]
        tt = p.duration
        s += v * tt + a * tt**2 / 2 + p.jerk * tt**3 / 6
        v += a * tt + p.jerk * tt**2 / 2
        a += p.jerk * tt
    breaks = np.concatenate([[0.0], np.cumsum([p.duration for p in time_pieces])])
    signs = np.array([p.direction for p in time_pieces])
    direction = PiecewisePolynomial(signs[None, :], breaks) if (signs < 0).any() else None
    return RoadProfile(
        distance_of_time=PiecewisePolynomial(c, breaks),
        curvature=curvature,
        heading=curvature.antiderivative(),
        grade=grade,
        bank=bank,
        duration_s=float(breaks[-1]),
        zones=zones,
        direction=direction,
    )

