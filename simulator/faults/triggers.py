"""When a fault acts: its trigger, turned into time intervals of the drive.

A fault entry has exactly one trigger:

* ``start`` + ``duration`` (s since the scenario start);
* ``zone``: every stretch the drive spends in that zone;
* ``distance: [from, to]``: the stretch between two travelled distances (m);
* ``random: {rate, duration, min_gap}``: a Poisson process of ``rate`` events per hour of
  driving, each lasting a duration drawn from ``{distribution: fixed|uniform|exponential,
  mean|min|max}``; intervals never overlap (a draw that would overlap the previous one starts
  after it, ``min_gap`` later).

Public names
------------
TRIGGER_FIELDS, trigger_problems, fault_intervals.
"""

from __future__ import annotations

import numpy as np

from simulator.schema import Context, Number, Path, Record, Text, Vector

_DURATION_DISTRIBUTION = Record({
    "distribution": Text("fixed", choices=["fixed", "uniform", "exponential"],
                         doc="how each event's duration is drawn"),
    "mean": Number("s", None, gt=0, doc="fixed value, or mean of the exponential"),
    "min": Number("s", None, min=0, doc="uniform: shortest"),
    "max": Number("s", None, gt=0, doc="uniform: longest"),
})

TRIGGER_FIELDS = {
    "start": Number("s", None, min=0, doc="start time, s since the scenario start"),
    "duration": Number("s", None, gt=0, doc="length of the fault, s"),
    "zone": Text(None, doc="act over every stretch in this zone"),
    "distance": Vector(2, Number("m", min=0), None, doc="[from, to] travelled distance, m"),
    "random": Record({
        "rate": Number("1/s", gt=0, doc="events per unit time (\"3 /h\", or per second)"),
        "duration": _DURATION_DISTRIBUTION,
        "min_gap": Number("s", 1.0, min=0, doc="least time between two events"),
    }, default=None, doc="random events over the whole drive (a Poisson process of `rate`, "
                         "durations drawn from `duration`)"),
}


def _given(fault: dict) -> list[str]:
    names = ["start", "zone", "distance", "random"]
    return [n for n in names if fault.get(n) is not None]


def trigger_problems(fault: dict, path: Path, ctx: Context, duration_s: float,
                     zones: set[str], length_m: float | None = None) -> None:
    """Report a fault whose trigger is missing, ambiguous, outside the drive (in time, or
    beyond the ``length_m`` travelled), or names a zone that no stretch of the drive has."""
    given = _given(fault)
    if len(given) != 1:
        ctx.error(path, "give exactly one trigger: start (+ duration), zone, distance or random"
                  f" (given: {', '.join(given) or 'none'})")
        return
    trigger = given[0]
    if trigger == "start":
        if fault.get("duration") is None:
            ctx.error(path + ("duration",), "a fault with a start needs a duration")
        elif fault["start"] + fault["duration"] > duration_s + 1e-9:
            ctx.error(path + ("duration",), f"the window {fault['start']:g} s + "
                      f"{fault['duration']:g} s ends after the drive ({duration_s:.1f} s)")
    elif fault.get("duration") is not None:
        ctx.error(path + ("duration",), f"duration goes with start, not with {trigger}")
    if trigger == "zone" and fault["zone"] not in zones:
        ctx.error(path + ("zone",), f"no stretch of the drive is in zone {fault['zone']!r} "
                  f"(zones: {', '.join(sorted(zones)) or 'none'})")
    if trigger == "distance":
        lo, hi = fault["distance"]
        if hi <= lo:
            ctx.error(path + ("distance",), "the range must increase: [from, to]")
        elif length_m is not None and lo >= length_m:
            ctx.error(path + ("distance",), f"starts at {lo:g} m, beyond the drive's end "
                      f"({length_m:.1f} m travelled)")
    if trigger == "random":
        expected = fault["random"]["rate"] * duration_s
        if expected > MAX_RANDOM_EVENTS:
            ctx.error(path + ("random", "rate"),
                      f"{fault['random']['rate']:.3g} events/s over the {duration_s:.1f} s drive "
                      f"is about {expected:.3g} events, more than one fault may draw "
                      f"({MAX_RANDOM_EVENTS:,}); lower the rate (e.g. \"30 /h\") or use a "
                      "start/duration window")
        dist = fault["random"]["duration"]
        kind = dist["distribution"]
        if kind in ("fixed", "exponential") and dist["mean"] is None:
            ctx.error(path + ("random", "duration", "mean"), f"a {kind} duration needs mean")
        if kind == "uniform" and (dist["min"] is None or dist["max"] is None
                                  or dist["max"] <= dist["min"]):
            ctx.error(path + ("random", "duration"), "a uniform duration needs min < max")


# events one random fault may draw over a drive (each is a row of the events table and an
# interval every stream is masked with); a fault every second of a 28 h drive is 100 800
MAX_RANDOM_EVENTS = 200_000


def fault_intervals(fault: dict, truth, rng: np.random.Generator) -> list[tuple[float, float]]:
    """The time intervals [t_start, t_end) over which a validated fault acts.

    Parameters
    ----------
    fault : dict
        The resolved fault entry.
    truth : simulator.trajectory.kinematics.Kinematics
        The drive (for zones, distances and its duration).
    rng : numpy.random.Generator
        The fault's own random stream (used by ``random`` triggers only).
    """
    end = truth.duration_s
    if fault.get("start") is not None:
        return [(fault["start"], fault["start"] + fault["duration"])]
    if fault.get("zone") is not None:
        return [(a, b) for a, b, name in truth.profile.zones if name == fault["zone"]]
    if fault.get("distance") is not None:
        lo, hi = fault["distance"]
        t = truth.t_grid
        s = truth.profile.distance_of_time(t)
        inside = np.flatnonzero((s >= lo) & (s < hi))
        if len(inside) == 0:
            return []
        return [(float(t[inside[0]]), float(min(t[inside[-1]] + 1 / truth.rate_hz, end)))]
    return _random_intervals(fault["random"], end, rng)


def _random_intervals(spec: dict, end: float, rng: np.random.Generator
                      ) -> list[tuple[float, float]]:
    count = rng.poisson(spec["rate"] * end)
    starts = np.sort(rng.uniform(0.0, end, count))
    dist = spec["duration"]
    if dist["distribution"] == "fixed":
        lengths = np.full(count, dist["mean"])
    elif dist["distribution"] == "uniform":
        lengths = rng.uniform(dist["min"], dist["max"], count)
    else:
        lengths = rng.exponential(dist["mean"], count)
    out: list[tuple[float, float]] = []
    free_from = 0.0
    for start, length in zip(starts, lengths, strict=True):
        start = max(start, free_from)
        if start >= end:
            break
        stop = min(start + length, end)
        out.append((float(start), float(stop)))
        free_from = stop + spec["min_gap"]
    return out
