"""The scenario file's schema (SPEC section 4), assembled from the parts each module owns, and the
cross-section checks (drivability, rates) that need more than one section.

Public names
------------
SCENARIO_FIELD, START_FIELD, ESTIMATOR_ENTRY_FIELD.
"""

from __future__ import annotations

from estimators.registry import name_problems
from simulator.drive import build_profile
from simulator.environment import COVERED_ZONE_NAMES, ENVIRONMENT_FIELD, ZONE_FIELD
from simulator.faults import FAULT_FIELD, check_faults
from simulator.schema import (
    Anything,
    Context,
    DateTime,
    Either,
    Integer,
    ListOf,
    MapOf,
    Number,
    Path,
    Record,
    SafeName,
    Tagged,
    Text,
    Vector,
)
from simulator.sensors import SENSOR_FIELDS
from simulator.trajectory import TRAJECTORY_KINDS
from simulator.trajectory.segments import LIMITS_FIELD
from simulator.vehicle import VEHICLE_FIELD
from simulator.vehicle.params import default_vehicle

START_FIELD = Record({
    "utc": DateTime("2020-01-01T00:00:00Z", earliest="1980-01-06T00:00:00",
                    doc="UTC time of t = 0 (from the GPS epoch, 1980-01-06, on)"),
    "lat": Number(angle=True, min=-89.0, max=89.0, doc="latitude, deg"),
    "lon": Number(angle=True, min=-180.0, max=180.0, doc="longitude, deg"),
    "alt": Number("m", 0.0, min=-500.0, max=9000.0, doc="ellipsoidal height, m"),
    "heading": Number(default=0.0, angle=True, min=-360.0, max=360.0,
                      doc="initial heading from true north, deg"),
})

_INIT_FIELD = Record({
    "position_error": Vector(3, Number("m"), None, doc="north, east, down, m"),
    "velocity_error": Vector(3, Number("m/s"), None, doc="north, east, down, m/s"),
    "attitude_error": Vector(3, Number(angle=True), None, doc="roll, pitch, yaw, deg"),
    "heading_error": Number(default=None, angle=True, doc="deg (adds to attitude_error's yaw)"),
    "sensor_errors": Either(
        Text(choices=["truth"]), MapOf(Anything(None)), None,
        doc="priors of the sensor-error states: 'truth' hands the drawn true values (the "
            "manifest's sensors block), a mapping {sensor: {parameter: value}} hands those"),
}, default=None)

ESTIMATOR_ENTRY_FIELD = Either(
    Text(),
    Record({
        "name": Text(doc="registered name, or module:Class"),
        "label": SafeName(None, doc="solution name (default: the estimator name); it names the "
                          "solution file, so letters, digits, '.', '_' and '-' only"),
        "init": _INIT_FIELD,
        "config": Anything(None, doc="the estimator's own options"),
    }),
)


def _check_whole(value: dict, path: Path, ctx: Context) -> dict:
    traj = value["trajectory"]
    if value["vehicle"] is None:
        value["vehicle"] = default_vehicle(traj["kind"])
    imu = value["sensors"].get("imu")
    if traj.get("rate") is None:
        traj["rate"] = imu["rate"] if imu else 100.0
    elif imu and traj["rate"] < imu["rate"]:
        ctx.error(path + ("trajectory", "rate"),
                  f"the truth rate {traj['rate']:g} Hz is below the IMU rate {imu['rate']:g} Hz")
    _check_base(value["sensors"], path + ("sensors", "gnss_base"), ctx)
    profile = build_profile(value, ctx)
    if profile is not None:
        ctx.built["profile"] = profile
        _check_job_size(value, profile.duration_s, path, ctx)
        _check_rates(value, profile.duration_s, path, ctx)
        check_faults(value, path, ctx, profile.duration_s, {z[2] for z in profile.zones},
                     float(profile.distance_of_time(profile.duration_s)))
    labels: set[str] = set()
    for i, entry in enumerate(value["estimators"]):
        label = entry if isinstance(entry, str) else (entry["label"] or entry["name"])
        if label in labels:
            ctx.error(path + ("estimators", i), f"label {label!r} is used twice; give a label")
        labels.add(label)
        for key, message in name_problems(entry):
            where = path + ("estimators", i) + (() if isinstance(entry, str) else (key,))
            ctx.error(where, message)
    zones = value["environment"]["zones"]
    used = _zones_used(value)
    if used is not None:
        for name in sorted(set(zones) - used):
            ctx.error(path + ("environment", "zones", name), "no segment has this zone")
    elif profile is not None:  # zones from a network or a log: the drive may miss a declared one
        used = {name for _, _, name in profile.zones}
    if used is not None:
        for name in sorted(used - set(zones)):
            sky = "none" if name in COVERED_ZONE_NAMES else "open"
            zones[name] = ZONE_FIELD.check({"sky": sky}, path + ("environment", "zones", name),
                                           ctx)
    return value


