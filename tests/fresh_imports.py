"""Each of landnav's modules imported on its own, in a process of its own, for
tests/test_architecture.py (run in a fresh interpreter: ``failures(modules)``).

The processes are forked, one per module, from a ``forkserver`` (the standard library's
``multiprocessing``) that has imported the third-party packages every module builds on
(``PRELOADED``) and none of landnav's: each import starts where an interpreter that has just
imported numpy, pandas and scipy would, so an import cycle among landnav's modules, or a module
that works only once another of landnav's has been imported, fails as in a fresh interpreter,
without paying the third-party packages' start-up once per module. A child that finds one of
landnav's modules already imported says so instead of importing."""

from __future__ import annotations

import multiprocessing
import os
import sys
import traceback
from multiprocessing.connection import Connection

# scipy's submodules that landnav's modules import (scipy.stats alone is most of an import of
# simulator.datasheet): scipy loads a submodule when first named, so preloading them hides no
# missing import
PRELOADED = ("numpy", "pandas", "numba", "yaml", "pyarrow", "matplotlib", "scipy", "scipy.stats",
             "scipy.interpolate", "scipy.spatial.transform", "scipy.special", "scipy.linalg",
             "scipy.signal", "scipy.sparse.linalg")
OURS = ("simulator", "estimators")


def import_error(module: str) -> str:
    """Import ``module``; the error's last line, or "" when it imports."""
    already = sorted(m for m in sys.modules if m.split(".")[0] in OURS)
    if already:
        return f"not a fresh process: {', '.join(already)} imported before it"
    try:
        __import__(module)
    except BaseException:  # noqa: BLE001 - any failure to import is the finding
        return traceback.format_exc().strip().splitlines()[-1]
    return ""


def _report(module: str, sender: Connection) -> None:
    sender.send(import_error(module))
    sender.close()


def failures(modules: list[str]) -> dict[str, str]:
    """module -> error of every module of ``modules`` that does not import on its own, one
    process per core at a time."""
    if "forkserver" in multiprocessing.get_all_start_methods():
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(list(PRELOADED))
    else:  # Windows: a spawned interpreter per module
        context = multiprocessing.get_context("spawn")
    pending, running, found = list(modules), [], {}
    while pending or running:
        while pending and len(running) < (os.cpu_count() or 1):
            receiver, sender = context.Pipe(duplex=False)
            process = context.Process(target=_report, args=(pending[0], sender))
            process.start()
            sender.close()
            running.append((pending.pop(0), process, receiver))
        module, process, receiver = running.pop(0)
        try:
            error = receiver.recv()
        except EOFError:  # the process died without a word
            error = "the importing process ended without a report"
        process.join()
        if error or process.exitcode:
            found[module] = error or f"exit code {process.exitcode}"
    return found
