"""Trajectory kind ``sumo``: a drive through a SUMO road network, simulated in-process with
libsumo among other traffic, then fitted into a smooth ``RoadProfile``.

The scenario block::

    trajectory:
      kind: sumo
      network: city.net.xml                 # or .osm / .xodr, {netgenerate: {...}},
                                            # {nodes: x.nod.xml, edges: x.edg.xml}
      route: {edges: [a, b, c]}             # or {from: a, to: c, via: [b]}, or {length: 5000}
      traffic: {vehicles: 50}
      step_length: 0.1
      ego: {accel: 2.6, decel: 2.0, max_speed: 20.0, sigma: 0.5}

How it runs: the network is prepared (``sumo_network``), SUMO starts through libsumo with
continuous lane changes (``--lanechange.duration``, so a lane change is a smooth lateral move,
not a jump) and no teleporting; the ego vehicle departs at rest at the start of its route's first
edge, is followed until it arrives and stops at the end of its last edge (or until
``max_duration``). Each step reads only the ego's 3-D
position, lane and lane position (one subscription). ``traffic.vehicles`` other cars drive random
trips. Everything random (trips, SUMO's driver imperfection) follows ``trajectory.seed``, not the
scenario seed, so a Monte Carlo campaign over seeds keeps the same drive.

Braking: the ego's ``decel`` defaults to a comfortable 2.0 m/s^2 (SUMO's passenger default, 4.5,
is a hard stop), and SUMO's ``--tls.yellow.min-decel`` is set to it, so a driver who would have
to brake harder than that for a yellow light drives on, as a driver does. Without it SUMO brakes
for yellow at up to 3 m/s^2 whatever ``decel`` says: on the shipped city grid 13 % of the moving
time braked harder than 2.5 m/s^2 (real drives: about 1 %), 0.06 % with it (issue 13). A
network built by netgenerate has its yellow lights timed for that deceleration too
(``sumo_network.yellow_time``, ITE's change interval: 4.5 s at 13.9 m/s and 2 m/s^2, 5 s in
whole seconds, instead of 3 s), so a driver is not caught between the stop line and red.

Placement: a georeferenced network (OSM) keeps its true latitude and longitude through its
projection; a network without georeference (netgenerate, plain XML, most .net.xml and OpenDRIVE
files) has its origin (x = y = 0) placed at the scenario's ``start`` lat/lon. Heights are
``start.alt`` plus the network's z. The start heading is the road's: the scenario's
``start.heading`` is ignored, and the truth starts where the ego does (``RoadProfile.start``).

SUMO runs are cached by content (like the networks), so ``landnav validate`` followed by
``landnav generate`` simulates once.

Public names
------------
SUMO_FIELD, FIT_FIELD, SumoDrive, RouteError, run_sumo, place_drive, build_sumo_profile.

References
----------
SUMO documentation, "TraCI/Interfacing TraCI from Python", "Libsumo", "Simulation/Randomness",
"Simulation/SublaneModel" (lanechange.duration), https://sumo.dlr.de/docs/.
"""

from __future__ import annotations

import contextlib
import difflib
import json
import os
import sys
import tempfile
import threading
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from simulator.earth import ecef_to_geodetic, ned_to_ecef
from simulator.schema import Context, Integer, ListOf, Number, Record, Text
from simulator.trajectory.fit import (
    LocalFrame,
    fit_drive,
    local_frame,
    start_block,
    zone_intervals,
)
from simulator.trajectory.segments import RoadProfile
from simulator.trajectory.sumo_network import (
    NETWORK_FIELD,
    Network,
    NetworkError,
    cache_dir,
    prepare_network,
)

FIT_FIELD = Record({
    "knot_spacing": Number("m", 3.0, min=2.0, max=100.0,
                           doc="smallest knot spacing of the path splines (larger: smoother)"),
    "knot_time": Number("s", 0.4, min=0, max=10.0,
                        doc="knots at least this much travel time apart"),
    "time_window": Number("s", 0.5, gt=0, max=10.0,
                          doc="half-width of the kernel smoothing the distance in time"),
    "min_radius": Number("m", 4.5, min=0, max=100.0,
                         doc="tightest turn of the car's centre of gravity: the path is widened "
                             "where SUMO turns tighter (a mid-size car at full lock); 0: none"),
}, default={})

