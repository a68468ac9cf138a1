"""Faults: transformations of streams over intervals (outages, satellite limits, multipath,
pressure jumps, wheel slip, bias steps, dropouts...), configured in the scenario's ``faults:``
list. Each kind is a ``FaultKind`` (its schema and its transformation) listed by name in
``FAULT_REGISTRY``; triggers
(start + duration, zone, distance range, random) are shared by all kinds.

Public names
------------
FAULT_REGISTRY, FAULT_KINDS, FAULT_FIELD, FAULT_STREAMS, check_faults.
"""

from __future__ import annotations

from simulator.faults.base import FaultKind
from simulator.faults.gnss_faults import GNSS_FAULTS
from simulator.faults.sensor_faults import SENSOR_FAULTS
from simulator.faults.triggers import trigger_problems
from simulator.schema import Context, Path, Record, Tagged

# every fault kind by name: the one table the scenario, the generator and the faults read
FAULT_REGISTRY: dict[str, FaultKind] = {kind.name: kind for kind in (*GNSS_FAULTS, *SENSOR_FAULTS)}

FAULT_KINDS: dict[str, Record] = {name: kind.record for name, kind in FAULT_REGISTRY.items()}

FAULT_FIELD = Tagged(FAULT_KINDS, what="fault kind")

# which sensor (and GNSS output) produces each stream a fault can act on
FAULT_STREAMS = {"imu": ("imu", None), "odometer": ("odometer", None), "baro": ("baro", None),
                 "mag": ("mag", None), "gnss_fix": ("gnss", "fix"), "gnss_raw": ("gnss", "raw")}


def _has_stream(sensors: dict, stream: str) -> bool:
    sensor, output = FAULT_STREAMS[stream]
    config = sensors.get(sensor)
    if config is None:
        return False
    return output is None or output in config.get("outputs", ["fix"])


def check_faults(scenario: dict, path: Path, ctx: Context, duration_s: float,
                 zones: set[str], length_m: float | None = None) -> None:
    """Cross-checks of every fault against the drive (its duration, zones and length travelled)
    and the configured sensors."""
    for i, fault in enumerate(scenario["faults"]):
        where = path + ("faults", i)
        trigger_problems(fault, where, ctx, duration_s, zones, length_m)
        kind = FAULT_REGISTRY[fault["kind"]]
        wanted = [fault["stream"]] if "stream" in fault else list(kind.streams)
        if not any(_has_stream(scenario["sensors"], s) for s in wanted):
            ctx.error(where + ("kind",), f"{fault['kind']} acts on {' or '.join(wanted)}, "
                      "which no configured sensor produces")
