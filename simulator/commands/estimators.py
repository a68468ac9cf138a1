"""``landnav estimators``: list the registered estimators, one line each."""

from __future__ import annotations

import argparse

from simulator.commands import SUMMARIES


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "estimators", help=SUMMARIES["estimators"],
        description="List the built-in estimators and those installed through the "
                    "landnav.estimators entry-point group: name, the streams each needs (and "
                    "takes if present), and the paper it follows. Any estimator class can also "
                    "be named as module:Class without registering it.")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from estimators.registry import get_estimator, list_estimators
    from simulator.errors import InputError

    names = list_estimators()
    width = max(len(n) for n in names)
    for name in names:
        try:
            cls = get_estimator(name)
        except InputError as exc:
            print(f"{name:<{width}}  (cannot be loaded: {exc.problems[0].message})")
            continue
        streams = ", ".join(cls.needs) or "-"
        if cls.uses:
            streams += f" (uses {', '.join(cls.uses)})"
        print(f"{name:<{width}}  needs {streams}  {cls.paper}")
    return 0