SUMO_FIELD = Record({
    "network": NETWORK_FIELD,
    "route": Record({
        "edges": ListOf(Text(), None, min_len=1, doc="explicit, connected edge list"),
        "from": Text(None, doc="first edge; SUMO finds the fastest route to 'to'"),
        "to": Text(None, doc="last edge"),
        "via": ListOf(Text(), [], doc="edges to pass between from and to"),
        "length": Number("m", None, gt=0, doc="a random trip at least this long"),
    }),
    "traffic": Record({"vehicles": Integer(0, min=0, max=5000,
                                           doc="other vehicles on random trips")}, default={}),
    "step_length": Number("s", 0.1, gt=0, max=1.0, doc="SUMO step"),
    "ego": Record({
        "accel": Number("m/s^2", 2.6, gt=0, max=10.0, doc="largest acceleration"),
        "decel": Number("m/s^2", 2.0, gt=0, max=10.0,
                        doc="comfortable deceleration (SUMO's decel; also the hardest braking "
                            "for a yellow light, tls.yellow.min-decel, and the deceleration a "
                            "generated network's yellow lights are timed for)"),
        "max_speed": Number("m/s", 33.3, gt=0, max=70.0, doc="top speed"),
        "sigma": Number("", 0.5, min=0, max=1, doc="driver imperfection (Krauss sigma)"),
    }, default={}),
    "initial_stop": Number("s", 0.0, min=0, doc="standstill before the ego departs"),
    "max_duration": Number("s", 3600.0, gt=0, max=86400.0, doc="end of the drive at the latest"),
    "seed": Integer(0, min=0, max=2**31 - 1, doc="seed of SUMO and of the random trips"),
    "fit": FIT_FIELD,
    "rate": Number("Hz", None, gt=0, max=10000,
                   doc="base rate of the truth table (default: the IMU rate, or 100 Hz)"),
})

_RUN_VERSION = "3"  # part of the run cache key: change it when the simulation set-up changes
_SUMO_LOCK = threading.Lock()  # libsumo is one simulation per process
_LANE_CHANGE_S = 3.0  # duration of a lane change, s (continuous lateral motion)


class RouteError(Exception):
    """A route that cannot be driven; ``key`` names the scenario key under ``route``."""

    def __init__(self, key: tuple, message: str):
        super().__init__(message)
        self.key = key


@dataclass
class SumoDrive:
    """The ego vehicle's samples from SUMO: time (s), network position (m, shape (n, 3)) and
    zone name per sample ('' outside zones)."""

    t: np.ndarray
    xyz: np.ndarray
    zone: np.ndarray


def run_sumo(traj: dict, network: Network) -> SumoDrive:
    """Simulate the drive of a validated ``sumo`` trajectory block (cached by content).

    Raises
    ------
    RouteError
        Unknown edges, unconnected edges, no route.
    NetworkError
        SUMO cannot load the network or fails while running.
    """
    key = _run_key(traj, network)
    cached = cache_dir() / f"run-{key}.npz"
    if cached.is_file():
        with np.load(cached, allow_pickle=False) as z:
            return SumoDrive(z["t"], z["xyz"], z["zone"].astype(object))
    drive = _simulate(traj, network)
    fd, tmp = tempfile.mkstemp(dir=cache_dir(), suffix=".npz")
    os.close(fd)
    np.savez(tmp, t=drive.t, xyz=drive.xyz, zone=drive.zone.astype(str))
    os.replace(tmp, cached)
    return drive


def _run_key(traj: dict, network: Network) -> str:
    import hashlib  # imported where used (as in sumo_network)

    digest = hashlib.sha256(_RUN_VERSION.encode() + network.path.read_bytes())
    block = {k: traj[k] for k in ("route", "traffic", "step_length", "ego", "initial_stop",
                                  "max_duration", "seed")}
    digest.update(json.dumps(block, sort_keys=True).encode())
    digest.update(json.dumps(sorted(network.zones.items())).encode())
    import sumo

    digest.update(str(sumo.SUMO_HOME).encode())
    return digest.hexdigest()[:24]


