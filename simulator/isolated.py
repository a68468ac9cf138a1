"""A plug-in's code run in a child process, under a time limit: importing it and checking its
config (``check_entries``), describing it (``call_isolated``), and replaying a dataset into it
(``run_isolated``). What a plug-in
does there (exit the process, hang or loop at import or in a handler, crash in compiled code,
print without end, fork processes that outlive it) ends the child, not landnav, and is
reported as the estimator's failure, naming the plug-in's file.

The child is ``python -m simulator.isolated``: a fresh interpreter with this one's ``sys.path``
and folder, in a session (and process group) of its own, so a Ctrl-C reaches landnav, which
then ends it. It reads the request on its standard input and writes its answer (the problems
found, or the pickled solution table and run information) to a file in a private temporary
folder, renamed there when complete. Its standard output is its standard error from the start,
so a plug-in's prints (Python's or a C library's) go to landnav's standard error, never into
landnav's results. On its standard output (the control channel) it sends one byte once its
own work is ready (the dataset open, landnav's modules imported), before any plug-in code runs,
and later why it could not write its answer (a full disk), if so: the time limit counts from
that byte, not from the interpreter's start, and counts the child's own time:
the wall time less the time it waited for a CPU that other processes held (Linux's
``/proc/PID/schedstat``; elsewhere the wall time), so that a loaded machine slows a plug-in
without stopping it. A child that ends without an
answer, or is still running at the limit, is one ``InputError`` naming the estimator and its
file. When the child has ended, every process left in its group (a plug-in's forks) is killed;
the child ends itself and its group when landnav's process is gone (``watch_parent``).

Public names
------------
check_entries, call_isolated, run_isolated, needs_isolation, watch_parent, PARENT_POLL_S,
CHECK_LIMIT_S.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

from estimators.registry import BUILTINS, entry_problems, plugin_file
from simulator.errors import InputError, Problem, storage_error

PARENT_POLL_S = 0.5  # how often a child checks that the process it works for still runs
# how long importing the plug-ins and checking their configs may take without --time-limit
CHECK_LIMIT_S = 120.0
_STARTED = b"S"
_ANSWER = "answer.pickle"
_PROGRESS = "checking"  # the index of the entry the check child is importing

Entry = Mapping[str, Any] | str


def _name(entry: Entry) -> str:
    return entry if isinstance(entry, str) else entry["name"]


def needs_isolation(entry: Entry, time_limit_s: float | None) -> bool:
    """Whether to run ``entry`` in a child: any estimator that is not a built-in (the
    user's or a third party's code), and any with a time limit; but never a class of the
    running program itself (``__main__:Class``, as a notebook defines one), which a child
    cannot import."""
    name = _name(entry)
    if name.partition(":")[0] == "__main__":
        return False
    return time_limit_s is not None or name not in BUILTINS


def watch_parent(parent_pid: int, whole_group: bool = False) -> None:
    """In a child process: a thread that kills the child when ``parent_pid`` is gone (killed
    with SIGKILL, say, which leaves it no chance to stop its children), so no child outlives
    the process it computes for; with ``whole_group``, every process of the child's process
    group (the child leads its own: a plug-in's forks) too."""
    def watch() -> None:
        while True:
            time.sleep(PARENT_POLL_S)
            try:
                os.kill(parent_pid, 0)
            except (ProcessLookupError, PermissionError):  # gone (or the id taken by another)
                # nobody is left to receive the results
                if whole_group:
                    os.killpg(0, signal.SIGKILL)
                os.kill(os.getpid(), signal.SIGKILL)

    threading.Thread(target=watch, name="landnav-parent-watch", daemon=True).start()


def _write_answer(folder: Path, name: str, value: object) -> None:
    """``value`` pickled into ``folder/name``, written under a name of this process's own
    (a plug-in's fork may answer too) and renamed when complete."""
    tmp = folder / f".{name}.{os.getpid()}"
    tmp.write_bytes(pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL))
    os.replace(tmp, folder / name)


def _checked(entries: Sequence[Entry], folder: Path) -> list[list[tuple[str, str]]]:
    """In the check child: ``entry_problems`` of each entry, the index of the one being
    imported written first (the parent names it if the child never answers)."""
    out = []
    for i, entry in enumerate(entries):
        _write_answer(folder, _PROGRESS, i)
        out.append(entry_problems(entry))
    return out


