"""``landnav estimators [NAME]``: list the registered estimators, one line each, or describe one:
its paper, streams, output and every ``config`` key with its default, unit and meaning."""

from __future__ import annotations

import argparse
from typing import Any

from simulator.commands import SUMMARIES
from simulator.errors import InputError


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "estimators", help=SUMMARIES["estimators"],
        description="List the built-in estimators and those installed through the "
                    "landnav.estimators entry-point group: name, the streams each needs (and "
                    "takes if present), and the paper it follows. With NAME, describe that "
                    "estimator: its paper, streams, solution columns and every config key with "
                    "its default, unit and meaning (set them in a scenario entry's config: "
                    "mapping or with landnav estimate --set KEY=VALUE). Any estimator class can "
                    "also be named as module:Class without registering it.")
    p.add_argument("name", nargs="?", metavar="NAME",
                   help="an estimator to describe (registered name or module:Class)")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from estimators.registry import BUILTINS, list_estimators
    from simulator.isolated import call_isolated, needs_isolation

    if args.name:
        print(call_isolated(described, (args.name,), args.name)
              if needs_isolation(args.name, None) else described(args.name))
        return 0
    names = list_estimators()
    plugins = [name for name in names if name not in BUILTINS]
    lines = listed(names[:len(names) - len(plugins)])
    for name in plugins:  # installed plug-ins: each imported in a child, under a time limit
        try:
            lines += call_isolated(listed, ([name],), name)
        except InputError as exc:
            lines.append(f"{name}  (cannot be loaded: {exc.problems[0].file}: "
                         f"{exc.problems[0].message})")
    width = max(len(line.partition("  ")[0]) for line in lines)
    for line in lines:
        name, _, rest = line.partition("  ")
        print(f"{name:<{width}}  {rest}")
    return 0


def described(name: str) -> str:
    """What ``landnav estimators NAME`` prints (``describe``), the class imported here."""
    from estimators.registry import get_estimator

    return describe(get_estimator(name), name)


def listed(names: list[str]) -> list[str]:
    """One line per estimator, ``NAME  needs STREAMS  PAPER`` (or why it cannot be loaded),
    each class imported here."""
    from estimators.registry import get_estimator

    lines = []
    for name in names:
        try:
            cls = get_estimator(name)
        except InputError as exc:
            lines.append(f"{name}  (cannot be loaded: {exc.problems[0].message})")
            continue
        lines.append(f"{name}  needs {_streams(cls)}  {cls.paper}")
    return lines


def _streams(cls: type) -> str:
    text = ", ".join(cls.needs) or "-"
    return text + (f" (uses {', '.join(cls.uses)})" if cls.uses else "")


def describe(cls: type, name: str) -> str:
    """What ``landnav estimators NAME`` prints about one estimator class."""
    lines = [f"{name} ({cls.__module__}:{cls.__qualname__})",
             f"paper:   {cls.paper or '-'}",
             f"needs:   {', '.join(cls.needs) or '-'}",
             f"uses:    {', '.join(cls.uses) or '-'} (when the dataset has them)",
             f"output:  t, {', '.join(cls.output_columns)} (at {cls.output_rate_hz:g} Hz and "
             "after every GNSS epoch)",
             "initial: " + ("from its own first measurements" if cls.initialises_itself else
                            "the truth at its first message, perturbed by the entry's init"),
             ""]
    if not cls.defaults:
        return "\n".join([*lines, "config:  no keys"])
    lines.append("config (a scenario entry's config: mapping, or landnav estimate --set "
                 "KEY=VALUE):")
    rows = [(key, _default(value, cls.config_help.get(key, ("", ""))[0]),
             cls.config_help.get(key, ("", "(not described by the estimator)"))[1])
            for key, value in cls.defaults.items()]
    key_width = max(len(r[0]) for r in rows)
    value_width = min(max(len(r[1]) for r in rows), 40)
    lines += [f"  {k:<{key_width}}  {v:<{value_width}}  {meaning}" for k, v, meaning in rows]
    return "\n".join(lines)


def _default(value: Any, unit: str) -> str:
    """A default as YAML writes it, with its unit, and in datasheet units where they differ
    (``0.000349 rad/s/sqrt(Hz) = 1.2 deg/sqrt(h)``)."""
    from simulator.display_units import display

    if value is None:
        return "null"
    if isinstance(value, bool):
        return str(value).lower()
    numbers = isinstance(value, (int, float)) or (
        isinstance(value, (list, tuple)) and all(isinstance(x, (int, float)) for x in value))
    if not numbers:
        return str(value)
    text = (f"{value:.6g}" if isinstance(value, (int, float))
            else "[" + ", ".join(f"{x:.6g}" for x in value) + "]")
    if not unit:
        return text
    shown = display(list(value) if isinstance(value, (list, tuple)) else value, unit)
    text = f"{text} {unit}"
    return text if shown.split()[-1] == unit else f"{text} = {shown}"
