"""One estimator replayed in a child process, under a time limit: what a plug-in does there
(exit the process, never return, crash in compiled code) ends the child, not landnav, and is
reported as the estimator's failure.

``run_isolated(dataset_path, entry, time_limit_s)`` starts the child (``forkserver``, or
``spawn`` where there is none), which opens the dataset and runs
``simulator.replay.run_estimator``; the solution table and run information come back through
a pipe. A child that ends without sending them, or is still running after ``time_limit_s``
(then killed), is one ``InputError`` naming the estimator. An interruption of landnav ends the
child too.

Public names
------------
run_isolated, needs_isolation.
"""

from __future__ import annotations

import multiprocessing
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pandas as pd

from estimators.registry import BUILTINS
from simulator.errors import InputError, Problem


def needs_isolation(entry: Mapping[str, Any] | str, time_limit_s: float | None) -> bool:
    """Whether to replay ``entry`` in a child: any estimator that is not a built-in (the
    user's or a third party's code), and any with a time limit; but never a class of the
    running program itself (``__main__:Class``, as a notebook defines one), which a child
    cannot import."""
    name = entry if isinstance(entry, str) else entry["name"]
    if name.partition(":")[0] == "__main__":
        return False
    return time_limit_s is not None or name not in BUILTINS


def _child(dataset_path: str, entry: Mapping[str, Any] | str, conn: Any) -> None:
    from simulator.dataset.io import open_dataset
    from simulator.replay import run_estimator

    try:
        dataset = open_dataset(dataset_path)
        conn.send(("started", None))  # the time limit counts from here, not from the imports
        result: tuple = ("ok", run_estimator(dataset, entry, show_progress=False))
    except InputError as exc:
        result = ("error", exc.problems)
    conn.send(result)
    conn.close()


def _receive(receive: Any, child: Any, where: str, start: float) -> tuple[str, Any]:
    """The child's next message; InputError when it ended without sending one."""
    try:
        return receive.recv()
    except (EOFError, OSError):
        child.join(5.0)
        raise InputError([Problem(where, None, "", f"ended its process (exit code "
                                  f"{child.exitcode}) after {time.monotonic() - start:.1f} s "
                                  "without a solution; an estimator must return, not "
                                  "exit")]) from None


def _context() -> multiprocessing.context.BaseContext:
    method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
    return multiprocessing.get_context(method)


def run_isolated(dataset_path: str | Path, entry: Mapping[str, Any] | str,
                 time_limit_s: float | None = None) -> tuple[pd.DataFrame, dict]:
    """``run_estimator`` of ``entry`` over the dataset at ``dataset_path``, in a child process.

    Raises
    ------
    InputError
        As ``run_estimator``; and when the estimator ends the child without a solution, or
        runs past ``time_limit_s`` (s; None: no limit).
    """
    name = entry if isinstance(entry, str) else entry["name"]
    where = f"estimator {name!r}"
    context = _context()
    receive, send = context.Pipe(duplex=False)
    child = context.Process(target=_child, args=(str(dataset_path), entry, send),
                            name=f"landnav-estimator-{name}", daemon=True)
    start = time.monotonic()
    child.start()
    send.close()  # the child holds the only writing end: its end is our EOF
    try:
        status, value = _receive(receive, child, where, start)
        if status == "started":
            if not receive.poll(time_limit_s):
                raise InputError([Problem(where, None, "", "did not finish within the time "
                                          f"limit of {time_limit_s:g} s; it was stopped (raise "
                                          "the limit with --time-limit if it is only slow)")])
            status, value = _receive(receive, child, where, start)
        if status == "error":
            raise InputError(value)
        return value
    finally:
        receive.close()
        if child.is_alive():
            child.kill()
        child.join(5.0)
