"""A small declarative schema for scenario files: types, units, ranges, defaults, and all problems
reported at once with their key path and line.

Each module that owns a part of the scenario (a sensor, a fault kind, a trajectory source) declares
its part with these field types; ``simulator.scenario.spec`` assembles them. Validation returns the
resolved value (defaults filled, unit strings converted to SI floats, plain angles kept in degrees
so the resolved scenario is itself a valid scenario) and records problems in a ``Context``.

Public classes
--------------
Context, Field, Number, Integer, Text, Boolean, DateTime, Vector, ListOf, Record, MapOf, OneKey,
Either, Anything; REQUIRED, INVALID.
"""

from __future__ import annotations

import datetime as dt
import difflib
import re
from collections.abc import Callable
from typing import Any

from simulator.errors import Problem
from simulator.units import UnitError, to_si

REQUIRED = object()  # marks a key that must be given
INVALID = object()  # returned by a field whose value failed validation

Path = tuple  # a key path: strings for mapping keys, ints for list indices


def path_text(path: Path) -> str:
    return ".".join(str(p) for p in path) or "(top level)"


class Context:
    """Where problems are collected, with the source file and the line of every key path."""

    def __init__(self, file: str, lines: dict[Path, int] | None = None,
                 overridden: set[Path] | None = None):
        self.file = file
        self.lines = lines or {}
        self.overridden = overridden or set()
        self.problems: list[Problem] = []
        # what a check built that its caller reuses (the scenario's road profile), by name
        self.built: dict[str, Any] = {}

    def line_of(self, path: Path) -> int | str | None:
        for n in range(len(path), -1, -1):
            if path[:n] in self.overridden:
                return "--set"
            if path[:n] in self.lines:
                return self.lines[path[:n]]
        return None

    def error(self, path: Path, message: str) -> object:
        self.problems.append(Problem(self.file, self.line_of(path), path_text(path), message))
        return INVALID


class Field:
    """Base of all field types: a default (``REQUIRED`` for none) and a one-line doc."""

    def __init__(self, default: Any = REQUIRED, doc: str = ""):
        self.default = default
        self.doc = doc

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        raise NotImplementedError

    def resolve_missing(self, path: Path, ctx: Context) -> Any:
        if self.default is REQUIRED:
            return ctx.error(path, "missing required key")
        if self.default is None:
            return None
        return self.check(self.default, path, ctx)


# no scenario quantity comes near this in SI units (1e12 m is 7 astronomical units, 1e12 s is
# 31 700 years); larger values only overflow the arithmetic
MAX_MAGNITUDE = 1e12


class Number(Field):
    """A real number in ``unit`` (SI), or a string with any unit of the same dimension.

    With ``angle=True`` the field is a plain angle: plain numbers are degrees, and the resolved
    value stays in degrees (a string such as ``"0.1 rad"`` is converted to degrees).
    """

    def __init__(self, unit: str = "", default: Any = REQUIRED, *, angle: bool = False,
                 min: float | None = None, max: float | None = None,
                 gt: float | None = None, lt: float | None = None, doc: str = ""):
        super().__init__(default, doc)
        self.unit = "deg" if angle else unit
        self.angle = angle
        self.min, self.max, self.gt, self.lt = min, max, gt, lt

    def convert(self, value: Any, path: Path, ctx: Context) -> Any:
        if isinstance(value, bool):
            return ctx.error(path, f"expected a number{self._unit_hint()}, got {value!r}")
        if isinstance(value, (int, float)):
            return float(value)
        if isinstance(value, str):
            try:
                return to_si(value, self.unit)
            except UnitError as exc:
                if "dimension" in str(exc):
                    return ctx.error(path, str(exc))
                return ctx.error(path, f"expected a number{self._unit_hint()}; {exc}")
        return ctx.error(path, f"expected a number{self._unit_hint()}, got {value!r}")

    def _unit_hint(self) -> str:
        return f" in {self.unit} (or a string with a unit)" if self.unit else ""

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        x = self.convert(value, path, ctx)
        if x is INVALID:
            return x
        if x != x or x in (float("inf"), float("-inf")):
            return ctx.error(path, f"expected a finite number, got {value!r}")
        if abs(x) > MAX_MAGNITUDE:
            return ctx.error(path, f"{value!r} is beyond any value a scenario describes "
                                   f"(|x| <= {MAX_MAGNITUDE:g} in SI units)")
        unit = f" {self.unit}" if self.unit else ""
        if self.min is not None and x < self.min:
            return ctx.error(path, f"{value!r} is below the minimum {self.min:g}{unit}")
        if self.max is not None and x > self.max:
            return ctx.error(path, f"{value!r} is above the maximum {self.max:g}{unit}")
        if self.gt is not None and x <= self.gt:
            return ctx.error(path, f"{value!r} must be greater than {self.gt:g}{unit}")
        if self.lt is not None and x >= self.lt:
            return ctx.error(path, f"{value!r} must be less than {self.lt:g}{unit}")
        return x


