"""The ``landnav`` command line (its commands in README.md, its formats in docs/). Each command
lives in its own module under ``simulator/commands/`` with ``add_parser(subparsers)`` and
``run(args) -> int``.

Bad input ends with one clear message per problem on stderr and exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import multiprocessing
import os
import signal
import sys
import threading
from types import FrameType

from simulator import __version__
from simulator.commands import MODULES, SUMMARIES
from simulator.errors import InputError, Terminated

DESCRIPTION = """\
landnav: synthetic land-vehicle drives and navigation-sensor datasets, with estimator replay
and truth-referenced scoring.

A scenario (YAML) describes the drive, the sensors, the faults and the estimators to run.
Typical use:

  landnav run scenarios/quickstart.yaml -o runs/quickstart   the main job: dataset, estimators,
                                                  scores, runs/quickstart/report.html
  landnav validate scenarios/quickstart.yaml      check a scenario, list every problem
  landnav generate scenarios/parking_garage.yaml -o out/g --set sensors.imu.rate=200 --seed 3
  landnav estimators ins_odo_ekf                  an estimator's streams and config keys
  landnav campaign scenarios/karamat2015_partial_outages.yaml --runs 20 -o out/mc

Run `landnav COMMAND --help` for each command's options. Reference documentation is in the
repository's docs/ folder: scenario-reference.md (every scenario key, generated from the
schema), dataset-format.md, solution-format.md, scores.md, faults.md, estimator_plugins.md.
"""


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser; only ``command``'s module is imported (none when None: ``landnav --help``
    needs only the one-line summaries). A command module imports what its work needs inside
    its ``run``, so that ``landnav COMMAND --help`` imports no numerical library."""
    parser = argparse.ArgumentParser(
        prog="landnav", description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"landnav {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, summary in SUMMARIES.items():
        if command == name:
            module = MODULES.get(name, name)
            importlib.import_module(f"simulator.commands.{module}").add_parser(sub)
        else:
            sub.add_parser(name, help=summary)
    return parser


# landnav multiplies small matrices (3 x 3 on long arrays, filters of a few dozen states) and
# runs its own worker threads: a multi-threaded OpenBLAS only adds thread wake-ups (up to 80 ms
# for one (n, 3) x (3, 3) product on a busy machine, against 1 ms on one thread). Set before the
# command imports numpy; a user's own setting wins.
BLAS_THREADS = {"OPENBLAS_NUM_THREADS": "1"}


def _command_name(argv: list[str]) -> str | None:
    return next((a for a in argv if not a.startswith("-")), None)


def main(argv: list[str] | None = None) -> int:
    """The ``landnav`` program (the console script): run one command, return its exit code.
    Output into a pipe closed early (``landnav ... | head -1``) ends it quietly with code 1, as
    Python's documentation advises, instead of a traceback; a full or failing standard output
    is one message and code 2; a closed one loses what is printed."""
    for name, value in BLAS_THREADS.items():
        os.environ.setdefault(name, value)
    argv = sys.argv[1:] if argv is None else argv
    command = _command_name(argv)
    args = build_parser(command).parse_args(argv)
    if sys.stdout is None:  # started with its standard output closed: what it says is lost
        sys.stdout = open(os.devnull, "w", encoding="utf-8")  # noqa: SIM115 (open to the end)
    try:
        code = _run(args)
        sys.stdout.flush()
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # nothing more to write
        return 1
    except OSError as exc:  # the standard output is full or failing (the files are written)
        if exc.filename is not None:  # a file's error that no writer named: not the output
            print(f"error: {exc.filename}: {exc.strerror or exc}", file=sys.stderr)
            return 2
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        print(f"error: cannot write to the standard output: {exc.strerror or exc}",
              file=sys.stderr)
        return 2
    return code


_MULTIPROCESSING_DIR = os.path.dirname(multiprocessing.__file__)


def _in_critical_section(frame: FrameType | None) -> bool:
    """Whether the interrupted code is an import or the start of a child process (the import
    system or ``multiprocessing`` on its stack)."""
    while frame is not None:
        name = frame.f_code.co_filename
        if name.startswith("<frozen importlib") or name.startswith(_MULTIPROCESSING_DIR):
            return True
        frame = frame.f_back
    return False


def _stop(signum: int, frame: FrameType | None) -> None:
    """SIGTERM and SIGINT: raise ``Terminated`` or ``KeyboardInterrupt`` in the main thread, so
    every ``with`` block unwinds and removes its temporaries. Not during an import or while a
    worker process is being started: an exception between the import system's taking and
    releasing its global lock would leave the lock held and hang every thread that imports (and
    a module's own bare ``except:`` may swallow it), and one inside a process start leaves a
    child half made that no one can stop; there the signal is retried 20 ms later."""
    if _in_critical_section(frame):
        _deferred.append(signum)
        signal.setitimer(signal.ITIMER_REAL, 0.02)
        return
    raise KeyboardInterrupt if signum == signal.SIGINT else Terminated(signum)


def _retry(signum: int, frame: FrameType | None) -> None:
    if _deferred:
        _stop(_deferred.pop(), frame)


_deferred: list[int] = []


def _install_stop_handlers() -> dict[int, object]:
    """Handlers for SIGTERM, SIGINT (unless ignored, as in a background job) and the retry
    timer; returns the previous ones."""
    previous = {signal.SIGTERM: signal.signal(signal.SIGTERM, _stop),
                signal.SIGALRM: signal.signal(signal.SIGALRM, _retry)}
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:
        previous[signal.SIGINT] = signal.signal(signal.SIGINT, _stop)
    return previous


def _run(args: argparse.Namespace) -> int:
    previous = {}
    if threading.current_thread() is threading.main_thread():
        previous = _install_stop_handlers()
    try:
        try:
            return int(args.run(args) or 0)
        except InputError as exc:  # a signal while this prints ends it as below
            for problem in exc.problems:
                print(f"error: {problem}", file=sys.stderr)
            return 2
    except KeyboardInterrupt:
        print("interrupted: unfinished outputs were removed", file=sys.stderr)
        return 130
    except Terminated:
        print("terminated: unfinished outputs were removed", file=sys.stderr)
        return 143
    finally:
        if previous:
            signal.setitimer(signal.ITIMER_REAL, 0)
        for signum, handler in previous.items():
            signal.signal(signum, handler)


if __name__ == "__main__":
    sys.exit(main())
