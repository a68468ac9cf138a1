"""Scenario files: reading, ``--set`` overrides, validation and resolution (defaults filled).

Public names
------------
Scenario, load_scenario, validate_data.
"""

from __future__ import annotations

import contextlib
import copy
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from simulator.drive import Drive, build_drive
from simulator.errors import InputError, Problem, refuse_undecodable
from simulator.scenario.spec import SCENARIO_FIELD
from simulator.scenario.yamlio import apply_overrides, read_yaml
from simulator.schema import INVALID, Context


@dataclass(frozen=True)
class Scenario:
    """A validated scenario: ``data`` is the resolved scenario (defaults filled, SI values) and
    ``drive`` the drive its validation built (None for a Scenario made in code: the generator
    then builds it)."""

    path: Path
    data: dict
    overrides: list[str]
    drive: Drive | None = None

    @property
    def name(self) -> str:
        return self.data["name"]

    @property
    def seed(self) -> int:
        return self.data["seed"]

    @property
    def input_files(self) -> list[Path]:
        """The scenario file and every file its resolved data names (a SUMO network, a recorded
        drive, a navigation file: made absolute at validation): what an output must not touch."""
        found = [Path(self.path)]
        stack: list[Any] = [self.data]
        while stack:
            node = stack.pop()
            if isinstance(node, dict):
                stack.extend(node.values())
            elif isinstance(node, list):
                stack.extend(node)
            elif isinstance(node, str) and node.startswith("/") and len(node) < 4096:
                with contextlib.suppress(OSError, ValueError):
                    if Path(node).is_file():
                        found.append(Path(node))
        return found


def _validate(data: Any, file: str, lines: dict | None = None,
              overridden: set | None = None) -> tuple[dict, Drive]:
    ctx = Context(file, lines, overridden)
    resolved = SCENARIO_FIELD.check(copy.deepcopy(data), (), ctx)
    if ctx.problems or resolved is INVALID:
        raise InputError(ctx.problems)
    return resolved, build_drive(resolved, ctx.built["profile"])


def validate_data(data: Any, file: str, lines: dict | None = None,
                  overridden: set | None = None) -> dict:
    """Validate scenario data; return the resolved scenario or raise InputError with every
    problem found."""
    return _validate(data, file, lines, overridden)[0]


def load_scenario(path: str | Path, overrides: list[str] | None = None,
                  seed: int | None = None) -> Scenario:
    """Read, override and validate a scenario file.

    Parameters
    ----------
    path : path of the YAML file.
    overrides : ``key.path=value`` strings (``--set``), applied before validation.
    seed : replaces the scenario's seed when given (``--seed``).

    Raises
    ------
    InputError
        With every problem as ``file:line: key.path: message``.
    """
    path = Path(path)
    refuse_undecodable(path, "scenario's name")
    data, lines = read_yaml(path)
    if not isinstance(data, dict):
        raise InputError([Problem(str(path), 1, "", "a scenario is a mapping of keys (name, "
                                  f"start, trajectory, sensors, ...), not {data!r}")])
    overrides = list(overrides or [])
    if seed is not None:
        overrides.append(f"seed={seed}")
    data, touched = apply_overrides(data, overrides, str(path))
    data.setdefault("name", path.stem.removesuffix(".scenario"))
    resolved, drive = _validate(data, str(path), lines, touched)
    return Scenario(path=path, data=resolved, overrides=overrides, drive=drive)