class Integer(Field):
    def __init__(self, default: Any = REQUIRED, *, min: int | None = None,
                 max: int | None = None, doc: str = ""):
        super().__init__(default, doc)
        self.min, self.max = min, max

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        if isinstance(value, bool) or not isinstance(value, int):
            if isinstance(value, float) and value.is_integer():
                value = int(value)
            else:
                return ctx.error(path, f"expected a whole number, got {value!r}")
        if self.min is not None and value < self.min:
            return ctx.error(path, f"{value} is below the minimum {self.min}")
        if self.max is not None and value > self.max:
            return ctx.error(path, f"{value} is above the maximum {self.max}")
        return value


class Text(Field):
    def __init__(self, default: Any = REQUIRED, *, choices: list[str] | None = None,
                 doc: str = ""):
        super().__init__(default, doc)
        self.choices = choices

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        if not isinstance(value, str):
            return ctx.error(path, f"expected text, got {value!r}")
        if self.choices is not None and value not in self.choices:
            return ctx.error(path, f"{value!r} is not one of: {', '.join(self.choices)}")
        return value


class SafeName(Text):
    """Text that may become a file or folder name: letters, digits, ``.``, ``_`` and ``-``, at
    most 100 characters, not starting with a dot or a dash (so never ``..``, a hidden file, an
    option, or a path with separators)."""

    PATTERN = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9._-]{0,99}$")

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        value = super().check(value, path, ctx)
        if isinstance(value, str) and not self.PATTERN.match(value):
            return ctx.error(path, f"{value!r} cannot be a file name: use letters, digits, '.', "
                             "'_' and '-' (at most 100, not starting with '.' or '-')")
        return value


class Boolean(Field):
    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        if not isinstance(value, bool):
            return ctx.error(path, f"expected true or false, got {value!r}")
        return value


LATEST_TIME = dt.datetime(2200, 1, 1)  # the latest start a scenario may give


class DateTime(Field):
    """An ISO 8601 UTC time, not before ``earliest`` (ISO text) if given; resolved to text
    ``YYYY-MM-DDTHH:MM:SS(.ffffff)Z``."""

    def __init__(self, default: Any = REQUIRED, *, earliest: str | None = None, doc: str = ""):
        super().__init__(default, doc)
        self.earliest = None if earliest is None else dt.datetime.fromisoformat(earliest)

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        if isinstance(value, dt.datetime):
            stamp = value
        elif isinstance(value, str):
            try:
                stamp = dt.datetime.fromisoformat(value.replace("Z", "+00:00"))
            except ValueError as exc:
                return ctx.error(path, f"{value!r} is not a valid ISO 8601 UTC time ({exc}; "
                                       "example: 2019-05-01T03:00:00Z)")
        else:
            return ctx.error(path, f"expected an ISO 8601 UTC time, got {value!r}")
        if stamp.tzinfo is not None:
            try:
                stamp = stamp.astimezone(dt.UTC).replace(tzinfo=None)
            except OverflowError:  # beyond year 1 or 9999 in UTC: the side its offset pushes
                stamp = dt.datetime.min if stamp.year == 1 else dt.datetime.max
        if stamp >= LATEST_TIME:
            return ctx.error(path, f"{value!r} is after {LATEST_TIME.isoformat()}Z: a drive "
                                   "starts before then (GPS weeks, leap seconds and the file "
                                   "formats' year fields are defined up to there)")
        if self.earliest is not None and stamp < self.earliest:
            return ctx.error(path, f"{stamp.isoformat()}Z is before {self.earliest.isoformat()}Z"
                                   " (the GPS epoch: GPS time and broadcast orbits start there)")
        return stamp.isoformat() + "Z"


class Vector(Field):
    """A list of ``n`` numbers of the same unit."""

    def __init__(self, n: int, item: Number, default: Any = REQUIRED, doc: str = ""):
        super().__init__(default, doc)
        self.n, self.item = n, item

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        if not isinstance(value, (list, tuple)) or len(value) != self.n:
            return ctx.error(path, f"expected a list of {self.n} numbers, got {value!r}")
        out = [self.item.check(v, path + (i,), ctx) for i, v in enumerate(value)]
        return INVALID if INVALID in out else out


class ListOf(Field):
    def __init__(self, item: Field, default: Any = REQUIRED, *, min_len: int = 0,
                 doc: str = ""):
        super().__init__(default, doc)
        self.item, self.min_len = item, min_len

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        if not isinstance(value, list):
            return ctx.error(path, f"expected a list, got {type(value).__name__}")
        if len(value) < self.min_len:
            return ctx.error(path, f"expected at least {self.min_len} item(s)")
        return [self.item.check(v, path + (i,), ctx) for i, v in enumerate(value)]