def _check_base(sensors: dict, path: Path, ctx: Context) -> None:
    """A base station needs a rover, whose epochs it shares: the rover's rate is a whole
    multiple of the base's."""
    base, rover = sensors.get("gnss_base"), sensors.get("gnss")
    if base is None:
        return
    if rover is None:
        ctx.error(path, "a base station needs sensors.gnss (it shares the rover's sky)")
        return
    ratio = rover["rate"] / base["rate"]
    if abs(ratio - round(ratio)) > 1e-9 or round(ratio) < 1:
        ctx.error(path + ("rate",), f"the rover's rate {rover['rate']:g} Hz must be a whole "
                                    f"multiple of the base's {base['rate']:g} Hz")


# What one generation holds, measured with /usr/bin/time -v on `landnav generate` of a straight
# drive with every sensor (IMU 100 Hz, odometer, barometer, magnetometer, GNSS fix and raw at
# 1 Hz, 31 satellites): peak RSS 233 MB at 10 min, 347 MB at 30 min, 527 MB at 60 min, so
# 0.35 GB per drive hour (1 kB per truth sample at 100 Hz) over 0.17 GB. A GNSS epoch costs by
# what it tracks and outputs. Raw measurements only, 5-minute drives at 10 Hz (3000 epochs),
# one receiver: 298 MB with GPS L1 alone, 314 MB with three GPS signals, 456 MB with GPS,
# Galileo, BeiDou and GLONASS on one signal each, 519 MB on two each: about 20 kB per system
# (by its satellites: 0.66 kB per satellite-epoch, GPS's 31 the most of the four skies) and
# 3-5 kB per further signal, taken as 6 kB. With fixes as well (10 Hz, 100 Hz IMU, drives of 2
# and 10 min): 230 and 473 MB with GPS alone (40.6 kB per epoch beyond the truth samples), 611
# MB over 10 min with three GPS signals (24 kB more): twice the raw figures. The rover and
# base of four systems on two signals, raw only, at 10 Hz: 759 MB at 5 min and 1307 MB at 10
# min (91 kB per receiver-epoch), and the whole hour (36 000 epochs each) 5.17 GB once each
# receiver's rows were held once; the estimate (104 kB) holds that hour at 7.5 GB.
# The odometer, barometer and magnetometer at 100 Hz instead of 10 Hz (60 min, ideal IMU at
# 100 Hz, GNSS at 1 Hz): 698 MB against 606 MB, 94 bytes per further sample of each.
BYTES_PER_TRUTH_SAMPLE = 1000
BYTES_PER_SENSOR_SAMPLE = 100  # of the odometer, barometer and magnetometer
SAMPLED_SENSORS = ("odometer", "baro", "mag")
BYTES_PER_SYSTEM_EPOCH = 20_000
BYTES_PER_EXTRA_SIGNAL_EPOCH = 6_000
FIX_FACTOR = 2  # an epoch of a receiver that also computes fixes
MAX_TRUTH_SAMPLES = 10_000_000  # about 28 h at 100 Hz: 10 GB
MAX_JOB_BYTES = 10e9


def _gnss_epoch_bytes(gnss: dict) -> int:
    """What one epoch of a GNSS receiver costs a generation, by the systems and signals it
    tracks and whether it computes fixes (measured: see above); each system tracks one signal
    where none are named."""
    signals = gnss.get("signals") or {}
    raw = sum(BYTES_PER_SYSTEM_EPOCH
              + BYTES_PER_EXTRA_SIGNAL_EPOCH * max(len(signals.get(system) or ()) - 1, 0)
              for system in gnss.get("systems") or ("gps",))
    return raw * (FIX_FACTOR if "fix" in (gnss.get("outputs") or ()) else 1)