def _serve() -> None:
    """The child: read the request, answer into its folder (module docstring)."""
    parent_pid, path, folder, request = pickle.load(sys.stdin.buffer)
    sys.stdout.flush()
    control = os.dup(1)  # the control channel, not inherited by the processes a plug-in starts
    os.dup2(2, 1)  # everything written to the standard output goes to the standard error
    watch_parent(parent_pid, whole_group=True)
    sys.path[:] = path
    kind, *args = request

    def started() -> None:
        os.write(control, _STARTED)

    try:
        if kind == "check":
            started()
            answer: tuple = ("ok", _checked(args[0], Path(folder)))
        elif kind == "call":
            function, arguments = args
            started()
            answer = ("ok", function(*arguments))
        else:
            from simulator.dataset.io import open_dataset
            from simulator.replay import run_estimator

            dataset_path, entry = args
            dataset = open_dataset(dataset_path)
            started()
            answer = ("ok", run_estimator(dataset, entry, show_progress=False))
    except InputError as exc:
        answer = ("error", exc.problems)
    try:
        _write_answer(Path(folder), _ANSWER, answer)
    except OSError as exc:  # a full disk: said on the control channel, read by the parent
        os.write(control, f"{exc.errno or 0} {exc.strerror or exc}".encode())
        sys.exit(1)


def _runqueue_wait_s(pid: int) -> float:
    """How long the main thread of process ``pid`` has waited for a CPU held by other
    processes, s (Linux's ``/proc/PID/schedstat``; 0 where it cannot be read)."""
    try:
        return int(Path(f"/proc/{pid}/schedstat").read_text().split()[1]) / 1e9
    except (OSError, IndexError, ValueError):
        return 0.0


def _waited(pid: int, limit_s: float | None) -> bool:
    """Whether the child ``pid`` ended within ``limit_s`` of its own time (None: waits for it),
    leaving it unreaped: its id, and so its process group's, stays taken until ``_end`` kills
    the group. Its own time is the wall time less the time it waited for a CPU (a loaded
    machine slows a plug-in; it does not make it run past its limit)."""
    ended = threading.Event()

    def wait() -> None:
        with contextlib.suppress(ChildProcessError):  # reaped meanwhile by _end
            os.waitid(os.P_PID, pid, os.WEXITED | os.WNOWAIT)
        ended.set()

    threading.Thread(target=wait, name="landnav-isolated-wait", daemon=True).start()
    if limit_s is None:
        return ended.wait()
    start, waited_before = time.monotonic(), _runqueue_wait_s(pid)
    while True:
        used = time.monotonic() - start - (_runqueue_wait_s(pid) - waited_before)
        if used >= limit_s:
            return ended.is_set()
        if ended.wait(max(limit_s - used, 0.05)):  # its own time grows at most as fast
            return True


def _end(child: subprocess.Popen) -> None:
    """Kill every process of the child's group (the child if it still runs, a plug-in's
    forks), then reap the child."""
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(child.pid, signal.SIGKILL)
    child.wait()


@contextlib.contextmanager
def _child(request: tuple) -> Iterator[tuple[subprocess.Popen, Path, bool]]:
    """A started child serving ``request``: the process, its answer folder and whether it
    reached the point where plug-in code runs (its byte); the group ended and the folder
    removed on the way out, however that is."""
    folder = Path(tempfile.mkdtemp(prefix="landnav-isolated-"))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    child = subprocess.Popen([sys.executable, "-m", "simulator.isolated"], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, env=env, cwd=os.getcwd(),
                             start_new_session=True)
    try:
        with child.stdin:
            child.stdin.write(pickle.dumps((os.getpid(), list(sys.path), str(folder), request)))
        # b"" if it ended before; unbuffered: what follows is read by _said
        started = os.read(child.stdout.fileno(), 1) == _STARTED
        yield child, folder, started
    finally:
        _end(child)
        child.stdout.close()
        shutil.rmtree(folder, ignore_errors=True)


def _said(child: subprocess.Popen, folder: Path) -> str:
    """Why an ended child wrote no answer into ``folder``, as it said on its control channel
    after its first byte (``ERRNO REASON``), "" when nothing.

    Raises
    ------
    StorageError
        The storage refused the answer (no space, a file size limit): named by the folder
        the private one was made in.
    """
    os.set_blocking(child.stdout.fileno(), False)  # a plug-in's fork may hold it open
    try:
        said = os.read(child.stdout.fileno(), 2000).decode("utf-8", "replace")
    except BlockingIOError:
        return ""
    code, _, reason = said.partition(" ")
    if not code.isdigit():
        return said
    refused = storage_error(folder.parent, OSError(int(code), reason))
    if refused is not None:
        raise refused
    return f"cannot hand its answer back through {folder}: {reason}"


def _answer(folder: Path, name: str) -> Any:
    """The child's answer in ``folder`` (None when it wrote none)."""
    try:
        return pickle.loads((folder / name).read_bytes())
    except FileNotFoundError:
        return None


def _where(entry: Entry) -> str:
    """``estimator 'NAME' (its module's file)``, the file found without running it."""
    name = _name(entry)
    file = plugin_file(name)
    return f"estimator {name!r}" + (f" ({file})" if file else "")


