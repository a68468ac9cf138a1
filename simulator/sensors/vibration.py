"""Vehicle vibration sensed by an IMU: an engine line at a fixed frequency and speed-dependent road
vibration with a band-limited spectrum. Zero-mean motion of the unit on its mount, so it is added
to what the IMU senses, not to the truth trajectory.

* engine: on every axis a sinusoid of rms ``engine_accel`` (m/s^2) / ``engine_gyro`` (rad/s) at
  ``engine_frequency`` (a four-cylinder engine idling at 750 rpm fires at 25 Hz) with a random
  phase per axis; increments integrate it exactly;
* road: white noise band-passed to ``road_band`` [low, high] Hz (a flat spectrum there, cut at
  the Nyquist frequency of the sample rate) with rms ``road_accel`` / ``road_gyro`` at
  ``road_speed``, scaled in proportion to the vehicle speed, so zero at standstill; increments
  take the sample value times dt.

Public names
------------
VIBRATION_FIELD, DrawnVibration, draw_vibration, vibration_at_speed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simulator.schema import INVALID, Context, Number, Path, Record, Vector


def _check(value: dict, path: Path, ctx: Context) -> dict:
    low, high = value["road_band"]
    if low >= high:
        ctx.error(path + ("road_band",), "the low edge must be below the high edge")
        return INVALID
    return value


VIBRATION_FIELD = Record(
    {
        "engine_frequency": Number("Hz", 25.0, gt=0, doc="engine vibration frequency"),
        "engine_accel": Number("m/s^2", 0.0, min=0, doc="engine vibration, rms per axis"),
        "engine_gyro": Number("rad/s", 0.0, min=0, doc="engine angular vibration, rms per axis"),
        "road_band": Vector(2, Number("Hz", gt=0), [5.0, 30.0],
                            doc="band of the road vibration spectrum"),
        "road_accel": Number("m/s^2", 0.0, min=0, doc="road vibration at road_speed, rms"),
        "road_gyro": Number("rad/s", 0.0, min=0, doc="road angular vibration at road_speed"),
        "road_speed": Number("m/s", 10.0, gt=0, doc="speed the road rms values refer to"),
    },
    default={},
    post=_check,
)


def _engine_basis(t: np.ndarray, freq_hz: float, dt_s: float,
                  increment: bool) -> tuple[np.ndarray, np.ndarray, float]:
    """sin(theta), cos(theta) and the amplitude per unit rms of the engine line: theta = w t on
    rate output; on increments theta = w (t - dt / 2) and the amplitude of the integral over
    each interval (t - dt, t], (2 sqrt(2) / w) sin(w dt / 2). Shared by both groups."""
    w = 2 * np.pi * freq_hz
    if increment:
        theta = w * (t - dt_s / 2)
        gain = 2 * np.sqrt(2.0) / w * np.sin(w * dt_s / 2)
    else:
        theta = w * t
        gain = np.sqrt(2.0)
    return np.sin(theta), np.cos(theta), gain


def _road(n: int, rms: float, band_hz: list[float], dt_s: float,
          rng: np.random.Generator) -> np.ndarray | None:
    """Band-limited white noise of rms ``rms``, shape (n, 3), single precision (None when no
    frequency of the band is below the Nyquist frequency): its spectrum drawn directly in the
    frequency domain (the real FFT of n unit normals has independent N(0, n/2) real and
    imaginary parts per bin, the Nyquist bin real N(0, n)) and transformed back. Single
    precision is 2.5 times quicker and half the memory: a noise realisation rounded to 6e-8 of
    its rms, far below any sensor's resolution."""
    freq = np.fft.rfftfreq(n, dt_s)
    keep = np.flatnonzero((freq >= band_hz[0]) & (freq <= band_hz[1]))
    if not len(keep):
        return None
    band = slice(keep[0], keep[-1] + 1)  # the band is one run of bins
    draws = rng.standard_normal((2, len(keep), 3))
    spectrum = np.zeros((3, len(freq)), dtype=np.complex64)
    spectrum.real[:, band] = draws[0].T
    spectrum.imag[:, band] = draws[1].T
    if n % 2 == 0 and keep[-1] == len(freq) - 1:  # the Nyquist bin is real
        spectrum[:, -1] = np.sqrt(2.0) * draws[0, -1]
    fraction = len(keep) / len(freq)  # share of the white variance inside the band
    road = np.fft.irfft(spectrum, n, axis=1)
    road *= rms * np.sqrt(n / 2.0 / fraction)
    return road.T


@dataclass
class DrawnVibration:
    """The random part of the vibration (``draw_vibration``): the engine line's sine and cosine
    (None without an engine term), and per group ("gyro", "accel") the engine amplitudes along
    them (shape (2, 3), None when off) and the road vibration at ``road_speed`` (shape (n, 3),
    single precision, None when off)."""

    sin_theta: np.ndarray | None
    cos_theta: np.ndarray | None
    engine: dict[str, np.ndarray | None]
    road: dict[str, np.ndarray | None]


def draw_vibration(t: np.ndarray, dt_s: float, config: dict, increment: bool,
                   rng: np.random.Generator) -> DrawnVibration:
    """The random part of the vibration, which needs no trajectory: the engine line's drawn
    phases (a sine of amplitude rms sqrt(2) per axis, or its integral over each interval,
    written as sin(theta) cos(phase) + cos(theta) sin(phase), so that one sine and one cosine
    serve every axis of both groups) and the road vibration at ``road_speed``.

    ``vibration_at_speed`` adds them up once the speed is known.
    """
    c = config
    sin_theta = cos_theta = None
    engine: dict[str, np.ndarray | None] = {}
    road: dict[str, np.ndarray | None] = {}
    for group, engine_rms, road_rms in (("gyro", c["engine_gyro"], c["road_gyro"]),
                                        ("accel", c["engine_accel"], c["road_accel"])):
        engine[group] = road[group] = None
        if engine_rms > 0:
            if sin_theta is None:
                sin_theta, cos_theta, gain = _engine_basis(t, c["engine_frequency"], dt_s,
                                                           increment)
            phase = rng.uniform(0.0, 2 * np.pi, 3)
            engine[group] = engine_rms * gain * np.stack([np.cos(phase), np.sin(phase)])
        if road_rms > 0:
            road[group] = _road(len(t), road_rms, c["road_band"], dt_s, rng)
    return DrawnVibration(sin_theta, cos_theta, engine, road)


def vibration_at_speed(drawn: DrawnVibration, speed: np.ndarray, dt_s: float, config: dict,
                       increment: bool) -> dict[str, np.ndarray | None]:
    """Angular-rate ("gyro") and specific-force ("accel") vibration (or their increments), body
    frame, shape (n, 3) each (None for a group without vibration): the engine term plus the road
    term scaled by speed / ``road_speed`` (``speed`` at the samples, m/s, shape (n,))."""
    road_scale = (speed * ((dt_s if increment else 1.0) / config["road_speed"]))[:, None]
    out: dict[str, np.ndarray | None] = {}
    for group in ("gyro", "accel"):
        engine, road = drawn.engine[group], drawn.road[group]
        total = None
        if engine is not None:
            total = drawn.sin_theta[:, None] * engine[0]
            total += drawn.cos_theta[:, None] * engine[1]
        if road is not None:
            scaled = road * road_scale
            total = scaled if total is None else np.add(total, scaled, out=total)
        out[group] = total
    return out
