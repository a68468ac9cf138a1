"""``landnav schema``: print the JSON Schema of the scenario file (for editor completion)."""

from __future__ import annotations

import argparse
import json

from simulator.commands import SUMMARIES


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "schema", help=SUMMARIES["schema"],
        description="Print the JSON Schema (draft 2020-12) of a scenario file, made from the "
                    "same schema `landnav validate` checks (docs/scenario-reference.md). Point "
                    "an editor's YAML support at it for completion and checking, e.g. "
                    "`landnav schema > scenario.schema.json` and the yaml-language-server line "
                    "`# yaml-language-server: $schema=scenario.schema.json`. Cross-field rules "
                    "(physics limits, zone names) are only checked by `landnav validate`.")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from simulator.scenario.reference import json_schema

    print(json.dumps(json_schema(), indent=1))
    return 0
