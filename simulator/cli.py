"""The ``landnav`` command line (its commands in README.md, its formats in docs/). Each command
lives in its own module under ``simulator/commands/`` with ``add_parser(subparsers)`` and
``run(args) -> int``.

Bad input ends with one clear message per problem on stderr and exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import os
import sys

from simulator.commands import SUMMARIES
from simulator.errors import InputError

DESCRIPTION = """\
landnav: synthetic land-vehicle drives and navigation-sensor datasets, with estimator replay
and truth-referenced scoring.

A scenario (YAML) describes the drive, the sensors, the faults and the estimators to run.
Typical use:

  landnav validate scenarios/quickstart.yaml      check a scenario, list every problem
  landnav generate scenarios/quickstart.yaml -o out/quick   write the dataset
  landnav generate scenarios/garage.yaml -o out/g --set sensors.imu.rate=200 --seed 3
  landnav campaign scenarios/karamat2015_partial_outages.yaml --runs 20 -o out/mc

Run `landnav COMMAND --help` for each command's options. Reference documentation is in the
repository's docs/ folder: scenario-reference.md (every scenario key, generated from the
schema), dataset-format.md, solution-format.md, scores.md, faults.md, estimator_plugins.md.
"""


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser; only ``command``'s module is imported (all of them when None)."""
    parser = argparse.ArgumentParser(
        prog="landnav", description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, summary in SUMMARIES.items():
        if command in (None, name):
            importlib.import_module(f"simulator.commands.{name}").add_parser(sub)
        else:
            sub.add_parser(name, help=summary)
    return parser


# landnav multiplies small matrices (3 x 3 on long arrays, filters of a few dozen states) and
# runs its own worker threads: a multi-threaded OpenBLAS only adds thread wake-ups (up to 80 ms
# for one (n, 3) x (3, 3) product on a busy machine, against 1 ms on one thread). Set before the
# command imports numpy; a user's own setting wins.
BLAS_THREADS = {"OPENBLAS_NUM_THREADS": "1"}
_M_ARENA_MAX = -8  # mallopt parameter, glibc malloc.h


def _one_malloc_arena() -> None:
    """Let every thread allocate from one glibc heap (mallopt M_ARENA_MAX = 1) unless the user
    set MALLOC_ARENA_MAX. glibc gives each thread its own heap, so the arrays a worker thread
    frees are not reused by the others and every new array touches fresh pages: one arena cuts a
    generation's page faults by a third (a tenth of its CPU). Linux with glibc only; set before
    any thread starts. The few allocator calls of large arrays make the shared lock cheap."""
    if not sys.platform.startswith("linux") or "MALLOC_ARENA_MAX" in os.environ:
        return
    import ctypes

    try:
        ctypes.CDLL("libc.so.6").mallopt(_M_ARENA_MAX, 1)
    except (OSError, AttributeError):  # not glibc
        pass


def _command_name(argv: list[str]) -> str | None:
    return next((a for a in argv if not a.startswith("-")), None)


def main(argv: list[str] | None = None) -> int:
    for name, value in BLAS_THREADS.items():
        os.environ.setdefault(name, value)
    _one_malloc_arena()
    argv = sys.argv[1:] if argv is None else argv
    command = _command_name(argv)
    # importing the command makes some 100 000 objects that live to the end: no collections
    # while they are made, and none that scans them again later (about 10 ms of collections
    # that free nothing); unfrozen at the end, for callers that run several commands
    collecting = gc.isenabled()
    gc.disable()
    try:
        args = build_parser(command if command in SUMMARIES else None).parse_args(argv)
        gc.freeze()
        if collecting:
            gc.enable()
        return _run(args)
    finally:
        gc.unfreeze()
        if collecting:
            gc.enable()


def _run(args: argparse.Namespace) -> int:
    try:
        return int(args.run(args) or 0)
    except InputError as exc:
        for problem in exc.problems:
            print(f"error: {problem}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


# commands that run no user code and have written and closed every file when ``main`` returns:
# the program ends without the interpreter's teardown, whose finalisers of numpy and pyarrow
# take 40-60 ms (pandas' over 100 ms) and have nothing left to do
_EXIT_WITHOUT_TEARDOWN = {"generate"}


def program() -> None:
    """The ``landnav`` program: ``main`` on the command line, then the process ends with its
    exit code (without the interpreter's teardown after ``landnav generate``). Output into a
    pipe closed early (``landnav ... | head -1``) ends it quietly with code 1, as Python's
    documentation advises, instead of a traceback."""
    argv = sys.argv[1:]
    try:
        code = main(argv)
        sys.stdout.flush()
        sys.stderr.flush()
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # nothing more to write
        code = 1
    if _command_name(argv) in _EXIT_WITHOUT_TEARDOWN:
        os._exit(code)
    sys.exit(code)


if __name__ == "__main__":
    program()