def _simulate(traj: dict, network: Network) -> SumoDrive:
    if not _SUMO_LOCK.acquire(blocking=False):
        raise RuntimeError("a SUMO simulation is already running in this process "
                           "(libsumo allows one at a time)")
    try:
        os.environ.setdefault("LIBSUMO_AS_TRACI", "quiet")  # no pyarrow-version banner
        import libsumo

        with _sumo_messages() as messages:
            try:
                libsumo.start(["sumo", "--net-file", str(network.path),
                               "--step-length", repr(traj["step_length"]),
                               "--seed", str(traj["seed"]), "--no-step-log", "true",
                               "--no-warnings", "true", "--time-to-teleport", "-1",
                               "--lanechange.duration", repr(_LANE_CHANGE_S),
                               "--collision.action", "warn",
                               "--tls.yellow.min-decel", repr(traj["ego"]["decel"])])
            except Exception as exc:  # libsumo raises its own exception types
                raise NetworkError(("network",), "SUMO cannot load the network: "
                                   f"{messages() or exc}") from None
            try:
                return _drive(libsumo, traj, network)
            except libsumo.TraCIException as exc:
                raise NetworkError(("network",), "SUMO failed during the drive: "
                                   f"{messages() or exc}") from None
            finally:
                libsumo.close()
    finally:
        _SUMO_LOCK.release()


@contextlib.contextmanager
def _sumo_messages():
    """Capture what SUMO's C++ core writes to stderr (file descriptor 2) while it runs; yields
    a function returning its error lines joined (so they end up in one clear message)."""
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile(mode="w+b") as log:
        os.dup2(log.fileno(), 2)

        def errors() -> str:
            log.seek(0)
            lines = log.read().decode(errors="replace").splitlines()
            return "; ".join(ln.strip().removeprefix("Error: ").rstrip(".") for ln in lines
                             if ln.startswith("Error"))[:500]

        try:
            yield errors
        finally:
            os.dup2(saved, 2)
            os.close(saved)


def _drive(sumo, traj: dict, network: Network) -> SumoDrive:
    rng = np.random.default_rng(traj["seed"])
    edges = sorted(e for e in sumo.edge.getIDList() if not e.startswith(":"))
    ego = traj["ego"]
    sumo.vehicletype.copy("DEFAULT_VEHTYPE", "ego_type")
    sumo.vehicletype.setAccel("ego_type", ego["accel"])
    sumo.vehicletype.setDecel("ego_type", ego["decel"])
    sumo.vehicletype.setMaxSpeed("ego_type", ego["max_speed"])
    sumo.vehicletype.setImperfection("ego_type", ego["sigma"])
    route = _ego_route(sumo, traj["route"], edges, rng)
    sumo.route.add("ego_route", route)
    sumo.vehicle.add("ego", "ego_route", typeID="ego_type", depart="0", departLane="best",
                     departPos="base", departSpeed="0", arrivalSpeed="0")
    length = max(2000.0, _route_length(sumo, route))
    for i in range(traj["traffic"]["vehicles"]):
        trip = _random_trip(sumo, edges, length, rng)
        if trip:
            sumo.route.add(f"r{i}", trip)
            sumo.vehicle.add(f"v{i}", f"r{i}", depart="0", departLane="best",
                             departPos="random", departSpeed="max")
    c = sumo.constants
    sumo.vehicle.subscribe("ego", [c.VAR_POSITION3D, c.VAR_LANE_ID, c.VAR_LANEPOSITION])
    dt = traj["step_length"]
    n_max = int(np.ceil(traj["max_duration"] / dt))
    t, pos, lanes, lane_pos = [], [], [], []
    for k in range(1, n_max + 1):
        sumo.simulationStep()
        got = sumo.vehicle.getSubscriptionResults("ego")
        if not got:
            if t:
                break  # arrived
            if k * dt > 600.0:
                raise RouteError((), "the ego vehicle could not enter the network in 10 minutes "
                                     "(its first edge stays blocked)")
            continue
        t.append(k * dt)
        pos.append(got[c.VAR_POSITION3D])
        lanes.append(got[c.VAR_LANE_ID])
        lane_pos.append(got[c.VAR_LANEPOSITION])
    lane_len = {lane: sumo.lane.getLength(lane) for lane in set(lanes)}
    t_arr = np.asarray(t)
    xyz = np.asarray(pos, dtype=float)
    if traj["initial_stop"] > 0:
        t_arr = np.concatenate([[t_arr[0] - traj["initial_stop"]], t_arr])
        xyz = np.vstack([xyz[:1], xyz])
        lanes, lane_pos = lanes[:1] + lanes, lane_pos[:1] + lane_pos
    zone = _zone_per_sample(network, lanes, np.asarray(lane_pos), lane_len)
    return SumoDrive(t_arr - t_arr[0], xyz, zone)


