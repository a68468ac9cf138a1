"""Numba compilation during a piece of work: announced once on stderr and timed, so that an
estimator's runtime can leave it out.

numba compiles a kernel on its first call in a process unless its on-disk cache (``cache=True``,
in ``__pycache__`` beside the module) holds it; the ``numba:compile`` event of numba's event API
(``numba.core.event``) fires only for a real compilation, not for a load from the cache. Only
the outermost compilation is timed (compiling a kernel compiles the kernels it calls inside it),
and only on the thread that entered the watch. Loading kernels from the cache is not
compilation: it stays in the time of the work (tens of milliseconds).

Public names
------------
CompileWatch.
"""

from __future__ import annotations

import sys
import threading
import time
from types import TracebackType


class CompileWatch:
    """``with CompileWatch("dr3d_ekf") as watch: ...``: prints ``compiling numba kernels for
    dr3d_ekf (first run only)`` on stderr at the first compilation inside the block, and sums
    the wall time of the compilations in ``watch.seconds``. Does nothing (and imports nothing)
    when numba has not been imported."""

    def __init__(self, what: str) -> None:
        self.what = what
        self.seconds = 0.0
        self._depth = 0
        self._started = 0.0
        self._announced = False
        self._thread = threading.get_ident()
        self._installed = None

    def __enter__(self) -> CompileWatch:
        if "numba" in sys.modules:
            from numba.core import event

            watch = self

            class Listener(event.Listener):
                def on_start(self, ev: event.Event) -> None:
                    watch._start()

                def on_end(self, ev: event.Event) -> None:
                    watch._end()

            self._installed = event.install_listener("numba:compile", Listener())
            self._installed.__enter__()
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 trace: TracebackType | None) -> None:
        if self._installed is not None:
            self._installed.__exit__(kind, exc, trace)
            self._installed = None

    def _start(self) -> None:
        if threading.get_ident() != self._thread:
            return
        if self._depth == 0:
            if not self._announced:
                print(f"compiling numba kernels for {self.what} (first run only)",
                      file=sys.stderr, flush=True)
                self._announced = True
            self._started = time.perf_counter()
        self._depth += 1

    def _end(self) -> None:
        if threading.get_ident() != self._thread or self._depth == 0:
            return
        self._depth -= 1
        if self._depth == 0:
            self.seconds += time.perf_counter() - self._started

