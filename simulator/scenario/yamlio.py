"""Reading scenario YAML with the line of every key, and applying ``--set key.path=value``.

The reader is bounded: alias expansion and nesting depth are limited (``MAX_NODES``,
``MAX_DEPTH``), so a small "billion laughs" file or a self-referencing alias is refused with its
line instead of exhausting memory or the stack. Plain scalars that YAML 1.1 leaves as strings but
every reader means as numbers (``1.0e9``, ``1e-3``: YAML 1.1 wants a sign in the exponent and a dot
in the mantissa) are read as floats, and a timestamp that is not a real date (``2024-13-45``) is
left as its text, for the schema to report with every other problem of the file.

Public functions
----------------
read_yaml, apply_overrides, load_value.
"""

from __future__ import annotations

import os
import re
import stat
from pathlib import Path as FsPath
from typing import Any

import yaml

from simulator.errors import InputError, Problem

MAX_NODES = 200_000  # values built from one file, aliases expanded; a scenario has a few thousand
MAX_DEPTH = 64  # nesting of mappings and lists
MAX_FILE_BYTES = 64 * 2**20  # a scenario's text (the largest shipped one has a few kB)

# a number in scientific notation without the sign or dot YAML 1.1's float pattern requires
_PLAIN_FLOAT = re.compile(r"^[-+]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)[eE][-+]?[0-9]+$")


class _Budget:
    """What a file may still build: a node count and the mappings/lists open on the path."""

    def __init__(self) -> None:
        self.nodes = 0
        self.open: set[int] = set()


def _refuse(file: str, node: yaml.Node, path: tuple, message: str) -> InputError:
    return InputError([Problem(file, node.start_mark.line + 1, ".".join(map(str, path)),
                               message)])


def _scalar(node: yaml.ScalarNode, loader: yaml.SafeLoader) -> Any:
    if not node.style and node.tag == "tag:yaml.org,2002:str" and _PLAIN_FLOAT.match(
            node.value):
        return float(node.value)
    try:
        return loader.construct_object(node, deep=True)
    except (ValueError, OverflowError):
        # YAML's reading of the text failed (a timestamp that is no real date, 2024-13-45): the
        # text goes to the schema, whose field reports it with the file's other problems
        return node.value


def _construct(node: yaml.Node, loader: yaml.SafeLoader, path: tuple, lines: dict,
               file: str, budget: _Budget) -> Any:
    lines.setdefault(path, node.start_mark.line + 1)
    budget.nodes += 1
    if budget.nodes > MAX_NODES:
        raise _refuse(file, node, path, f"the file expands to more than {MAX_NODES} values "
                      "(aliases repeated inside aliases?); write the content out")
    if not isinstance(node, (yaml.MappingNode, yaml.SequenceNode)):
        return _scalar(node, loader)
    if len(path) >= MAX_DEPTH:
        raise _refuse(file, node, path, f"nested more than {MAX_DEPTH} levels deep")
    if id(node) in budget.open:
        raise _refuse(file, node, path, "an alias refers to a mapping or list that contains it")
    budget.open.add(id(node))
    try:
        return _construct_collection(node, loader, path, lines, file, budget)
    finally:
        budget.open.discard(id(node))


def _construct_collection(node: yaml.Node, loader: yaml.SafeLoader, path: tuple, lines: dict,
                          file: str, budget: _Budget) -> Any:
    if isinstance(node, yaml.MappingNode):
        loader.flatten_mapping(node)
        out: dict[Any, Any] = {}
        for key_node, value_node in node.value:
            key = loader.construct_object(key_node, deep=True)
            if not isinstance(key, (str, int, float, bool)):
                raise InputError([Problem(file, key_node.start_mark.line + 1, ".".join(
                    map(str, path)), f"a key must be plain text, got {key!r}")])
            if key in out:
                raise InputError([Problem(file, key_node.start_mark.line + 1,
                                          ".".join(map(str, path + (key,))), "duplicate key")])
            lines[path + (key,)] = key_node.start_mark.line + 1
            out[key] = _construct(value_node, loader, path + (key,), lines, file, budget)
        return out
    return [_construct(item, loader, path + (i,), lines, file, budget)
            for i, item in enumerate(node.value)]