def _unknown_key(key: str, known: list[str]) -> str:
    close = difflib.get_close_matches(str(key), known, n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return f"unknown key{hint}; known keys: {', '.join(known)}"


class Record(Field):
    """A mapping with fixed keys. ``post(value, path, ctx)`` runs cross-field checks after the
    fields validated (only if none failed) and may return a completed value."""

    def __init__(self, fields: dict[str, Field], default: Any = REQUIRED, *,
                 post: Callable[[dict, Path, Context], Any] | None = None, doc: str = ""):
        super().__init__(default, doc)
        self.fields, self.post = fields, post

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        if value is None:
            value = {}
        if not isinstance(value, dict):
            return ctx.error(path, f"expected a mapping, got {value!r}")
        out: dict[str, Any] = {}
        failed = False
        for key in value:
            if key not in self.fields:
                ctx.error(path + (key,), _unknown_key(key, list(self.fields)))
                failed = True
        for key, field in self.fields.items():
            if key in value and value[key] is None and field.default is None:
                got = None  # an optional value given explicitly as null
            elif key in value:
                got = field.check(value[key], path + (key,), ctx)
            else:
                got = field.resolve_missing(path + (key,), ctx)
            failed |= _contains_invalid(got)
            out[key] = got
        if failed:
            return INVALID
        if self.post is not None:
            return self.post(out, path, ctx)
        return out


class MapOf(Field):
    """A mapping with free keys (names) and values of one field type."""

    def __init__(self, value: Field, default: Any = REQUIRED, doc: str = ""):
        super().__init__(default, doc)
        self.value = value

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        if value is None:
            value = {}
        if not isinstance(value, dict):
            return ctx.error(path, f"expected a mapping, got {value!r}")
        return {str(k): self.value.check(v, path + (k,), ctx) for k, v in value.items()}


class OneKey(Field):
    """A one-key mapping whose key picks the variant, such as ``{turn: {angle: 90, radius: 25}}``.

    The resolved value is ``{"kind": key, **fields}`` flattened back as ``{key: fields}``.
    """

    def __init__(self, variants: dict[str, Record], *, shared: dict[str, Field] | None = None,
                 what: str = "item", doc: str = ""):
        super().__init__(REQUIRED, doc)
        self.variants, self.shared, self.what = variants, shared or {}, what

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        if not isinstance(value, dict) or len(value) != 1:
            return ctx.error(path, f"expected a one-key mapping naming the {self.what} "
                                   f"({', '.join(self.variants)}), got {value!r}")
        (kind, body), = value.items()
        if kind not in self.variants:
            return ctx.error(path + (kind,), f"unknown {self.what}; known: "
                                             f"{', '.join(self.variants)}")
        record = self.variants[kind]
        merged = Record({**record.fields, **self.shared}, post=record.post)
        got = merged.check(body, path + (kind,), ctx)
        return INVALID if got is INVALID else {kind: got}


class Either(Field):
    """A value that is a plain name (``Text``) or a structured value (``Record``, ``ListOf``)."""

    def __init__(self, name: Text, record: Field, default: Any = REQUIRED, doc: str = ""):
        super().__init__(default, doc)
        self.name, self.record = name, record

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        if isinstance(value, str):
            return self.name.check(value, path, ctx)
        return self.record.check(value, path, ctx)


class Anything(Field):
    """Free-form content handed on unchanged (an estimator's own ``config``)."""

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        return value


def _contains_invalid(value: Any) -> bool:
    if value is INVALID:
        return True
    if isinstance(value, dict):
        return any(_contains_invalid(v) for v in value.values())
    if isinstance(value, list):
        return any(_contains_invalid(v) for v in value)
    return False


class Tagged(Field):
    """A mapping whose ``key`` (default ``kind``) picks the record that validates the rest."""

    def __init__(self, variants: dict[str, Record], default: Any = REQUIRED, *,
                 key: str = "kind", what: str = "kind", doc: str = ""):
        super().__init__(default, doc)
        self.variants, self.key, self.what = variants, key, what

    def check(self, value: Any, path: Path, ctx: Context) -> Any:
        if not isinstance(value, dict):
            return ctx.error(path, f"expected a mapping with a {self.key!r} key, got {value!r}")
        if self.key not in value:
            return ctx.error(path + (self.key,), f"missing required key (one of: "
                                                 f"{', '.join(self.variants)})")
        kind = value[self.key]
        if kind not in self.variants:
            return ctx.error(path + (self.key,), f"unknown {self.what} {kind!r}; known: "
                                                 f"{', '.join(self.variants) or 'none'}")
        record = self.variants[kind]
        body = {k: v for k, v in value.items() if k != self.key}
        got = record.check(body, path, ctx)
        return INVALID if got is INVALID else {self.key: kind, **got}