def _check_edges(names: list[str], edges: list[str], key: tuple, listed: bool) -> None:
    known = set(edges)
    for i, name in enumerate(names):
        if name not in known:
            close = difflib.get_close_matches(name, edges, n=3)
            hint = f" (did you mean {', '.join(close)}?)" if close else ""
            raise RouteError(key + ((i,) if listed else ()),
                             f"edge {name!r} does not exist in the network{hint}")


def _find(sumo, a: str, b: str) -> list[str]:
    return list(sumo.simulation.findRoute(a, b, vType="ego_type").edges)


def _ego_route(sumo, spec: dict, edges: list[str], rng: np.random.Generator) -> list[str]:
    forms = [k for k in ("edges", "from", "length") if spec.get(k) is not None]
    if len(forms) != 1 or (spec.get("from") is None) != (spec.get("to") is None):
        raise RouteError((), "give exactly one route form: edges: [...], from: and to: "
                             "(optionally via:), or length:")
    if spec.get("edges") is not None:
        route = spec["edges"]
        _check_edges(route, edges, ("edges",), True)
        for i, (a, b) in enumerate(zip(route[:-1], route[1:], strict=True)):
            if _find(sumo, a, b) != [a, b]:
                raise RouteError(("edges", i + 1), f"edge {b!r} does not follow edge {a!r}: "
                                                   "the two are not connected")
        return list(route)
    if spec.get("from") is not None:
        stops = [spec["from"], *spec["via"], spec["to"]]
        _check_edges([spec["from"]], edges, ("from",), False)
        _check_edges(spec["via"], edges, ("via",), True)
        _check_edges([spec["to"]], edges, ("to",), False)
        route = [stops[0]]
        for a, b in zip(stops[:-1], stops[1:], strict=True):
            leg = _find(sumo, a, b)
            if not leg:
                raise RouteError(("to",), f"there is no route from edge {a!r} to edge {b!r}")
            route += leg[1:]
        return route
    trip = _random_trip(sumo, edges, spec["length"], rng, no_uturn=True)
    if not trip:
        raise RouteError(("length",), "no random trip could be found in this network")
    return trip


def _route_length(sumo, route: list[str]) -> float:
    return float(sum(sumo.lane.getLength(f"{e}_0") for e in route))


def _random_trip(sumo, edges: list[str], length: float, rng: np.random.Generator,
                 no_uturn: bool = False, starts: int = 20, tries: int = 20) -> list[str]:
    """A chain of fastest routes between random edges, at least ``length`` m long if the
    network allows (else the longest found; [] when there is no route at all). A chain that
    gets stuck (a dead end) starts again from another edge. With ``no_uturn``, legs that turn
    back onto the reverse edge (a U-turn of a few metres radius in SUMO) are skipped."""
    best: list[str] = []
    for _ in range(starts):
        here = edges[rng.integers(len(edges))]
        trip, total, fails = [here], 0.0, 0
        while total < length and fails < tries:
            there = edges[rng.integers(len(edges))]
            leg = sumo.simulation.findRoute(here, there) if there != here else None
            if leg is None or len(leg.edges) < 2 or (
                    no_uturn and _has_uturn(sumo, [trip[-1], *leg.edges[1:]])):
                fails += 1
                continue
            trip += list(leg.edges)[1:]
            total += leg.length
            here, fails = there, 0
        if total >= length:
            return trip
        best = max(best, trip, key=len)
    return best if len(best) > 1 else []


def _has_uturn(sumo, route: list[str]) -> bool:
    ends = [(sumo.edge.getFromJunction(e), sumo.edge.getToJunction(e)) for e in route]
    return any(a == d and b == c for (a, b), (c, d) in zip(ends[:-1], ends[1:], strict=True))


def _zone_per_sample(network: Network, lanes: list[str], lane_pos: np.ndarray,
                     lane_len: dict[str, float]) -> np.ndarray:
    """Zone name of every sample; junction-internal samples between two stretches of the same
    zone belong to it (a tunnel does not open at a junction inside it)."""
    zone = np.full(len(lanes), "", dtype=object)
    if not network.zones:
        return zone
    lane_arr = np.asarray(lanes, dtype=object)
    edge_arr = np.array([lane.rsplit("_", 1)[0] for lane in lanes], dtype=object)
    frac = lane_pos / np.array([max(lane_len[lane], 1e-9) for lane in lanes])
    for edge, stretches in network.zones.items():
        on = edge_arr == edge
        for lo, hi, name in stretches:
            zone[on & (frac >= lo) & (frac <= hi)] = name
    internal = np.array([lane.startswith(":") for lane in lane_arr])
    idx = np.arange(len(zone))
    valid = ~internal
    prev = np.maximum.accumulate(np.where(valid, idx, -1))
    nxt = np.minimum.accumulate(np.where(valid, idx, len(zone))[::-1])[::-1]
    inside = internal & (prev >= 0) & (nxt < len(zone))
    before = zone[np.clip(prev, 0, len(zone) - 1)]
    after = zone[np.clip(nxt, 0, len(zone) - 1)]
    fill = inside & (before == after) & (before != "")
    zone[fill] = before[fill]
    return zone


