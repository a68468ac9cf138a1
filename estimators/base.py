"""The estimator plug-in interface (SPEC section 6): what every estimator declares, how it is
built, how it receives messages and how it reports its solution.

An estimator is a subclass of ``Estimator``. The class declares

* ``name``: its short name (the registry key);
* ``needs``: the streams it requires (``("imu", "odometer")``); a dataset without one of them is
  refused before the run;
* ``uses``: streams it takes when the dataset has them;
* ``paper``: the citation it follows;
* ``output_rate_hz``: how often the replay asks for a solution (default 10 Hz); it also asks after
  every GNSS epoch;
* ``defaults``: its configuration keys and their default values; the scenario's ``config``
  mapping is merged over them and an unknown key is an error;
* ``config_help``: for each key of ``defaults``, its unit (SI, as the value is given; ``""`` for
  a switch, a name or a plain number) and what it sets; ``landnav estimators NAME`` shows them;
* ``output_columns``: the columns of its solution rows after ``t`` (the nine navigation columns
  of SPEC section 7, then optionally ``std_*`` columns and free extra columns);
* ``initialises_itself``: True if it needs no initial state (it starts from the first fixes).

The replay (``simulator.replay``) builds it with its merged configuration, its initial state
(``InitialState``: the truth at its start time perturbed by the scenario's ``init`` errors, or
None) and the layout of the streams it receives, then calls ``setup()``. Each message goes to the
method ``on_<stream>(t, row)``: ``row`` is a read-only float64 row of the stream's table whose
column positions are ``self.columns[stream][column]`` (units in ``self.units[stream]``;
``self.imu_output`` says whether the IMU rows are rates, ``"rate"``, or increments over the
interval before each sample, ``"increment"``, from the dataset's IMU stream description;
``self.datasheet`` is the manifest's ``datasheet``, what a user knows of the sensors and the
car: each sensor's parameters, the GNSS ``antenna_lever_arm``, the IMU ``mounting``, the
``vehicle`` block with the rear axle from the IMU; empty when the dataset has none); a
``gnss_raw`` message is one whole epoch, a 2-D array with one row per satellite. After the
messages of an output instant the replay calls ``solution(t)``, which returns the values of
``output_columns`` for time ``t`` (or None while the estimator has no solution yet).

Public names
------------
Estimator, InitialState, NAV_COLUMNS, STD_COLUMNS, GNSS_STREAMS, config_problems, resolve_config,
check_estimator_class.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from simulator import columns as col
from simulator.earth import euler_to_quat
from simulator.errors import InputError, Problem

NAV_COLUMNS = tuple(c for c in col.SOLUTION if c != "t")  # lat, lon (deg), alt, vn ... yaw (rad)
STD_COLUMNS = tuple(col.SOLUTION_STD)
GNSS_STREAMS = ("gnss_fix", "gnss_raw")  # a solution is asked for after each of their epochs


@dataclass(frozen=True)
class InitialState:
    """The state an estimator starts from, at time ``t``.

    Attributes
    ----------
    t : float
        Time of the state, s since the scenario start (the estimator's first message time).
    position : ndarray, shape (3,)
        Latitude (rad), longitude (rad), ellipsoidal height (m).
    velocity : ndarray, shape (3,)
        NED velocity, m/s.
    attitude : ndarray, shape (3,)
        Roll, pitch, yaw (rad), ZYX Euler angles of the FRD body frame in NED.
    sensor_errors : dict
        Priors of sensor-error states, ``{sensor: {parameter: value}}`` (the scenario's
        ``init.sensor_errors``: the drawn true values with ``truth``, the given values with a
        mapping; empty when not given, and the estimator starts from its own defaults).
    """

    t: float
    position: np.ndarray
    velocity: np.ndarray
    attitude: np.ndarray
    sensor_errors: dict = field(default_factory=dict)

    @property
    def quaternion(self) -> np.ndarray:
        """Body-to-NED quaternion (scalar first), shape (4,)."""
        return euler_to_quat(*self.attitude)


class Estimator:
    """Base class of every estimator; see the module docstring for the contract."""

    name: ClassVar[str] = ""
    needs: ClassVar[tuple[str, ...]] = ()
    uses: ClassVar[tuple[str, ...]] = ()
    paper: ClassVar[str] = ""
    output_rate_hz: ClassVar[float] = 10.0
    defaults: ClassVar[Mapping[str, Any]] = {}
    config_help: ClassVar[Mapping[str, tuple[str, str]]] = {}  # key -> (SI unit, meaning)
    output_columns: ClassVar[tuple[str, ...]] = NAV_COLUMNS
    initialises_itself: ClassVar[bool] = False

    def __init__(self, config: Mapping[str, Any] | None, initial: InitialState | None,
                 columns: Mapping[str, Mapping[str, int]],
                 units: Mapping[str, Mapping[str, str]], *, imu_output: str | None = None,
                 datasheet: Mapping[str, Any] | None = None):
        self.config = resolve_config(type(self), config)
        self.initial = initial
        self.columns = {k: dict(v) for k, v in columns.items()}
        self.units = {k: dict(v) for k, v in units.items()}
        # "rate" or "increment" (None without an IMU stream): what the IMU rows hold
        self.imu_output = imu_output
        self.datasheet = copy.deepcopy(dict(datasheet or {}))
        self.setup()

    def setup(self) -> None:
        """Prepare the state from ``self.config``, ``self.initial``, ``self.columns``."""

    def solution(self, t: float) -> Sequence[float] | np.ndarray | None:
        """The solution at time ``t`` (values of ``output_columns``) or None if there is none."""
        raise NotImplementedError


def config_problems(cls: type[Estimator], config: Mapping[str, Any] | None) -> list[str]:
    """What is wrong with ``config`` for ``cls`` (empty if nothing): keys the estimator does
    not have (naming the known ones), values whose type differs from the default's (bool,
    number, text, list, mapping)."""
    if config is not None and not isinstance(config, Mapping):
        return [f"config must be a mapping of keys to values, got {config!r}"]
    config = dict(config or {})
    unknown = sorted(set(config) - set(cls.defaults))
    if unknown:
        known = ", ".join(sorted(cls.defaults)) or "none"
        return [f"unknown config key(s) {', '.join(map(str, unknown))} for estimator "
                f"{cls.name or cls.__name__}; known: {known}"]
    problems = []
    for key, value in config.items():
        expected = _kind(cls.defaults[key])
        if expected is not None and _kind(value) != expected:
            problems.append(f"config key {key!r} of estimator {cls.name or cls.__name__} "
                            f"expects {expected}, got {value!r}")
    return problems


def resolve_config(cls: type[Estimator], config: Mapping[str, Any] | None) -> dict[str, Any]:
    """Merge ``config`` over ``cls.defaults``; raise InputError with ``config_problems``."""
    problems = config_problems(cls, config)
    if problems:
        raise InputError([Problem("config", None, "", p) for p in problems])
    return copy.deepcopy({**cls.defaults, **(config or {})})


def _kind(value: Any) -> str | None:
    if value is None:
        return None
    if isinstance(value, bool):
        return "true or false"
    if isinstance(value, (int, float)):
        return "a number"
    if isinstance(value, str):
        return "text"
    if isinstance(value, (list, tuple)):
        return "a list"
    if isinstance(value, Mapping):
        return "a mapping"
    return type(value).__name__


MAX_OUTPUT_RATE_HZ = 1000.0  # solution rows per second of data an estimator may ask for


def check_estimator_class(cls: Any, where: str) -> list[str]:
    """Problems with a class offered as an estimator (empty if it satisfies the contract)."""
    if not (isinstance(cls, type) and issubclass(cls, Estimator)):
        return [f"{where} is not an estimators.base.Estimator subclass"]
    problems = []
    scoring = [s for s in (*cls.needs, *cls.uses) if s in col.SCORING_ONLY]
    if scoring:
        problems.append(f"{where} asks for the scoring-only stream(s) {', '.join(scoring)}; "
                        "an estimator never sees truth or events")
    for stream in (*cls.needs, *cls.uses):
        if not callable(getattr(cls, f"on_{stream}", None)):
            problems.append(f"{where} takes the {stream!r} stream but has no on_{stream} method")
    if cls.solution is Estimator.solution:
        problems.append(f"{where} has no solution(t) method")
    missing = [c for c in NAV_COLUMNS if c not in cls.output_columns]
    if missing:
        problems.append(f"{where}: output_columns lacks {', '.join(missing)}")
    columns = cls.output_columns
    if not isinstance(columns, (tuple, list)) or not all(isinstance(c, str) for c in columns):
        problems.append(f"{where}: output_columns must be a tuple of column names")
    else:
        repeated = sorted({c for c in columns if columns.count(c) > 1} | (
            {"t"} & set(columns)))
        if repeated:
            problems.append(f"{where}: output_columns names {', '.join(repeated)} twice "
                            "(t is added by the replay)")
    if not isinstance(cls.defaults, Mapping):
        problems.append(f"{where}: defaults must be a mapping of config keys to default values, "
                        f"got {cls.defaults!r}")
    rate = cls.output_rate_hz
    if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not (
            0 < rate <= MAX_OUTPUT_RATE_HZ):
        problems.append(f"{where}: output_rate_hz must be a number in (0, "
                        f"{MAX_OUTPUT_RATE_HZ:g}] Hz, got {rate!r}")
    return problems
