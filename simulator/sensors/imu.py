"""Inertial measurement unit: the exact body rate and specific force with a per-axis MEMS error
model, sampled as rates or as increments integrated over each sample interval.

Measurement model (Groves 2013, eqs. 4.16-4.17), per group (gyro, accel) in the sensor frame::

    y = x + (S + M) x + b0 + b_in(t) + b_gm(t) + b_rw(t) + k_T dT(t) + G f  (gyro only) + n

* ``x``: the true rate (w_ib, rad/s) or specific force (m/s^2) at the unit, rotated by the
  ``mounting`` (roll, pitch, yaw of the unit in the vehicle, degrees): x_s = C_v^s x_v, with the
  lever-arm terms dw/dt x r + w x (w x r) added to the specific force (Groves eq. 6.43 rearranged;
  dw/dt a central difference, step 1 ms, of the analytic body rate), plus the engine and road
  ``vibration`` of the unit on its mount (``simulator.sensors.vibration``), in the sensor frame.
* ``S + M``: diagonal scale-factor errors and off-diagonal misalignment / cross-axis coupling,
  each drawn once per run, N(0, ``scale_factor``^2) and N(0, ``misalignment``^2).
* ``b0``: turn-on bias, N(0, ``bias``^2) per axis.
* ``bias`` and ``scale_factor`` may instead be given as ``{fixed: value}`` (one number or a
  list of three, any sign): the true value of this run rather than a 1-sigma, for a paper's
  situation that fixes the errors (Cho & Choi 2006, eq. 36:
  ``scale_factor: {fixed: [0.2, 0.1, -0.1]}``). The values in ``drawn`` are then the fixed ones.
* ``b_in``: in-run bias instability B. With ``bias_correlation_time`` tau_c: a first-order
  Gauss-Markov process whose Allan-deviation peak (at 1.89 tau_c) is 0.664 B, i.e. its stationary
  std is 0.664 B / 0.6174; without: a flicker process (sum of Gauss-Markov processes, see
  ``simulator.stochastic``) with the flat Allan floor 0.664 B (IEEE Std 952-1997). Both are
  discretised exactly, so their statistics do not depend on the rate.
* ``b_gm``: a correlated bias besides ``b_in``, so that an axis can have both the flicker floor
  and an exponentially correlated bias, as real MEMS units do (the ADIS16448 y accelerometer's
  Allan curve rises from 2 s to a plateau at 100-300 s above its flicker floor): a first-order
  Gauss-Markov process of stationary std ``gauss_markov_sigma`` and correlation time
  ``gauss_markov_correlation_time`` T_c, both per axis (sigma 0, the default, is off), discretised
  exactly. Its Allan variance is IEEE Std 952's Markov noise
  (``simulator.stochastic.gauss_markov_avar``), peaking at 0.617 sigma at 1.89 T_c.
  El-Sheimy et al. (IEEE Trans. Instrum. Meas. 57(1), 2008) list this correlated noise among the
  error terms of MEMS inertial sensors; it is commonly attributed to temperature variation inside
  the unit.
* ``b_rw``: rate / acceleration random walk of density ``random_walk`` (rad/s^2/sqrt(Hz),
  m/s^3/sqrt(Hz)), starting at zero, plus a rate ramp R t (IEEE Std 952 "rate ramp", Allan
  deviation R tau / sqrt(2)) of magnitude ``ramp`` (rad/s^2, m/s^3) and a drawn sign.
* ``k_T dT``: bias change with temperature; k_T per axis is drawn N(0, ``temperature_coefficient``
  ^2) and dT(t) = offset + warmup (1 - exp(-t / warmup_time)) is the unit's temperature profile
  (``temperature`` block, kelvin from the calibration temperature); the scale factor changes too,
  by s_T dT with s_T drawn N(0, ``scale_factor_temperature_coefficient``^2) (1/K).
* ``G f``: gyro g-sensitivity, a 3 x 3 matrix with elements N(0, ``g_sensitivity``^2),
  rad/s per m/s^2.
* ``n``: white noise of density N: sigma = N sqrt(rate) on rate output and N sqrt(dt) on the
  increment (IEEE Std 952 angle / velocity random walk).

Then the sensor's internal first-order low-pass of corner ``bandwidth`` (Hz; none when unset),
saturation at +-``range`` and quantisation to ``resolution``. Increment output (``output:
increment``) integrates the truth exactly over each interval (anti-aliased, Gauss-Legendre on the
analytic kinematics); its error terms are the rate terms times dt, its saturation limit is
range x dt and its quantum resolution x dt, with the rounding remainder carried to the next
sample as integrating IMUs do (so the summed increments are exact to one quantum).
Rate output (``output: rate``) is by default the interval mean (``rate_sampling:
interval_mean``): the exact increment over (t - 1/rate, t] divided by 1/rate, as a unit whose
output filter averages over the sample interval delivers it. This is a moving-average
(sinc-shaped) anti-aliasing filter: content above the Nyquist frequency (a speed bump's jolt at
100 Hz) no longer folds into the samples, and the group delay it adds is exactly half a sample
(the mean of a linear signal over the interval is its value at t - 1/(2 rate)). The interval of
the sample at t = 0 reaches before the drive, where the truth holds its starting state; the
vibration is averaged over the interval too, and the white noise keeps sigma = N sqrt(rate), the
interval mean of white noise of density N. ``rate_sampling: point`` is the truth at t (for tests
of the error terms against the analytic truth; it aliases). A datasheet ``bandwidth`` low-pass
applies on top of either.
``timestamp_jitter`` (1-sigma, s) samples the truth at t + e while the sample is stamped t (for
increments: the interval ends move by e, to first order in e). On increment output the lever-arm
term integrates to dw x r + the integral of w x (w x r) (the cubic rule on the truth grid,
else three-point Gauss-Legendre).

Every parameter of a group is one number for all three axes or a list of three (x, y, z).
Misalignment is 1-sigma, a small angle in rad (strings such as "0.1 deg" or "1 mrad" accepted).
``axes`` lists the channels the unit has, or names a reduced unit of the seeds: ``riss3d``
(Karamat 2015: vertical gyro, forward and lateral accelerometers), ``drm1`` (Cho 2006: two
accelerometers and a yaw gyro) and ``drm2`` (Cho 2006: forward accelerometer, pitch and yaw gyros).
The drawn values (turn-on biases, scale factors, misalignment and g-sensitivity matrices,
temperature coefficients) are in ``drawn``; the true bias b0 + b_in + b_gm + b_rw + ramp + k_T dT
(rad/s, m/s^2, white noise excluded) and diagonal scale-factor error s + s_T dT of every axis over
time, at about ``TRUE_ERROR_RATE_HZ``, are in ``true_errors`` (written to truth_sensors.parquet;
misalignment and g-sensitivity are constant and stay in ``drawn``). The ``ideal`` preset turns
every error off: its rate output is the interval mean of the truth (with ``rate_sampling:
point``, the truth sampled at the IMU rate) and its increment output the exact integral.

Public names
------------
IMU_FIELD, REDUCED_UNITS, Imu.

References
----------
Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed.,
2013, section 4.4 (eqs. 4.16-4.17). IEEE Std 952-1997, Annex C.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Executor, Future
from dataclasses import dataclass
from typing import Any

import numpy as np

from simulator import columns as col
from simulator.earth import euler_to_dcm
from simulator.schema import (
    INVALID,
    Context,
    Either,
    Field,
    ListOf,
    Number,
    Path,
    Record,
    Text,
    Vector,
)
from simulator.sensors.base import (
    TEMPERATURE_FIELD,
    TRUE_ERROR_RATE_HZ,
    grid_index,
    grid_rows,
    integrate_over_samples,
    sample_times,
    temperature_change_k,
    truth_at,
)
from simulator.sensors.imu_presets import IMU_PRESETS
from simulator.sensors.presets import fill_from_preset, known_preset
from simulator.sensors.vibration import VIBRATION_FIELD, draw_vibration, vibration_at_speed
from simulator.stochastic import (
    FLICKER_ADEV_FACTOR,
    GM_ADEV_PEAK,
    ar1_filter,
    flicker,
    gauss_markov,
    random_walk,
    white,
)
from simulator.tables import ColumnTable
from simulator.trajectory.kinematics import Kinematics
from simulator.trajectory.quadrature import GL_NODES, GL_WEIGHTS, cubic_interval_integrals

REDUCED_UNITS = {
    "full": list(col.IMU_AXES),
    "riss3d": ["gyro_z", "accel_x", "accel_y"],
    "drm1": ["gyro_z", "accel_x", "accel_y"],
    "drm2": ["gyro_y", "gyro_z", "accel_x"],
}
_LEVER_ARM_STEP_S = 1e-3  # central-difference step for the angular acceleration, s


class AxisNumber(Field):
    """One number for all three axes, or a list of three (x, y, z), in ``unit``."""

    def __init__(self, unit: str, default: Any = None, doc: str = "", **limits: float):
        super().__init__(default, doc)
        self.number = Number(unit, **limits)
        self.vector = Vector(3, self.number)

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        if isinstance(value, (list, tuple)):
            return self.vector.check(value, path, ctx)
        return self.number.check(value, path, ctx)


class DrawnOrFixed(Field):
    """A per-run constant given as its 1-sigma (``AxisNumber``, drawn N(0, sigma^2) per axis) or
    as ``{fixed: value}``, the true value itself (one number or three, any sign), for a paper's
    situation that fixes it (Cho & Choi 2006, eq. 36: scale factors 0.2, 0.1, -0.1)."""

    def __init__(self, unit: str, doc: str = ""):
        super().__init__(None, doc)
        self.sigma = AxisNumber(unit, min=0)
        self.fixed = Record({"fixed": AxisNumber(unit)})

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        if isinstance(value, dict):
            return self.fixed.check(value, path, ctx)
        return self.sigma.check(value, path, ctx)


def _constant(value: float | list[float] | dict | None, rng: np.random.Generator) -> np.ndarray:
    """A group's per-axis constant: drawn N(0, sigma^2), or the ``fixed`` value. The normal
    draw is taken either way, so fixing one constant leaves every other draw unchanged."""
    draw = rng.standard_normal(3)
    if isinstance(value, dict):
        return _per_axis(value["fixed"]).copy()
    return _per_axis(value) * draw


def _group_fields(unit: str, random_walk_unit: str, gyro: bool) -> dict[str, Field]:
    fields: dict[str, Field] = {
        "bias": DrawnOrFixed(unit, doc="turn-on bias, 1-sigma, drawn once per run"),
        "bias_instability": AxisNumber(unit, min=0, doc="bias instability B (Allan floor "
                                                        "0.664 B), IEEE Std 952"),
        "bias_correlation_time": Number("s", None, gt=0, doc="with it, the instability is a "
                                        "Gauss-Markov bias; without, a flicker bias"),
        "gauss_markov_sigma": AxisNumber(unit, min=0, doc="stationary std of an extra "
                                                          "Gauss-Markov bias"),
        "gauss_markov_correlation_time": AxisNumber("s", min=0,
                                                    doc="its correlation time"),
        "noise_density": AxisNumber(f"{unit}/sqrt(Hz)", min=0,
                                    doc="white noise density (angle / velocity random walk)"),
        "random_walk": AxisNumber(random_walk_unit, min=0, doc="bias random walk density"),
        "ramp": AxisNumber(f"{unit}/s", min=0, doc="rate ramp, drawn sign"),
        "scale_factor": DrawnOrFixed("1", doc="scale-factor error, 1-sigma, drawn once"),
        "misalignment": AxisNumber("rad", min=0, doc="axis misalignment / cross-coupling, "
                                                     "1-sigma"),
        "range": AxisNumber(unit, gt=0, doc="saturation limit"),
        "resolution": AxisNumber(unit, min=0, doc="quantisation step"),
        "temperature_coefficient": AxisNumber(f"{unit}/K", min=0,
                                              doc="bias change per kelvin, 1-sigma"),
        "scale_factor_temperature_coefficient": AxisNumber(
            "1/K", min=0, doc="scale-factor change per kelvin, 1-sigma"),
        "bandwidth": AxisNumber("Hz", gt=0, doc="first-order low-pass cut-off"),
    }
    if gyro:
        fields["g_sensitivity"] = Number("rad/s/(m/s^2)", None, min=0,
                                         doc="gyro bias per specific force, 1-sigma")
    return fields


_GROUPS = {
    "gyro": _group_fields("rad/s", "rad/s^2/sqrt(Hz)", gyro=True),
    "accel": _group_fields("m/s^2", "m/s^3/sqrt(Hz)", gyro=False),
}
# keys whose absence means "no such term" rather than zero
_UNSET_IS_NONE = {"bias_correlation_time": None, "range": None, "bandwidth": None}


def _resolve(value: dict, path: Path, ctx: Context) -> dict:
    """Merge the preset into the resolved block (explicit values win) and expand ``axes``."""
    if not known_preset(value["preset"], IMU_PRESETS, "IMU", path, ctx):
        return INVALID
    preset = IMU_PRESETS[value["preset"]]
    out = fill_from_preset(value, preset, {"rate": IMU_FIELD.fields["rate"],
                                           "output": IMU_FIELD.fields["output"]},
                           path, ctx, {"rate": 100.0, "output": "rate"})
    if out is INVALID:
        return INVALID
    for group, fields in _GROUPS.items():
        out[group] = fill_from_preset(value[group] or {}, preset.get(group, {}), fields,
                                      path + (group,), ctx, _UNSET_IS_NONE)
        if out[group] is INVALID:
            return INVALID
    axes = value["axes"]
    out["axes"] = list(REDUCED_UNITS[axes]) if isinstance(axes, str) else axes
    failed = False
    for group in _GROUPS:
        limit, res = out[group]["range"], out[group]["resolution"]
        if limit is not None and np.any(np.asarray(res) >= np.asarray(limit)):
            ctx.error(path + (group, "resolution"), "must be smaller than range")
            failed = True
        markov = _per_axis(out[group]["gauss_markov_sigma"])
        if np.any((markov > 0) & (_per_axis(out[group]["gauss_markov_correlation_time"]) <= 0)):
            ctx.error(path + (group, "gauss_markov_correlation_time"),
                      "must be above 0 on every axis whose gauss_markov_sigma is")
            failed = True
    return INVALID if failed else out


IMU_FIELD = Record(
    {
        "preset": Text("ideal", doc="named parameter set; 'ideal' turns every error off"),
        "rate": Number("Hz", None, gt=0, max=10000, doc="sample rate (default: the preset's, "
                                                        "else 100 Hz)"),
        "output": Text(None, choices=["rate", "increment"],
                       doc="rates (rad/s, m/s^2) or increments over each sample (rad, m/s)"),
        "rate_sampling": Text("interval_mean", choices=["interval_mean", "point"],
                              doc="rate output: the mean over each sample interval (t - 1/rate, "
                                  "t], anti-aliased, half a sample late) or the truth at t "
                                  "(aliases content above the Nyquist frequency)"),
        "axes": Either(Text(choices=list(REDUCED_UNITS)),
                       ListOf(Text(choices=list(col.IMU_AXES)), min_len=1), default="full",
                       doc="channels of the unit, or a reduced unit: " + ", ".join(REDUCED_UNITS)),
        "lever_arm": Vector(3, Number("m"), [0.0, 0.0, 0.0],
                            doc="position of the unit from the vehicle reference point, FRD"),
        "mounting": Vector(3, Number(angle=True), [0.0, 0.0, 0.0],
                           doc="roll, pitch, yaw of the unit in the vehicle"),
        "timestamp_jitter": Number("s", 0.0, min=0, doc="1-sigma sampling-time error"),
        "temperature": TEMPERATURE_FIELD,
        "vibration": VIBRATION_FIELD,
        "gyro": Record(_GROUPS["gyro"], default=None),
        "accel": Record(_GROUPS["accel"], default=None),
    },
    default=None,
    post=_resolve,
)


def _per_axis(value: float | list[float] | None) -> np.ndarray:
    return np.broadcast_to(np.asarray(0.0 if value is None else value, dtype=float), (3,))


class Imu:
    """An IMU built from its resolved scenario block (``sensors.imu``)."""

    name = "imu"

    def __init__(self, config: dict):
        """``config``: the resolved ``sensors.imu`` block (``simulator.sensors.resolve_block``
        completes one built by hand)."""
        self.config = config
        self.rate_hz = float(self.config["rate"])
        self.increment = self.config["output"] == "increment"
        # the truth integrated over each interval: increments, and rates as interval means
        self.integrated = self.increment or self.config["rate_sampling"] == "interval_mean"
        self.drawn: dict = {"preset": self.config["preset"]}
        # column (columns.SENSOR_ERRORS) -> (t, true value), filled by ``generate``
        self.truth_keys: dict[str, float] = {}  # every key is a datasheet figure
        self.true_errors: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._prepared: _Draws | None = None

    def timing(self) -> dict[str, dict]:
        """Point rates are sampled at their stamp; increments and interval-mean rates cover
        (t - 1/rate, t], stamped at its end (their mean is half a sample behind). A
        ``bandwidth`` low-pass delays the signal by about 1/(2 pi bandwidth) at low frequencies
        (first-order filter)."""
        bandwidth = [self.config[g]["bandwidth"] for g in ("gyro", "accel")]
        delay = max((1.0 / (2 * np.pi * min(np.atleast_1d(b))) for b in bandwidth
                     if b is not None), default=0.0)
        if self.integrated:
            return {"imu": {"stamp": "the end of the integration interval (t - 1/rate, t]",
                            "delay_s": 0.5 / self.rate_hz + delay}}
        return {"imu": {"stamp": "the sampling instant", "delay_s": delay}}

    # -- the random part, drawn before the truth exists ---------------------------------------
    def prepare(self, duration_s: float, rng: np.random.Generator | None,
                pool: Executor | None = None) -> None:
        """Draw every random term that does not depend on the trajectory: each group's constants,
        bias processes and white noise, the timestamp jitter and the vibration noise.

        Needs only the drive's duration, so the dataset generator calls it before the truth is
        built, with its ``pool``: the groups and the vibration are then drawn in worker threads
        while the truth is computed. ``generate`` calls it itself when it has not been called.
        ``rng`` is split into one stream per part (timing, vibration, gyro, accel), so the draws
        do not depend on the threads, and switching one term on leaves the others unchanged.
        """
        rng = rng if rng is not None else np.random.default_rng()
        timing, shaking, *groups = rng.spawn(4)
        t = sample_times(duration_s, self.rate_hz, first=1 if self.increment else 0)
        dt = 1.0 / self.rate_hz
        run = pool.submit if pool is not None else _run_now
        jitter = float(self.config["timestamp_jitter"])
        # increments: the interval ends t - dt and t move; rates: the sampling instant moves
        size = len(t) + 1 if self.integrated else len(t)
        time_error = jitter * timing.standard_normal(size) if jitter > 0 else None
        vib = self.config["vibration"]
        shake = None
        if any(vib[k] > 0 for k in ("engine_accel", "engine_gyro", "road_accel", "road_gyro")):
            shake = run(draw_vibration, t, dt, vib, self.integrated, shaking)
        self._prepared = _Draws(duration_s, t, time_error, shake,
                                {group: run(self._draw_group, group, t, stream)
                                 for group, stream in zip(("gyro", "accel"), groups,
                                                          strict=True)}, run)

    def _draw_group(self, group: str, t: np.ndarray, rng: np.random.Generator) -> _GroupDraws:
        """One group's drawn constants and its additive error b(t) x (1 or dt) + n (white)."""
        p = self.config[group]
        n = len(t)
        dt = 1.0 / self.rate_hz
        bias0 = _constant(p["bias"], rng)
        sf = _constant(p["scale_factor"], rng)
        mis = _per_axis(p["misalignment"])[:, None] * rng.standard_normal((3, 3))
        np.fill_diagonal(mis, 0.0)
        k_temp = _per_axis(p["temperature_coefficient"]) * rng.standard_normal(3)
        k_sf_temp = _per_axis(p["scale_factor_temperature_coefficient"]) * rng.standard_normal(3)
        ramp = _per_axis(p["ramp"]) * rng.choice([-1.0, 1.0], size=3) + 0.0  # no -0.0
        g_matrix = (float(p["g_sensitivity"]) * rng.standard_normal((3, 3))
                    if group == "gyro" else None)
        drawn = {"bias": bias0.tolist(), "scale_factor": sf.tolist(),
                 "misalignment": mis.tolist(), "temperature_coefficient": k_temp.tolist(),
                 "scale_factor_temperature_coefficient": k_sf_temp.tolist(),
                 "ramp": ramp.tolist()}
        if g_matrix is not None:
            drawn["g_sensitivity"] = g_matrix.tolist()
        d_temp = temperature_change_k(self.config["temperature"], t)
        processes = []  # the random processes of the bias, each (n, 3)
        instability = _per_axis(p["bias_instability"])
        if instability.any():
            if p["bias_correlation_time"]:
                sigma = FLICKER_ADEV_FACTOR * instability / GM_ADEV_PEAK
                processes.append(gauss_markov(n, dt, sigma, p["bias_correlation_time"], rng))
            else:
                processes.append(flicker(n, dt, instability, rng))
        markov = _per_axis(p["gauss_markov_sigma"])
        if markov.any():
            corr_time = np.where(markov > 0, _per_axis(p["gauss_markov_correlation_time"]), 1.0)
            processes.append(gauss_markov(n, dt, markov, corr_time, rng))
        walk = _per_axis(p["random_walk"])
        if walk.any():
            processes.append(random_walk(n, dt, walk, rng))
        # summed in place into the first process (the additions are the only full passes)
        additive = processes[0] if processes else np.zeros((n, 3))
        for process in processes[1:]:
            additive += process
        additive += bias0
        if ramp.any():
            additive += np.multiply.outer(t, ramp)
        if k_temp.any():
            additive += np.multiply.outer(d_temp, k_temp)
        # the true bias and scale-factor error over time, before the white noise, at about
        # TRUE_ERROR_RATE_HZ (every ``step``-th sample) for truth_sensors.parquet
        step = max(1, round(self.rate_hz / TRUE_ERROR_RATE_HZ))
        true_scale = np.broadcast_to(sf, (len(t[::step]), 3))
        if k_sf_temp.any():
            true_scale = true_scale + np.multiply.outer(d_temp[::step], k_sf_temp)
        truth = {"t": t[::step], "bias": additive[::step].copy(), "scale_factor": true_scale}
        if self.increment:
            additive *= dt  # rate terms -> increment terms
        density = _per_axis(p["noise_density"])
        if density.any():
            additive += white(n, dt, density, rng, increment=self.increment)
        return _GroupDraws(drawn, np.eye(3) + np.diag(sf) + mis,
                           d_temp[:, None] * k_sf_temp if k_sf_temp.any() else None,
                           additive, g_matrix if g_matrix is not None and g_matrix.any() else None,
                           truth)

    # -- truth at the unit ------------------------------------------------------------------
    def _true_values(self, truth: Kinematics, t: np.ndarray,
                     time_error: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        """True rate and specific force (or their increments) at the unit, sensor frame."""
        dt = 1.0 / self.rate_hz
        lever = np.asarray(self.config["lever_arm"], dtype=float)
        if self.integrated:
            k = _integrate(truth, t, dt)
            w, f = k["w_body"], k["f_body"]
            if time_error is not None or lever.any():
                ends = truth_at(truth, np.concatenate([[t[0] - dt], t]))
            if time_error is not None:
                # interval (t - dt + e0, t + e1]: to first order in e, the exact increment plus
                # x(t) e1 - x(t - dt) e0
                e = time_error[:, None]
                w = w + ends["w_body"][1:] * e[1:] - ends["w_body"][:-1] * e[:-1]
                f = f + ends["f_body"][1:] * e[1:] - ends["f_body"][:-1] * e[:-1]
            if lever.any():
                dw = np.diff(ends["w_body"], axis=0)
                f = f + np.cross(dw, lever) + _centripetal_increment(truth, t, dt, lever)
            if not self.increment:  # the interval mean
                w, f = w / dt, f / dt
        else:
            t_true = t + time_error if time_error is not None else t
            k = truth_at(truth, t_true)
            w, f = k["w_body"], k["f_body"]
            if lever.any():
                h = _LEVER_ARM_STEP_S
                dw = (truth.inertial(t_true + h)["w_body"]
                      - truth.inertial(t_true - h)["w_body"]) / (2 * h)
                f = f + np.cross(dw, lever) + _centripetal(w, lever)
        mount = self.config["mounting"]
        if any(mount):
            c_sv = euler_to_dcm(*np.radians(mount)).T
            w, f = w @ c_sv.T, f @ c_sv.T
        return w, f

    # -- errors -----------------------------------------------------------------------------
    def _apply_errors(self, group: str, x: np.ndarray, f_true: np.ndarray,
                      draws: _GroupDraws) -> np.ndarray:
        """The group's output for the true values x (n, 3): scale factor, misalignment,
        g-sensitivity, the drawn additive errors, then low-pass, saturation and quantisation."""
        p = self.config[group]
        scale = 1.0 / self.rate_hz if self.increment else 1.0
        y = x @ draws.gain.T
        if draws.sf_temperature is not None:
            y += x * draws.sf_temperature
        y += draws.additive
        if draws.g_matrix is not None:
            y += f_true @ draws.g_matrix.T
        if p["bandwidth"] is not None:
            y = _low_pass(y, _per_axis(p["bandwidth"]), 1.0 / self.rate_hz)
        if p["range"] is not None:
            limit = _per_axis(p["range"]) * scale
            np.minimum(y, limit, out=y)  # np.clip does the same at twice the cost
            np.maximum(y, -limit, out=y)
        quantum = _per_axis(p["resolution"]) * scale
        if quantum.any():
            q = np.where(quantum > 0, quantum, 1.0)
            if self.increment:
                counts = np.cumsum(y, axis=0)
                counts /= q
                stepped = np.diff(np.round(counts, out=counts), axis=0, prepend=0.0)
            else:
                stepped = y / q
                np.round(stepped, out=stepped)
            stepped *= q
            y = stepped if quantum.all() else np.where(quantum > 0, stepped, y)
        self.drawn[group] = draws.drawn
        for i, axis in enumerate("xyz"):
            if f"{group}_{axis}" in self.config["axes"]:
                for kind in ("bias", "scale_factor"):
                    self.true_errors[f"{group}_{kind}_{axis}"] = (draws.truth["t"],
                                                                  draws.truth[kind][:, i])
        return y

    def generate(self, truth: Kinematics,
                 rng: np.random.Generator | None) -> dict[str, ColumnTable]:
        """The ``imu`` stream. ``rng`` may be None only for a unit without random terms (the
        ideal unit): a fresh generator then makes the (zero-size) draws. Uses the draws of an
        earlier ``prepare`` for the same duration, else draws them now."""
        if self._prepared is None or self._prepared.duration_s != truth.duration_s:
            self.prepare(truth.duration_s, rng)
        draws, self._prepared = self._prepared, None
        t = draws.t
        w, f = self._true_values(truth, t, draws.time_error)
        if draws.vibration is not None:
            dt = 1.0 / self.rate_hz
            t_speed = t - dt / 2 if self.integrated else t
            speed = np.maximum(truth.profile.distance_of_time(np.clip(t_speed, 0, None), 1), 0)
            shaking = vibration_at_speed(draws.vibration.result(), speed, dt,
                                         self.config["vibration"], self.integrated)
            if self.integrated and not self.increment:  # the interval mean
                shaking = {k: v / dt if v is not None else None for k, v in shaking.items()}
            if shaking["gyro"] is not None:
                w = np.add(shaking["gyro"], w, out=shaking["gyro"])
            if shaking["accel"] is not None:
                f = np.add(shaking["accel"], f, out=shaking["accel"])
        # the gyro group in the pool (behind its draws) while this thread does the accel group
        gyro_job = draws.submit(lambda: self._apply_errors("gyro", w, f,
                                                           draws.groups["gyro"].result()))
        accel = self._apply_errors("accel", f, f, draws.groups["accel"].result())
        gyro = gyro_job.result()
        table = {"t": t}
        for i, axis in enumerate(col.IMU_AXES):
            if axis in self.config["axes"]:
                table[axis] = (gyro if i < 3 else accel)[:, i % 3]
        return {"imu": table}


@dataclass
class _GroupDraws:
    """One group's random terms: the ``drawn`` record, I + S + M, the temperature change of the
    scale factor per sample (or None), the additive errors (n, 3) and the g-sensitivity matrix
    (or None)."""

    drawn: dict
    gain: np.ndarray
    sf_temperature: np.ndarray | None
    additive: np.ndarray
    g_matrix: np.ndarray | None
    truth: dict[str, np.ndarray]  # t, bias (rate units) and scale_factor, decimated, (m, 3)


@dataclass
class _Draws:
    """What ``Imu.prepare`` drew for a drive of ``duration_s``: the vibration and the groups as
    futures (done at once without a pool), and how to run more work (the pool's ``submit``,
    which must still be open when ``generate`` runs)."""

    duration_s: float
    t: np.ndarray
    time_error: np.ndarray | None
    vibration: Future | None
    groups: dict[str, Future]
    submit: Callable[..., Future]


def _run_now(function: Callable, *args: Any) -> Future:
    """``function(*args)`` run now, as a finished future (``prepare`` without a pool)."""
    done: Future = Future()
    done.set_result(function(*args))
    return done


def _low_pass(y: np.ndarray, bandwidth_hz: np.ndarray, dt_s: float) -> np.ndarray:
    """First-order low-pass y[k] = a y[k-1] + (1 - a) x[k], a = exp(-2 pi f_c dt), per column,
    started in steady state on the first sample (the sensor's internal digital filter). Filters
    ``y`` in place."""
    a = np.exp(-2 * np.pi * np.asarray(bandwidth_hz, dtype=float) * dt_s)
    y[0] /= 1 - a  # (1 - a) x[0] + a y[-1] with y[-1] = x[0]: the first output is x[0]
    return ar1_filter(y, a, overwrite=True, gain_in=1 - a)


def _integrate(truth: Kinematics, t_end: np.ndarray, dt_s: float) -> dict[str, np.ndarray]:
    """``integrate_over_samples`` over (t - dt, t] for every t; an interval reaching before the
    drive's start (the rate sample at t = 0) is integrated apart, so the others stay on the
    truth's grid (the fast cubic rule). Before t = 0 the truth holds its starting state."""
    if len(t_end) < 2 or t_end[0] >= dt_s - 1e-12:
        return integrate_over_samples(truth, t_end, dt_s)
    head = integrate_over_samples(truth, t_end[:1], dt_s)
    rest = integrate_over_samples(truth, t_end[1:], dt_s)
    return {key: np.concatenate([head[key], rest[key]]) for key in rest}


def _centripetal(w: np.ndarray, lever_arm: np.ndarray) -> np.ndarray:
    """w x (w x r) = w (w . r) - r |w|^2, rows of w (n, 3)."""
    return (w @ lever_arm)[:, None] * w - np.einsum("ij,ij->i", w, w)[:, None] * lever_arm


def _centripetal_increment(truth: Kinematics, t_end: np.ndarray, dt_s: float,
                           lever_arm: np.ndarray) -> np.ndarray:
    """Integral of w x (w x r) over each interval (t - dt, t]: the cubic rule on the truth's
    cached grid when the intervals are its grid intervals, three-point Gauss-Legendre
    otherwise."""
    k = grid_index(truth, t_end)
    if (k is not None and abs(dt_s * truth.rate_hz - 1.0) < 1e-12 and k.min() >= 1
            and len(truth.t_grid) >= 4):
        centripetal = _centripetal(truth.grid_inertial()["w_body"], lever_arm)
        return cubic_interval_integrals(centripetal, dt_s)[grid_rows(k - 1)]
    nodes = (t_end - dt_s)[:, None] + dt_s * GL_NODES[None, :]
    centripetal = _centripetal(truth.inertial(nodes.ravel())["w_body"], lever_arm)
    return dt_s * np.einsum("j,njk->nk", GL_WEIGHTS,
                            centripetal.reshape(len(t_end), len(GL_NODES), 3))
