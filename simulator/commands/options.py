"""Options shared by the commands that read a scenario (``--seed``, ``--set``)."""

from __future__ import annotations

import argparse

from simulator.errors import InputError, Problem


def add_scenario_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--seed", type=int, default=None,
                        help="random seed (replaces the scenario's seed)")
    parser.add_argument("--set", dest="overrides", action="append", default=[],
                        metavar="KEY.PATH=VALUE",
                        help="override any scenario value, e.g. --set sensors.imu.rate=200 or "
                             "--set trajectory.segments.2.straight.length=500 (repeatable; "
                             "validated like the file and recorded in the manifest)")


def worker_problems(command: str, workers: int | None, scheduler: str | None) -> list[Problem]:
    """The problems of ``--workers`` and ``--scheduler`` (campaign, reproduce): both given, or
    fewer than one worker."""
    if workers is not None and scheduler:
        return [Problem(f"landnav {command}", None, "--workers", "a Dask cluster has its own "
                        "workers: give --workers or --scheduler, not both")]
    if workers is not None and workers < 1:
        return [Problem(f"landnav {command}", None, "--workers",
                        f"must be at least 1, got {workers}")]
    return []


MAX_TIME_LIMIT_S = 7 * 86400.0


def check_time_limit(seconds: float | None, command: str) -> None:
    """Refuse a ``--time-limit`` that is not a number of seconds in (0, a week] (nan, inf)."""
    if seconds is not None and not 0 < seconds <= MAX_TIME_LIMIT_S:
        raise InputError([Problem(f"landnav {command}", None, "--time-limit",
                                  f"must be a number of seconds in (0, {MAX_TIME_LIMIT_S:g}], "
                                  f"got {seconds}")])