def _check_job_size(value: dict, duration_s: float, path: Path, ctx: Context) -> None:
    rate_hz = value["trajectory"]["rate"]
    samples = rate_hz * duration_s
    receivers = [r for r in (value["sensors"].get("gnss"), value["sensors"].get("gnss_base"))
                 if isinstance(r, dict)]
    epochs = sum(r["rate"] * duration_s for r in receivers)
    gnss_bytes = sum(r["rate"] * duration_s * _gnss_epoch_bytes(r) for r in receivers)
    sensor_samples = sum(sensor["rate"] * duration_s for name in SAMPLED_SENSORS
                         if isinstance(sensor := value["sensors"].get(name), dict)
                         and isinstance(sensor.get("rate"), float | int))
    job_bytes = (samples * BYTES_PER_TRUTH_SAMPLE + gnss_bytes
                 + sensor_samples * BYTES_PER_SENSOR_SAMPLE)
    if samples > MAX_TRUTH_SAMPLES:
        hours = MAX_TRUTH_SAMPLES / rate_hz / 3600
        ctx.error(path + ("trajectory",),
                  f"the drive lasts {duration_s / 3600:.4g} h: at {rate_hz:g} Hz that is "
                  f"{samples:.3g} truth samples (about {job_bytes / 1e9:.3g} GB), more than "
                  f"one job may hold ({MAX_TRUTH_SAMPLES:.0e}); split it into drives of at most "
                  f"{hours:.3g} h, or lower trajectory.rate")
    elif job_bytes > MAX_JOB_BYTES and not receivers:
        ctx.error(path + ("sensors",),
                  f"the drive lasts {duration_s / 3600:.4g} h: its {samples:.3g} truth samples "
                  f"and {sensor_samples:.3g} odometer, barometer and magnetometer samples need "
                  f"about {job_bytes / 1e9:.3g} GB, more than one job may hold "
                  f"({MAX_JOB_BYTES / 1e9:.3g} GB); lower the sensors' rates or split the drive")
    elif job_bytes > MAX_JOB_BYTES:
        gnss = receivers[0]
        ctx.error(path + ("sensors", "gnss", "rate"),
                  f"the drive lasts {duration_s / 3600:.4g} h: its {samples:.3g} truth samples "
                  f"and {epochs:.3g} GNSS epochs at {gnss['rate']:g} Hz need about "
                  f"{job_bytes / 1e9:.3g} GB (tracking "
                  f"{', '.join(gnss.get('systems') or ('gps',))}), more than one job may hold "
                  f"({MAX_JOB_BYTES / 1e9:.3g} GB); lower sensors.gnss.rate, track fewer "
                  "systems or signals, or split the drive")


def _check_rates(value: dict, duration_s: float, path: Path, ctx: Context) -> None:
    """No rate of the truth or of a sensor has a period longer than the drive: one such as
    ``rate: 1e-300`` gives a table of one row at most, and a stream timed by it (the IMU's
    integration interval) ages without bound."""
    rated = [(("sensors", name, "rate"), sensor.get("rate"))
             for name, sensor in value["sensors"].items() if isinstance(sensor, dict)]
    imu = value["sensors"].get("imu")
    if not (isinstance(imu, dict) and imu.get("rate") == value["trajectory"].get("rate")):
        rated.append((("trajectory", "rate"), value["trajectory"].get("rate")))  # its own
    for key, rate_hz in rated:
        if isinstance(rate_hz, float | int) and rate_hz * duration_s < 1:
            ctx.error(path + key, f"at {rate_hz:g} Hz one sample period is longer than the "
                                  f"{duration_s:.4g} s drive; give at least "
                                  f"{1 / duration_s:.3g} Hz")


def _zones_used(value: dict) -> set[str] | None:
    """Zone names the segments carry (None for sources whose zones come from elsewhere)."""
    traj = value["trajectory"]
    if traj["kind"] != "segments":
        return None
    return {seg.get("zone") for item in traj["segments"] for seg in item.values()} - {None}


SCENARIO_FIELD = Record(
    {
        "name": SafeName(None, doc="the drive's name; `landnav run` without -o writes to "
                         "runs/<name>, so letters, digits, '.', '_' and '-' only"),
        "description": Text(None, doc="free text"),
        "seed": Integer(0, min=0, max=2**63 - 1,
                        doc="determines every random draw (--seed overrides it)"),
        "start": START_FIELD,
        "limits": LIMITS_FIELD,
        "trajectory": Tagged(TRAJECTORY_KINDS, what="trajectory kind",
                             doc="the road and the speed: segments, a SUMO network or a "
                                 "recorded drive"),
        "vehicle": VEHICLE_FIELD,
        "environment": ENVIRONMENT_FIELD,
        "sensors": Record(SENSOR_FIELDS, default={},
                          doc="the sensors the car carries; a sensor left out is absent"),
        "faults": ListOf(FAULT_FIELD, [], doc="faults applied to the streams (docs/faults.md)"),
        "estimators": ListOf(ESTIMATOR_ENTRY_FIELD, [],
                             doc="what `landnav run` runs: a name, or {name, label, init, "
                                 "config}"),
    },
    post=_check_whole,
)
