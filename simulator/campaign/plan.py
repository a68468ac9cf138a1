"""The plan of a campaign: the swept values, the validated scenario of each sweep point, the runs
(run index, seed, sweep point) and the fingerprint that identifies the campaign on disk.

A ``--sweep KEY.PATH=V1,V2,...`` takes the key paths of ``--set``; its values are split at the
commas outside brackets and quotes (``--sweep sensors.imu.lever_arm=[0,0,0],[1,0,0]`` has two
values) and read as YAML, like ``--set``. Several sweeps give their cartesian product, the last
one varying fastest. Every sweep point is validated like the file before anything runs.

Run ``i`` has the seed ``base + i`` at every sweep point, so the sweep points are compared on
the same random draws (common random numbers) and a difference between them is not seed noise.

Public names
------------
PLAN_FORMAT, Sweep, SweepPoint, CampaignPlan, RunTask, entry_labels, parse_sweep, plan_campaign.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from simulator.errors import InputError, Problem
from simulator.pipeline import estimator_problems, load_scenario
from simulator.scenario import Scenario

MAX_SWEEP_POINTS = 1000  # points of the cartesian product of --sweep (each validated here)
PLAN_FORMAT = "landnav-campaign/1"  # written into DIR/campaign.json
_OPENING, _CLOSING = "[{(", "]})"


@dataclass(frozen=True)
class Sweep:
    """One ``--sweep``: the key path and its values as written on the command line."""

    key: str
    texts: tuple[str, ...]


@dataclass(frozen=True)
class SweepPoint:
    """One point of the sweep grid: its index, ``key=value`` overrides and column values."""

    index: int
    overrides: tuple[str, ...]
    values: dict[str, Any]


@dataclass(frozen=True)
class RunTask:
    """One run: a dataset generated from ``scenario`` (with this run's seed), every estimator.

    ``part`` names the run's result file in ``DIR/parts`` (without suffix); ``keep`` is the
    folder to keep the dataset in, or None for a temporary folder deleted after scoring.
    """

    run_id: int
    seed: int
    point: SweepPoint
    scenario: Scenario
    part: str
    keep: str | None = None


@dataclass(frozen=True)
class CampaignPlan:
    """The validated campaign: base scenario, sweeps, sweep points and their scenarios."""

    base: Scenario
    sweeps: tuple[Sweep, ...]
    points: tuple[SweepPoint, ...]
    scenarios: tuple[Scenario, ...]  # one per sweep point, with the base seed

    @property
    def labels(self) -> list[str]:
        """The solution labels, in the scenario's order."""
        return entry_labels(self.base.data["estimators"])

    @property
    def sweep_keys(self) -> list[str]:
        return [s.key for s in self.sweeps]

    def sweep_values(self) -> dict[str, list[Any]]:
        """Each swept key with its column values, in the order given."""
        return {s.key: _column_values(s) for s in self.sweeps}

    def fingerprint(self) -> str:
        """SHA-256 of the resolved scenario of every sweep point and the sweep as written:
        equal for the same scenario content, ``--set``, ``--seed`` and ``--sweep``."""
        text = json.dumps({"format": PLAN_FORMAT,
                           "sweeps": [[s.key, list(s.texts)] for s in self.sweeps],
                           "scenarios": [s.data for s in self.scenarios]},
                          sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()

    def record(self) -> dict:
        """What ``DIR/campaign.json`` holds about the plan (besides its fingerprint)."""
        return {"scenario": self.base.name, "scenario_file": str(self.base.path),
                "base_seed": self.base.seed, "overrides": self.base.overrides,
                "sweep": {s.key: list(s.texts) for s in self.sweeps}, "labels": self.labels}

    def tasks(self, runs: int, keep_root: Path | None = None) -> list[RunTask]:
        """Every run of the campaign: sweep point by sweep point, run 0 to ``runs - 1``."""
        out = []
        for point, scenario in zip(self.points, self.scenarios, strict=True):
            for i in range(runs):
                seed = self.base.seed + i
                part = (f"sweep-{point.index:04d}-run-{i:06d}" if self.sweeps
                        else f"run-{i:06d}")
                # the validated drive is kept: the road has its own seed (vehicle.road_seed),
                # so every run of a sweep point drives the same road
                run_scenario = dataclasses.replace(
                    scenario, data={**scenario.data, "seed": seed},
                    overrides=[*(o for o in scenario.overrides if not o.startswith("seed=")),
                               f"seed={seed}"])
                keep = None if keep_root is None else str(keep_root / part)
                out.append(RunTask(i, seed, point, run_scenario, part, keep))
        return out


def entry_labels(entries: list) -> list[str]:
    """The solution label of each resolved estimator entry (its ``label``, else its name)."""
    return [e if isinstance(e, str) else (e.get("label") or e["name"]) for e in entries]


def _split_values(text: str) -> list[str]:
    """Split at the commas that are outside brackets and quotes."""
    parts, depth, quote, current = [], 0, "", []
    for ch in text:
        if quote:
            quote = "" if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch in _OPENING:
            depth += 1
        elif ch in _CLOSING:
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append("".join(current).strip())
            current = []
            continue
        current.append(ch)
    parts.append("".join(current).strip())
    return parts


def parse_sweep(text: str, file: str) -> Sweep:
    """Read one ``KEY.PATH=V1,V2,...`` option.

    Raises
    ------
    InputError
        No ``=``, an empty key or value, a value given twice, or the key ``seed`` (the seeds
        are ``--seed`` and ``--runs``).
    """
    key, sep, values = text.partition("=")
    key = key.strip()

    def bad(message: str) -> InputError:
        return InputError([Problem(file, "--sweep", key or text, message)])

    if not sep or not key:
        raise bad(f"expected KEY.PATH=V1,V2,..., got {text!r}")
    if key == "seed":
        raise bad("the seeds are not swept: runs use --seed BASE + run index (--runs N)")
    texts = _split_values(values)
    if any(not t for t in texts):
        raise bad(f"empty value in {values!r}; give V1,V2,... separated by commas")
    if len(set(texts)) < len(texts):
        raise bad(f"a value is given twice in {values!r}")
    return Sweep(key, tuple(texts))


def _column_value(text: str) -> Any:
    """A sweep value as stored in its column: the YAML number or text, else the text."""
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError:
        return text
    return value if isinstance(value, (int, float, str)) and not isinstance(value, bool) else text


def _column_values(sweep: Sweep) -> list[Any]:
    """The values of one sweep column: all numbers, or else all the texts (one column type)."""
    values = [_column_value(t) for t in sweep.texts]
    if all(isinstance(v, (int, float)) for v in values):
        return values
    return list(sweep.texts)


def _at_point(problems: list[Problem], swept: dict[str, str]) -> list[Problem]:
    """Problems of a sweep point, naming it (the scenario without it is valid); those on a
    swept key come from ``--sweep``, not ``--set``."""
    where = ", ".join(f"{k}={v}" for k, v in swept.items())
    out = []
    for p in problems:
        on_key = any(p.key_path == k or p.key_path.startswith(k + ".")
                     or k.startswith(p.key_path + ".") for k in swept)
        out.append(dataclasses.replace(
            p, line="--sweep" if on_key else p.line, message=f"{p.message} (--sweep {where})"))
    return out


def _validate(path: Path, overrides: list[str], seed: int | None, swept: dict[str, str]
              ) -> Scenario:
    """Load a sweep point (its plug-ins checked by name: ``_check_plugins`` imports them)."""
    try:
        return load_scenario(path, overrides, seed)
    except InputError as exc:
        raise InputError(_at_point(exc.problems, swept)) from None


def _check_plugins(base: Scenario, points: list[SweepPoint], scenarios: list[Scenario],
                   time_limit_s: float | None) -> None:
    """Import and check every estimator entry of the base scenario and of each sweep point, in
    one bounded child process for the plug-ins (``pipeline.estimator_problems``)."""
    found = estimator_problems([base, *scenarios], True, time_limit_s)
    problems = found[0] or [p for point, at in zip(points, found[1:], strict=True)
                            for p in _at_point(at, _swept(point))]
    if problems:
        raise InputError(problems)


def _swept(point: SweepPoint) -> dict[str, str]:
    return dict(a.split("=", 1) for a in point.overrides)


def plan_campaign(path: str | Path, overrides: list[str], seed: int | None,
                  sweep_texts: list[str], time_limit_s: float | None = None) -> CampaignPlan:
    """Validate the scenario, every sweep value and every sweep point.

    Parameters
    ----------
    path : the scenario file.
    overrides : ``--set`` key=value strings.
    seed : ``--seed`` (the base seed; None keeps the scenario's).
    sweep_texts : the ``--sweep`` options as written.
    time_limit_s : how long importing and checking the plug-in estimators may take, s (None:
        ``simulator.isolated.CHECK_LIMIT_S``).

    Raises
    ------
    InputError
        Every problem found: a bad scenario, a malformed sweep, a key swept twice or also
        given with ``--set``, an invalid sweep value, a sweep that changes the estimator labels,
        a scenario without estimators.
    """
    path = Path(path)
    base = load_scenario(path, overrides, seed)
    if not base.data["estimators"]:
        raise InputError([Problem(str(path), None, "estimators", "the scenario names no "
                                  "estimator: a campaign scores estimators; add some")])
    sweeps = tuple(parse_sweep(t, str(path)) for t in sweep_texts)
    set_keys = {o.partition("=")[0].strip() for o in overrides}
    problems = []
    for i, s in enumerate(sweeps):
        if s.key in set_keys or s.key in [x.key for x in sweeps[:i]]:
            problems.append(Problem(str(path), "--sweep", s.key, "the key is also given by "
                                    "--set or another --sweep; give each key once"))
    n_points = math.prod(len(s.texts) for s in sweeps)
    if n_points > MAX_SWEEP_POINTS:
        problems.append(Problem(str(path), "--sweep", ", ".join(s.key for s in sweeps),
                                f"{n_points:,} sweep points, more than one campaign validates "
                                f"({MAX_SWEEP_POINTS:,}: each is a whole scenario built and "
                                "checked); sweep fewer values or split the campaign"))
    if problems:
        raise InputError(problems)
    for s in sweeps:  # each value alone first: one message per bad value
        for text in s.texts:
            _validate(path, [*overrides, f"{s.key}={text}"], seed, {s.key: text})
    columns = [_column_values(s) for s in sweeps]
    points, scenarios = [], []
    grid = itertools.product(*(range(len(s.texts)) for s in sweeps))
    for index, choice in enumerate(grid):
        swept = {s.key: s.texts[j] for s, j in zip(sweeps, choice, strict=True)}
        assignments = tuple(f"{k}={v}" for k, v in swept.items())
        values = {s.key: col[j] for s, col, j in zip(sweeps, columns, choice, strict=True)}
        points.append(SweepPoint(index, assignments, values))
        scenarios.append(_validate(path, [*overrides, *assignments], seed, swept))
        if entry_labels(scenarios[-1].data["estimators"]) != entry_labels(
                base.data["estimators"]):
            raise InputError([Problem(str(path), "--sweep", ", ".join(swept), "a sweep may not "
                                      "change the estimators or their labels")])
    _check_plugins(base, points, scenarios, time_limit_s)
    return CampaignPlan(base, sweeps, tuple(points), tuple(scenarios))