def _read_text(path: str | FsPath, file: str) -> str:
    """The text of a regular file of at most ``MAX_FILE_BYTES``: a device (``/dev/zero``), a
    named pipe (which would wait for a writer) or a folder is refused, opened without waiting
    and without reading it."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise InputError([Problem(file, None, "", "not a regular file (a device, a pipe or "
                                      "a folder); give the scenario's YAML file")])
        with os.fdopen(fd, "rb", closefd=False) as stream:
            data = stream.read(MAX_FILE_BYTES + 1)
    finally:
        os.close(fd)
    if len(data) > MAX_FILE_BYTES:
        raise InputError([Problem(file, None, "", f"larger than a scenario may be "
                                  f"({MAX_FILE_BYTES / 2**20:g} MiB); is it the right file?")])
    return data.decode("utf-8")


def read_yaml(path: str | FsPath) -> tuple[Any, dict[tuple, int]]:
    """Read a YAML file; return its content and a map from key path to line number (1-based).

    Raises
    ------
    InputError
        If the file is missing, unreadable or not valid YAML (with the line of the fault).
    """
    file = str(path)
    try:
        text = _read_text(path, file)
    except FileNotFoundError:
        raise InputError([Problem(file, None, "", "file not found")]) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError([Problem(file, None, "", f"cannot read the file: {exc}")]) from None
    lines: dict[tuple, int] = {}
    try:
        data = _bounded_load(text, file, lines, {})
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else None
        message = " ".join(str(x) for x in (exc.context, exc.problem) if x)
        raise InputError([Problem(file, line, "", f"malformed YAML: {message}")]) from None
    except yaml.YAMLError as exc:
        raise InputError([Problem(file, None, "", f"malformed YAML: {exc}")]) from None
    except RecursionError:  # the pure-Python parser (no libyaml) recurses once per level
        raise InputError([Problem(file, None, "", f"malformed YAML: nested more than "
                                  f"{MAX_DEPTH} levels deep")]) from None
    return data, lines


def _bounded_load(text: str, file: str, lines: dict, empty: Any, fast: bool = True) -> Any:
    """YAML text built within ``MAX_NODES`` and ``MAX_DEPTH`` (``empty`` for no document).
    ``fast``: libyaml's parser when PyYAML has it (several times faster), else the pure-Python
    one, which also reads flow mappings without a space after the colon (``{fixed:[1,2]}``,
    as ``yaml.safe_load`` does; libyaml refuses them)."""
    loader_class = getattr(yaml, "CSafeLoader", yaml.SafeLoader) if fast else yaml.SafeLoader
    loader = loader_class(text)
    try:
        node = loader.get_single_node()
        return empty if node is None else _construct(node, loader, (), lines, file, _Budget())
    finally:
        loader.dispose()


def load_value(raw: str, where: str) -> Any:
    """A ``KEY=VALUE`` option's value read as YAML within the same bounds as a file (aliases,
    nesting); text that is not YAML stays text, a value beyond the bounds is an InputError."""
    try:
        value = _bounded_load(raw, where, {}, None, fast=False) if raw.strip() else ""
    except (yaml.YAMLError, ValueError, RecursionError):
        value = raw
    if isinstance(value, str) and _PLAIN_FLOAT.match(value.strip()):
        value = float(value)
    return value


def apply_overrides(data: Any, overrides: list[str], file: str) -> tuple[Any, set[tuple]]:
    """Apply ``key.path=value`` overrides (values read as YAML) to loaded scenario data.

    List items are addressed by index (``faults.0.duration=90``); missing mappings are created.
    Returns the changed data and the set of key paths that were overridden.
    """
    problems: list[Problem] = []
    touched: set[tuple] = set()
    for text in overrides:
        if "=" not in text:
            problems.append(Problem(file, "--set", text, "expected key.path=value"))
            continue
        key, raw = text.split("=", 1)
        try:
            value = load_value(raw, f"--set {key}")
        except InputError as exc:
            problems.extend(Problem(file, "--set", key, p.message) for p in exc.problems)
            continue
        parts: list[Any] = [int(p) if p.lstrip("-").isdigit() else p for p in key.split(".")]
        if len(parts) > MAX_DEPTH:
            problems.append(Problem(file, "--set", key[:80] + "...",
                                    f"the key path is more than {MAX_DEPTH} levels deep"))
            continue
        if not all(str(p) for p in parts):
            problems.append(Problem(file, "--set", key, "empty part in the key path"))
            continue
        node = data
        for i, part in enumerate(parts[:-1]):
            nxt = parts[i + 1]
            if isinstance(node, list) and isinstance(part, int) and -len(node) <= part < len(node):
                node = node[part]
            elif isinstance(node, dict):
                if part not in node or node[part] is None:
                    node[part] = [] if isinstance(nxt, int) else {}
                node = node[part]
            else:
                problems.append(Problem(file, "--set", key,
                                        f"{'.'.join(map(str, parts[:i + 1]))} does not exist"))
                node = None
                break
        if node is None:
            continue
        last = parts[-1]
        if isinstance(node, list) and isinstance(last, int):
            if -len(node) <= last < len(node):
                node[last] = value
            elif last == len(node):
                node.append(value)
            else:
                problems.append(Problem(file, "--set", key, f"list index {last} out of range"))
                continue
        elif isinstance(node, dict):
            node[last] = value
        else:
            problems.append(Problem(file, "--set", key, "cannot set a key inside a plain value"))
            continue
        touched.add(tuple(parts))
    if problems:
        raise InputError(problems)
    return data, touched
