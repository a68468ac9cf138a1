"""SUMO road networks for the ``sumo`` trajectory source: where a network comes from, how it is
built (``netgenerate``, ``netconvert`` of the ``eclipse-sumo`` package), its georeference, and
which stretches of it are zones (tunnels, garages).

Network sources (``trajectory.network``):

* a path to a ``.net.xml`` (used as is), an OpenStreetMap ``.osm`` file (netconvert with
  ``--osm.elevation`` and the ``tunnel``, ``bridge``, ``layer``, ``covered`` tags kept as edge
  parameters) or an OpenDRIVE ``.xodr`` file (netconvert with position-based edge ids, so the
  OpenDRIVE ``<tunnel>`` records can be mapped back onto edges);
* ``{netgenerate: {type: grid|spider|random, ...}}``;
* ``{nodes: FILE.nod.xml, edges: FILE.edg.xml}`` plain XML (``z`` on nodes and in edge shapes is
  kept; coordinates are not shifted).

Networks built here have no turnarounds (``--no-turnarounds``): SUMO drives a turnaround as a
U-turn of half a lane width in radius, which no car can follow and which would put a yaw-rate
spike of several rad/s into the truth. They also limit junction speeds to an average lateral
acceleration of 2.5 m/s^2 (SUMO's default, 5.5, gives peaks over 1 g in tight turns).

Built networks are cached by content (inputs, options and SUMO version) under
``$LANDNAV_CACHE`` (default: ``landnav-cache`` in the system temporary folder), so validating and
then generating a scenario converts the network once.

Zones: an edge is in zone NAME when it has the parameter ``zone=NAME``, an OSM tag
``tunnel=yes|building_passage|culvert`` (zone ``tunnel``) or ``covered=yes`` (``underpass``), or
an edge type containing ``tunnel``/``garage``; an OpenDRIVE ``<tunnel s= length=>`` marks that
part of its road. Zone names apply through the environment's zone settings.

Public names
------------
NETWORK_FIELD, NETGENERATE_FIELD, Network, NetworkError, prepare_network, sumo_binary, cache_dir,
yellow_time.

References
----------
SUMO documentation: netgenerate, netconvert (OpenStreetMap, OpenDRIVE, PlainXML import),
"Networks/SUMO Road Networks" (the ``location`` element), https://sumo.dlr.de/docs/.
ASAM OpenDRIVE 1.6, section 13.3 (tunnels).
"""

from __future__ import annotations

import math
import os
import re
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from simulator.errors import not_regular
from simulator.schema import Boolean, Either, Integer, Number, Record, Text

if TYPE_CHECKING:
    import xml.etree.ElementTree as ET

NETGENERATE_FIELD = Record({
    "type": Text("grid", choices=["grid", "spider", "random"], doc="kind of network"),
    "number": Integer(4, min=2, max=50, doc="grid: junctions in each direction"),
    "length": Number("m", 200.0, gt=10, doc="grid: street length"),
    "arms": Integer(6, min=3, max=30, doc="spider: number of arms"),
    "circles": Integer(3, min=1, max=30, doc="spider: number of circles"),
    "radius": Number("m", 150.0, gt=10, doc="spider: distance between circles"),
    "iterations": Integer(60, min=1, max=10000, doc="random: edges added"),
    "lanes": Integer(1, min=1, max=6, doc="lanes per direction"),
    "speed": Number("m/s", 13.89, gt=0, doc="speed limit of every street"),
    "traffic_lights": Boolean(True, doc="junctions controlled by traffic lights"),
    "junction_radius": Number("m", 10.0, gt=0, max=100.0, doc="turning radius at junctions"),
    "seed": Integer(1, min=0, doc="random: seed of the generator"),
})

NETWORK_FIELD = Either(
    Text(doc="path of a .net.xml, .osm or .xodr file, relative to the scenario file"),
    Record({
        "netgenerate": Record(NETGENERATE_FIELD.fields, default=None),
        "nodes": Text(None, doc="plain-XML nodes file (.nod.xml)"),
        "edges": Text(None, doc="plain-XML edges file (.edg.xml)"),
        "connections": Text(None, doc="plain-XML connections file (.con.xml), optional"),
    }),
)

