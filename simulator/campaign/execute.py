"""Where campaign runs execute: local worker processes, or a Dask cluster given by its scheduler
address. Both are driven as ``concurrent.futures`` executors, with a bounded number of runs in
flight so that an interrupted campaign has little work under way.

Local processes come from a ``forkserver`` whose preloaded worker module is forked for each
process (fast start, and no fork of a parent that runs threads; ``spawn`` where there is no
forkserver, or where the temporary folder's path is too long for its socket). Each leads a
process group of its own, which holds what a plug-in estimator forks there; when the pool
ends, every worker's group is killed, so nothing a plug-in started outlives the campaign (nor
the campaign's process: a worker ends its group when that process is gone). On Ctrl-C or
SIGTERM the campaign stops its workers with SIGTERM, on which a worker abandons its run and
removes the run's temporaries; nothing of an unfinished run is recorded.
A worker process that dies (a crash inside an estimator's compiled code, the out-of-memory
killer) fails the runs that were under way in the pool, and a new pool takes the next runs.

Public functions
----------------
open_executor, completed.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import multiprocessing
import os
import re
import signal
import socket
import tempfile
import threading
from collections.abc import Callable, Iterable, Iterator
from typing import Any, TypeVar

from simulator.errors import InputError, Problem, Terminated
from simulator.isolated import watch_parent

T = TypeVar("T")
_WORKER_MODULE = "simulator.campaign.worker"  # preloaded by the forkserver


class _RenewingPool(cf.Executor):
    """A local process pool that is replaced by a new one when a worker process has died; on
    its way out every worker is ended with its process group."""

    def __init__(self, workers: int):
        self.workers = workers
        if "forkserver" in multiprocessing.get_all_start_methods() and _socket_fits():
            self.context = multiprocessing.get_context("forkserver")
            self.context.set_forkserver_preload([_WORKER_MODULE])
        else:  # Windows, or a temporary folder too deep for the forkserver's socket
            self.context = multiprocessing.get_context("spawn")
        self.pool = self._new()
        self.started: set[int] = set()  # the ids of the worker processes, dead ones included

    def _new(self) -> cf.ProcessPoolExecutor:
        return cf.ProcessPoolExecutor(self.workers, mp_context=self.context,
                                      initializer=_start_worker, initargs=(os.getpid(),))

    def __exit__(self, kind: type | None, *rest: object) -> bool:
        # every run is in, or the campaign stops: a stuck run must not hold it
        self.shutdown(wait=False, cancel_futures=True)
        self.terminate_workers()
        self.shutdown(wait=True)  # the pool, its workers gone, winds down at once
        self.end_orphaned_groups()
        return False

    @staticmethod
    def terminate_workers() -> None:
        """SIGTERM to every worker process still running (or still starting), which ends it
        with its process group (``_stop_worker``); SIGKILL to the group of one that does not
        end within 2 s. The campaign's only child processes are its pools' workers."""
        children = multiprocessing.active_children()
        for process in children:
            process.terminate()
        for process in children:  # gone before this process ends and frees their queues
            process.join(2.0)
            if process.is_alive():
                _kill_group(process.pid)
                process.join(1.0)

    def end_orphaned_groups(self) -> None:
        """SIGKILL to the process group of every worker that has died (killed from outside,
        it could not end its group): what a plug-in forked there. Only for an id that no
        process holds now: the group is then one of its own processes, or none."""
        for pid in self.started:
            try:
                os.kill(pid, 0)
            except ProcessLookupError:
                _kill_group(pid)
            except PermissionError:  # the id taken by another user's process
                pass
        self.started = {p.pid for p in multiprocessing.active_children()}

    def submit(self, fn: Callable, /, *args: Any, **kwargs: Any) -> cf.Future:
        try:
            future = self.pool.submit(_in_worker, fn, *args, **kwargs)
        except (cf.BrokenExecutor, EOFError, OSError):  # a worker died, or could not start
            self.pool.shutdown(wait=False)
            self.end_orphaned_groups()
            self.pool = self._new()
            future = self.pool.submit(_in_worker, fn, *args, **kwargs)
        self.started.update(p.pid for p in multiprocessing.active_children())
        return future

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        self.pool.shutdown(wait=wait, cancel_futures=cancel_futures)


def _socket_fits() -> bool:
    """Whether the forkserver's Unix socket, ``TMPDIR/pymp-XXXXXXXX/listener-XXXXXXXX``, fits
    the length a socket's path may have (107 bytes on Linux, 103 on macOS): in a deeper
    temporary folder the workers are spawned instead (each imports the worker module itself,
    a second or two more at its start)."""
    return len(os.fsencode(tempfile.gettempdir())) + len("/pymp-12345678/listener-12345678") <= 103


def _kill_group(pid: int) -> None:
    """SIGKILL to the process group led by ``pid`` (where there are process groups)."""
    if hasattr(os, "killpg"):
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(pid, signal.SIGKILL)


_in_run = False  # in a worker process: whether it is running a task


def _in_worker(fn: Callable, /, *args: Any, **kwargs: Any) -> Any:
    """``fn(*args, **kwargs)`` in a worker process; stopped (SIGTERM), the task unwinds (its
    temporaries removed), then the worker ends with its process group."""
    global _in_run
    _in_run = True
    try:
        return fn(*args, **kwargs)
    except Terminated:
        _kill_group(os.getpid())
        raise
    finally:
        _in_run = False


def _stop_worker(signum: int, frame: object) -> None:
    """SIGTERM in a worker: unwind the task under way (``_in_worker``), or, idle, end the
    worker with its process group at once."""
    if _in_run:
        raise Terminated(signum)
    _kill_group(os.getpid())


def _start_worker(parent_pid: int) -> None:
    """A local worker process starts: the leader of a process group of its own, which holds
    what a plug-in forks there and is ended with the worker (``_stop_worker``), and when
    ``parent_pid`` (the campaign's process) is gone (``watch_parent``)."""
    own_group = hasattr(os, "setpgid")
    if own_group:
        os.setpgid(0, 0)
        signal.signal(signal.SIGTERM, _stop_worker)
    watch_parent(parent_pid, whole_group=own_group)


@contextlib.contextmanager
def open_executor(workers: int, scheduler: str | None, timeout_s: float
                  ) -> Iterator[tuple[cf.Executor, int]]:
    """An executor and how many runs to keep in flight on it.

    Parameters
    ----------
    workers : number of local worker processes (ignored with ``scheduler``).
    scheduler : address of a Dask scheduler (``tcp://host:port``), or None for local processes.
    timeout_s : how long to try to reach the scheduler, s.

    Raises
    ------
    InputError
        When the scheduler does not answer within ``timeout_s``.
    """
    if scheduler is None:
        with _RenewingPool(workers) as executor:
            yield executor, workers
        return
    _check_scheduler(scheduler, timeout_s)
    client = _connect(scheduler, timeout_s)
    try:
        slots = max(1, sum(client.nthreads().values()))
        yield client.get_executor(pure=False), 2 * slots
    finally:
        client.close()


_ADDRESS = re.compile(r"^(?:(?:tcp|tls|ws|wss)://)?(\[[0-9A-Fa-f:]+\]|[A-Za-z0-9._-]+):(\d{1,5})/?$")


def _check_scheduler(address: str, timeout_s: float) -> None:
    """Refuse an address that is not ``[tcp://]HOST:PORT``, or where nothing listens, before
    the Dask client is made (a client that fails half-made blocks 20 s on its way out)."""
    match = _ADDRESS.match(address.strip())
    if not match:
        raise InputError([Problem("--scheduler", None, address, "not a scheduler address; give "
                                  "tcp://HOST:PORT, e.g. tcp://127.0.0.1:8786")])
    host, port = match.group(1).strip("[]"), int(match.group(2))
    try:
        socket.create_connection((host, port), timeout=timeout_s).close()
    except OSError as exc:
        raise InputError([Problem("--scheduler", None, address, f"nothing answers there "
                                  f"within {timeout_s:g} s ({exc.strerror or exc})")]) from None


def _connect(scheduler: str, timeout_s: float) -> Any:
    """A Dask client of ``scheduler``, made in a helper thread that is given ``timeout_s``: a
    port that answers but is not a Dask scheduler never completes the handshake, and the
    client's own timeout does not cover that wait."""
    from distributed import Client

    made: dict[str, Any] = {}

    def connect() -> None:
        try:
            made["client"] = Client(scheduler, timeout=timeout_s, set_as_default=False)
        except Exception as exc:  # reported below, in the caller's thread
            made["error"] = exc

    thread = threading.Thread(target=connect, name="landnav-dask-connect", daemon=True)
    thread.start()
    thread.join(timeout_s)
    if "client" in made:
        return made["client"]
    reason = (f"{type(made['error']).__name__}: {made['error']}" if "error" in made
              else "it does not answer as a Dask scheduler")
    raise InputError([Problem("--scheduler", None, scheduler, f"no Dask scheduler answers "
                              f"within {timeout_s:g} s ({reason})")])


def completed(executor: cf.Executor, in_flight: int, fn: Callable[[T], Any], tasks: Iterable[T]
              ) -> Iterator[tuple[T, cf.Future]]:
    """Submit ``fn(task)`` for every task, at most ``in_flight`` at a time; yield each task
    with its finished future, in the order they finish. Closing the iterator (or an exception
    in the caller) cancels the runs under way."""
    pending = iter(tasks)
    running: dict[cf.Future, T] = {}

    def fill() -> None:
        while len(running) < in_flight:
            task = next(pending, None)
            if task is None:
                return
            running[executor.submit(fn, task)] = task

    try:
        fill()
        while running:
            done, _ = cf.wait(running, return_when=cf.FIRST_COMPLETED)
            for future in done:
                yield running.pop(future), future
            fill()
    finally:
        for future in running:
            future.cancel()
