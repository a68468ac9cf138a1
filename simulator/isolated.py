"""One estimator replayed in a child process, under a time limit: what a plug-in does there
(exit the process, never return, crash in compiled code) ends the child, not landnav, and is
reported as the estimator's failure.

``run_isolated(dataset_path, entry, time_limit_s)`` starts ``python -m simulator.isolated``
(a fresh interpreter with this one's ``sys.path`` and folder; in a session of its own, so a
Ctrl-C reaches landnav, which then ends the child), hands it the request on its standard
input and reads the answer from its standard output: one byte once the dataset is open (the
time limit counts from there, not from the imports), then the pickled solution table and run
information, or the problems. A child that ends without answering, or is still running after
``time_limit_s`` (then killed), is one ``InputError`` naming the estimator. The child ends
itself when landnav's process is gone (``watch_parent``).

Public names
------------
run_isolated, needs_isolation, watch_parent, PARENT_POLL_S.
"""

from __future__ import annotations

import os
import pickle
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from estimators.registry import BUILTINS
from simulator.errors import InputError, Problem

PARENT_POLL_S = 0.5  # how often a child checks that the process it works for still runs
_STARTED = b"S"


def needs_isolation(entry: Mapping[str, Any] | str, time_limit_s: float | None) -> bool:
    """Whether to replay ``entry`` in a child: any estimator that is not a built-in (the
    user's or a third party's code), and any with a time limit; but never a class of the
    running program itself (``__main__:Class``, as a notebook defines one), which a child
    cannot import."""
    name = entry if isinstance(entry, str) else entry["name"]
    if name.partition(":")[0] == "__main__":
        return False
    return time_limit_s is not None or name not in BUILTINS


def watch_parent(parent_pid: int) -> None:
    """In a child process: a thread that kills the child when ``parent_pid`` is gone (killed
    with SIGKILL, say, which leaves it no chance to stop its children), so no child outlives
    the process it computes for."""
    def watch() -> None:
        while True:
            time.sleep(PARENT_POLL_S)
            try:
                os.kill(parent_pid, 0)
            except (ProcessLookupError, PermissionError):  # gone (or the id taken by another)
                os.kill(os.getpid(), signal.SIGKILL)  # nobody is left to receive the results

    threading.Thread(target=watch, name="landnav-parent-watch", daemon=True).start()


def _serve() -> None:
    """The child: read the request, answer on the standard output (module docstring)."""
    out = sys.stdout.buffer
    sys.stdout = sys.stderr  # a plug-in's prints must not mix into the answer
    parent_pid, path, dataset_path, entry = pickle.load(sys.stdin.buffer)
    watch_parent(parent_pid)
    sys.path[:] = path
    from simulator.dataset.io import open_dataset
    from simulator.replay import run_estimator

    try:
        dataset = open_dataset(dataset_path)
        out.write(_STARTED)
        out.flush()
        answer: tuple = ("ok", run_estimator(dataset, entry, show_progress=False))
    except InputError as exc:
        answer = ("error", exc.problems)
    out.write(pickle.dumps(answer, protocol=pickle.HIGHEST_PROTOCOL))
    out.flush()


def run_isolated(dataset_path: str | Path, entry: Mapping[str, Any] | str,
                 time_limit_s: float | None = None) -> tuple[Any, dict]:
    """``run_estimator`` of ``entry`` over the dataset at ``dataset_path``, in a child process.

    Raises
    ------
    InputError
        As ``run_estimator``; and when the estimator ends the child without a solution, or
        runs past ``time_limit_s`` (s; None: no limit).
    """
    name = entry if isinstance(entry, str) else entry["name"]
    where = f"estimator {name!r}"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    start = time.monotonic()
    child = subprocess.Popen([sys.executable, "-m", "simulator.isolated"], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, env=env, cwd=os.getcwd(),
                             start_new_session=True)
    received = bytearray()
    started = threading.Event()

    def read() -> None:
        while chunk := child.stdout.read1(1 << 20):
            received.extend(chunk)
            started.set()
        started.set()

    reader = threading.Thread(target=read, name="landnav-isolated-read", daemon=True)
    try:
        child.stdin.write(pickle.dumps((os.getpid(), list(sys.path), str(dataset_path), entry)))
        child.stdin.close()
        reader.start()
        started.wait()
        if received[:1] == _STARTED:
            reader.join(time_limit_s)
            if reader.is_alive():
                raise InputError([Problem(where, None, "", "did not finish within the time "
                                          f"limit of {time_limit_s:g} s; it was stopped (raise "
                                          "the limit with --time-limit if it is only slow)")])
        reader.join()
        code = child.wait()
        body = bytes(received[1:] if received[:1] == _STARTED else received)
        try:
            status, value = pickle.loads(body)
        except Exception:  # nothing, or half an answer: the child ended on the way
            raise InputError([Problem(where, None, "", f"ended its process (exit code {code}) "
                                      f"after {time.monotonic() - start:.1f} s without a "
                                      "solution; an estimator must return, not exit")]
                             ) from None
        if status == "error":
            raise InputError(value)
        return value
    finally:
        if child.poll() is None:
            child.kill()
        child.wait()
        for stream in (child.stdin, child.stdout):
            if not stream.closed:
                stream.close()


if __name__ == "__main__":
    _serve()