# SUMO's default junction speed limit (5.5 m/s^2 average lateral acceleration) lets cars take
# 10 m radius turns at over 1 g peak; 2.5 m/s^2 average keeps the peak near 0.6 g
_TURN_SPEED = "--junctions.limit-turn-speed=2.5"
# perception-reaction time of the yellow interval (ITE's kinematic formula, ``yellow_time``), s
YELLOW_REACTION_S = 1.0
_TUNNEL_TAGS = {"yes", "building_passage", "culvert", "avalanche_protector"}
_ZONE_WORDS = ("tunnel", "garage", "parking", "underground")


def sumo_binary(name: str) -> str:
    """Path of a SUMO executable shipped in the ``eclipse-sumo`` package."""
    import sumo

    return os.path.join(sumo.SUMO_HOME, "bin", name)


def _sumo_version() -> str:
    import sumo

    return getattr(sumo, "__version__", "") or str(sumo.SUMO_HOME)


def cache_dir() -> Path:
    """The folder of built networks and cached SUMO runs."""
    root = os.environ.get("LANDNAV_CACHE") or os.path.join(tempfile.gettempdir(),
                                                            "landnav-cache")
    path = Path(root) / "sumo"
    path.mkdir(parents=True, exist_ok=True)
    return path


@dataclass
class Network:
    """A SUMO network ready to simulate.

    ``path`` is the ``.net.xml``; ``proj`` the PROJ string of its georeference ('' when it has
    none); ``offset`` its ``netOffset`` (m); ``zones`` maps an edge id to its zone stretches,
    (fraction of the edge from, fraction to, zone name).
    """

    path: Path
    proj: str
    offset: np.ndarray
    zones: dict[str, list[tuple[float, float, str]]] = field(default_factory=dict)

    @property
    def georeferenced(self) -> bool:
        return bool(self.proj) and self.proj != "!"

    def to_lonlat(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Network x, y (m), shape (n, 2), to longitude and latitude (deg) via its projection."""
        import pyproj

        proj = pyproj.Proj(self.proj)
        xy = np.asarray(xy, dtype=float) - self.offset
        lon, lat = proj(xy[:, 0], xy[:, 1], inverse=True)
        return np.asarray(lon), np.asarray(lat)


class NetworkError(Exception):
    """A network that cannot be built or read; ``key`` names the scenario key at fault."""

    def __init__(self, key: tuple, message: str):
        super().__init__(message)
        self.key = key


def prepare_network(spec: str | dict, base: Path, yellow_decel: float = 3.0) -> Network:
    """Build (or take from the cache) the network a scenario's ``trajectory.network`` names.

    Parameters
    ----------
    spec : str or dict
        The validated ``network`` value.
    base : Path
        Folder relative paths are resolved against (the scenario file's folder).
    yellow_decel : float
        Deceleration (m/s^2) the yellow lights of a generated network are timed for
        (``yellow_time``); a network read from a file keeps its own signal plans.

    Raises
    ------
    NetworkError
        A missing input file, an unknown file type, or a SUMO tool that fails (with its message).
    """
    if isinstance(spec, str):
        src = _existing(base, spec, ("network",))
        name = src.name.lower()
        if name.endswith(".net.xml") or name.endswith(".net.xml.gz"):
            return _read_network(src)
        if name.endswith(".osm") or name.endswith(".osm.xml"):
            net = _build([f"--osm-files={src}", "--osm.elevation", "--osm.all-attributes",
                          "--osm.extra-attributes=tunnel,bridge,layer,covered",
                          "--tls.guess-signals", "--junctions.join",
                          "--keep-edges.by-vclass=passenger", "--no-turnarounds", _TURN_SPEED],
                         [src],
                         ("network",))
            return _read_network(net)
        if name.endswith(".xodr"):
            net = _build([f"--opendrive-files={src}", "--opendrive.position-ids"], [src],
                         ("network",))
            network = _read_network(net)
            network.zones.update(_opendrive_tunnels(src, net))
            return network
        raise NetworkError(("network",), f"{spec!r}: unknown network file type; give a "
                                         ".net.xml, .osm or .xodr file")
    given = [k for k in ("netgenerate", "nodes") if spec.get(k)]
    if len(given) != 1 or bool(spec.get("nodes")) != bool(spec.get("edges")):
        raise NetworkError(("network",), "give exactly one network source: a file path, "
                                         "netgenerate: {...}, or nodes: and edges: files")
    if spec.get("netgenerate"):
        return _read_network(_netgenerate(spec["netgenerate"], yellow_decel))
    files = {k: _existing(base, spec[k], ("network", k))
             for k in ("nodes", "edges", "connections") if spec.get(k)}
    args = [f"--node-files={files['nodes']}", f"--edge-files={files['edges']}",
            "--offset.disable-normalization", "--no-turnarounds", _TURN_SPEED]
    if "connections" in files:
        args.append(f"--connection-files={files['connections']}")
    return _read_network(_build(args, list(files.values()), ("network",)))


def _existing(base: Path, name: str, key: tuple) -> Path:
    path = (base / name).resolve()
    kind = not_regular(path)
    if kind is not None:
        raise NetworkError(key, f"network file not found: {path}" if kind == "missing"
                           else f"network file {path} is {kind}, not a regular file")
    return path


def yellow_time(speed: float, decel: float) -> float:
    """The yellow (change) interval of a signal, s: the kinematic formula of the Institute of
    Transportation Engineers (Traffic Engineering Handbook), Y = t_r + v / (2 a) on a level
    approach, with a perception-reaction time t_r of 1 s, the approach speed v and the
    deceleration a drivers stop with, so that a driver who sees yellow beyond the stopping
    distance can stop at a and a nearer one passes before red. netgenerate's 3 s is shorter
    than that for drivers braking at a comfortable 2 m/s^2 from 13.9 m/s (4.5 s, 5 s as
    netgenerate takes it in whole seconds): they were
    caught between stop line and red and braked at SUMO's emergency deceleration
    (docs/vehicle.md, "SUMO braking")."""
    return YELLOW_REACTION_S + speed / (2.0 * decel)


def _netgenerate(recipe: dict, yellow_decel: float) -> Path:
    kind = recipe["type"]
    args = [f"--{'rand' if kind == 'random' else kind}", f"--default.lanenumber={recipe['lanes']}",
            f"--default.speed={recipe['speed']}", f"--seed={recipe['seed']}",
            "--no-turnarounds", f"--default.junctions.radius={recipe['junction_radius']}",
            "--junctions.internal-link-detail=10", _TURN_SPEED]
    if kind == "grid":
        args += [f"--grid.number={recipe['number']}", f"--grid.length={recipe['length']}"]
    elif kind == "spider":
        args += [f"--spider.arm-number={recipe['arms']}",
                 f"--spider.circle-number={recipe['circles']}",
                 f"--spider.space-radius={recipe['radius']}"]
    else:
        args += [f"--rand.iterations={recipe['iterations']}"]
    if recipe["traffic_lights"]:
        args += ["--default-junction-type=traffic_light",
                 # netgenerate takes whole seconds: rounded up, a little more time to stop
                 f"--tls.yellow.time={math.ceil(yellow_time(recipe['speed'], yellow_decel))}"]
    return _run_tool("netgenerate", args, [], ("network", "netgenerate"))


def _build(args: list[str], inputs: list[Path], key: tuple) -> Path:
    return _run_tool("netconvert", args, inputs, key)


def _run_tool(tool: str, args: list[str], inputs: list[Path], key: tuple) -> Path:
    """Run a SUMO network tool into the cache (keyed by its arguments, inputs and version)."""
    import hashlib  # hashlib, subprocess and xml are imported where used: a drive that is not
    import subprocess  # SUMO's (every parametric one) never needs them (10 ms at start)

    digest = hashlib.sha256("\0".join([tool, _sumo_version(), *args]).encode())
    for path in inputs:
        digest.update(path.read_bytes())
    out = cache_dir() / f"{tool}-{digest.hexdigest()[:20]}.net.xml"
    if out.is_file():
        return out
    with tempfile.TemporaryDirectory(dir=cache_dir()) as tmp:
        target = Path(tmp) / "net.net.xml"
        cmd = [sumo_binary(tool), *args, f"--output-file={target}", "--no-warnings"]
        done = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp)
        if done.returncode != 0 or not target.is_file():
            lines = [ln.strip() for ln in (done.stderr + done.stdout).splitlines()
                     if ln.strip().lower().startswith("error")]
            message = "; ".join(lines[:3]) or (done.stderr.strip() or "no output")[:300]
            raise NetworkError(key, f"{tool} failed: {message}")
        shutil.move(target, out)
    return out


def _read_network(path: Path) -> Network:
    """Georeference and zone edges of a ``.net.xml``."""
    import xml.etree.ElementTree as ET

    proj, offset = "", np.zeros(2)
    zones: dict[str, list[tuple[float, float, str]]] = {}
    try:
        for _, elem in ET.iterparse(path, events=("end",)):
            if elem.tag == "location":
                proj = elem.get("projParameter", "")
                offset = np.array([float(v) for v in elem.get("netOffset", "0,0").split(",")])
            elif elem.tag == "edge":
                if elem.get("function") != "internal":
                    name = _edge_zone(elem)
                    if name:
                        zones[elem.get("id", "")] = [(0.0, 1.0, name)]
                elem.clear()
    except ET.ParseError as exc:
        raise NetworkError(("network",), f"{path}: not a readable SUMO network ({exc})") from None
    return Network(path, proj, offset, zones)


def _edge_zone(edge: ET.Element) -> str | None:
    params = {p.get("key"): p.get("value") for p in edge.iter("param")}
    if params.get("zone"):
        return params["zone"]
    if params.get("tunnel") in _TUNNEL_TAGS:
        return "tunnel"
    if params.get("covered") == "yes":
        return "underpass"
    kind = (edge.get("type") or "").lower()
    return next((w for w in _ZONE_WORDS if w in kind), None)


_POSITION_ID = re.compile(r"^(-?)(.+)\.(\d+\.\d+)$")


def _opendrive_tunnels(xodr: Path, net: Path) -> dict[str, list[tuple[float, float, str]]]:
    """Tunnel stretches of an OpenDRIVE file as fractions of the netconvert edges.

    With ``--opendrive.position-ids`` an edge is ``[-]ROAD.OFFSET``: '-' edges run along the
    road's s (right-hand lanes), the others against it; each covers s from OFFSET to the next
    edge's offset of the same road (or the road's length).
    """
    import xml.etree.ElementTree as ET

    roads: dict[str, tuple[float, list[tuple[float, float]]]] = {}
    for road in ET.parse(xodr).getroot().iter("road"):
        spans = [(float(t.get("s", 0)), float(t.get("s", 0)) + float(t.get("length", 0)))
                 for t in road.iter("tunnel")]
        roads[road.get("id", "")] = (float(road.get("length", 0)), spans)
    edges = [e.get("id", "") for e in ET.parse(net).getroot().iter("edge")
             if e.get("function") != "internal"]
    offsets: dict[str, list[float]] = {}
    parsed = {}
    for eid in edges:
        m = _POSITION_ID.match(eid)
        if m and m.group(2) in roads:
            parsed[eid] = (m.group(1) == "-", m.group(2), float(m.group(3)))
            offsets.setdefault(m.group(2), []).append(float(m.group(3)))
    out: dict[str, list[tuple[float, float, str]]] = {}
    for eid, (forward, road, start) in parsed.items():
        length, spans = roads[road]
        later = [o for o in offsets[road] if o > start]
        end = min(later) if later else length
        for a, b in spans:
            lo, hi = max(a, start), min(b, end)
            if hi <= lo:
                continue
            f0, f1 = (lo - start) / (end - start), (hi - start) / (end - start)
            out.setdefault(eid, []).append((f0, f1, "tunnel") if forward
                                           else (1 - f1, 1 - f0, "tunnel"))
    return out