def _ended(child: subprocess.Popen, started: float) -> str:
    code = child.poll()
    how = f"was killed by signal {-code}" if code is not None and code < 0 else (
        f"exit code {code}")
    return f"ended its process ({how}) after {time.monotonic() - started:.1f} s"


def check_entries(entries: Sequence[Entry], time_limit_s: float | None = None
                  ) -> list[list[tuple[str, str]]]:
    """``entry_problems`` of each estimator entry (the class imports, its config fits): a
    built-in's here, the others' (``needs_isolation``) in one child process that may take
    ``time_limit_s`` (s; None: ``CHECK_LIMIT_S``) from when it starts importing them. A plug-in
    that hangs, exits or crashes while imported or checked is the problem of its entry (the
    entries after it are left unchecked: there is a problem to fix first)."""
    out: list[list[tuple[str, str]]] = []
    plugins: dict[bytes, list[int]] = {}  # one check for equal entries (a campaign's points)
    for i, entry in enumerate(entries):
        if needs_isolation(entry, None):
            plugins.setdefault(pickle.dumps(entry), []).append(i)
            out.append([])
        else:
            out.append(entry_problems(entry))
    if not plugins:
        return out
    unique = [entries[at[0]] for at in plugins.values()]
    limit = CHECK_LIMIT_S if time_limit_s is None else time_limit_s
    with _child(("check", unique)) as (child, folder, started):
        start = time.monotonic()
        finished = _waited(child.pid, limit if started else None)
        answer = _answer(folder, _ANSWER) if finished else None
        if answer is None:
            at = _answer(folder, _PROGRESS) or 0
            what = (f"importing it and checking its config did not finish within {limit:g} s; "
                    "it was stopped (a plug-in's module must not wait or loop when imported; "
                    "--time-limit sets this bound)" if not finished else
                    _said(child, folder) or f"{_ended(child, start)} while being imported and "
                    "checked, without an answer; a plug-in's module must not exit or crash when "
                    "imported")
            answer = ("ok", [[] for _ in unique])
            answer[1][at] = [("name", f"{_where(unique[at])}: {what}")]
    status, checked = answer
    if status == "error":
        raise InputError(checked)
    for problems, at in zip(checked, plugins.values(), strict=True):
        for i in at:
            out[i] = problems
    return out


def _answered(request: tuple, entry: Entry, time_limit_s: float | None, overrun: str,
              no_answer: str) -> Any:
    """The answer of a child serving ``request`` for the plug-in ``entry`` within
    ``time_limit_s`` (s of its own time; None: no limit); an InputError naming the estimator
    and its file with ``overrun`` when it runs past the limit, with ``no_answer`` when it ends
    without an answer (after how it ended), and the problems it answered with."""
    with _child(request) as (child, folder, started):
        start = time.monotonic()
        if not _waited(child.pid, time_limit_s if started else None):
            raise InputError([Problem(_where(entry), None, "", overrun)])
        answer = _answer(folder, _ANSWER)
        if answer is None:
            raise InputError([Problem(_where(entry), None, "", _said(child, folder) or (
                f"{_ended(child, start)} {no_answer}"))])
    status, value = answer
    if status == "error":
        raise InputError(value)
    return value


def call_isolated(function: Callable[..., Any], arguments: tuple, entry: Entry,
                  time_limit_s: float | None = None) -> Any:
    """``function(*arguments)`` in a child process, bounded by ``time_limit_s`` (s; None:
    ``CHECK_LIMIT_S``): a
    function of landnav's own (found by its module and name) that imports the plug-in
    ``entry`` names and returns plain data (text, numbers), so that nothing of the plug-in is
    unpickled here.

    Raises
    ------
    InputError
        As ``function``; and when the child ends without an answer or runs past the limit,
        naming the estimator and its file.
    """
    limit = CHECK_LIMIT_S if time_limit_s is None else time_limit_s
    return _answered(("call", function, arguments), entry, limit,
                     f"importing it did not finish within {limit:g} s; it was stopped "
                     "(a plug-in's module must not wait or loop when imported)",
                     "while being imported, without an answer; a plug-in's module must not "
                     "exit or crash when imported")


def run_isolated(dataset_path: str | Path, entry: Entry,
                 time_limit_s: float | None = None) -> tuple[Any, dict]:
    """``run_estimator`` of ``entry`` over the dataset at ``dataset_path``, in a child process.

    Raises
    ------
    InputError
        As ``run_estimator``; and when the estimator ends the child without a solution, or
        runs past ``time_limit_s`` (s; None: no limit).
    """
    return _answered(("replay", str(dataset_path), entry), entry, time_limit_s,
                     f"did not finish within the time limit of {time_limit_s or 0:g} s; it "
                     "was stopped (raise the limit with --time-limit if it is only slow)",
                     "without a solution; an estimator must return, not exit")


if __name__ == "__main__":
    _serve()