def place_drive(xyz: np.ndarray, network: Network, start: dict) -> LocalFrame:
    """Network positions (n, 3) to the fit's local frame.

    x, y go to latitude and longitude through the network's projection, or, without one, as
    east and north on the tangent plane at ``start``; the height is ``start.alt`` + z.
    """
    if network.georeferenced:
        lon, lat = network.to_lonlat(xyz[:, :2])
        lat, lon = np.radians(lat), np.radians(lon)
    else:
        ned = np.stack([xyz[:, 1], xyz[:, 0], np.zeros(len(xyz))], axis=-1)
        lat, lon, _ = ecef_to_geodetic(ned_to_ecef(ned, np.radians(start["lat"]),
                                                   np.radians(start["lon"]), start["alt"]))
    return local_frame(lat, lon, start["alt"] + xyz[:, 2])


def _resolve_paths(traj: dict, base: Path) -> None:
    """Make the network's file paths absolute, so the resolved scenario works from anywhere."""
    net = traj["network"]
    if isinstance(net, str):
        traj["network"] = str((base / net).resolve())
    else:
        for k in ("nodes", "edges", "connections"):
            if net.get(k):
                net[k] = str((base / net[k]).resolve())


SUMO_PACKAGES = ("sumo", "libsumo", "sumolib")  # of the extra: pip install -e '.[sumo]'


def _require_sumo() -> None:
    """Refuse a SUMO drive, with what to install, when SUMO is not installed (it is an extra:
    almost half of a full installation)."""
    import importlib.util

    missing = [name for name in SUMO_PACKAGES if importlib.util.find_spec(name) is None]
    if missing:
        raise NetworkError((), "a SUMO drive needs SUMO, an optional part of landnav "
                           f"({', '.join(missing)} not installed): pip install -e '.[sumo]' in "
                           "the checkout, or pip install 'landnav[sumo]'")


def _max_curvature(min_radius_m: float) -> float:
    """The fit's curvature limit (1/m) of ``fit.min_radius`` (0: none)."""
    return 1.0 / min_radius_m if min_radius_m > 0 else 0.0


def build_sumo_profile(scenario: dict, ctx: Context | None) -> RoadProfile | None:
    """The ``PROFILE_BUILDERS`` entry of kind ``sumo`` (see the module docstring).

    With a ``Context``, problems are reported there (under ``trajectory.*``) and None returned;
    without one, a ValueError is raised.
    """
    traj = scenario["trajectory"]
    base = Path(ctx.file).resolve().parent if ctx is not None else Path.cwd()
    try:
        _require_sumo()
        _resolve_paths(traj, base)
        network = prepare_network(traj["network"], base, traj["ego"]["decel"])
        drive = run_sumo(traj, network)
        frame = place_drive(drive.xyz, network, scenario["start"])
        fitted = fit_drive(drive.t, frame.enu, traj["fit"]["knot_spacing"],
                           traj["fit"]["time_window"], traj["fit"]["knot_time"],
                           zones=zone_intervals(drive.t, drive.zone),
                           convergence=frame.convergence,
                           max_curvature=_max_curvature(traj["fit"]["min_radius"]))
    except (NetworkError, RouteError) as exc:
        key = ("trajectory",) + (exc.key if isinstance(exc, NetworkError)
                                 else ("route",) + exc.key)
        if ctx is None:
            raise ValueError(f"{'.'.join(map(str, key))}: {exc}") from None
        ctx.error(key, str(exc))
        return None
    except ValueError as exc:
        if ctx is None:
            raise ValueError(f"trajectory: {exc}") from None
        ctx.error(("trajectory",), str(exc))
        return None
    fitted.profile.start = start_block(frame, fitted)
    fitted.profile.slip_relaxation = True  # SUMO turns at junctions within a few metres
    return fitted.profile
