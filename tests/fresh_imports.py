"""Each of landnav's modules imported on its own, in a process of its own, for
tests/test_architecture.py (run in a fresh interpreter: ``failures(modules)``).

The processes are forked, one per module, from a ``forkserver`` (the standard library's
``multiprocessing``) that has imported the third-party packages every module builds on
(``PRELOADED``, top-level packages only) and none of landnav's: each import starts where an
interpreter that has just imported numpy and pandas would, so an import cycle among landnav's
modules, or a module that works only once another of landnav's has been imported, fails as in a
fresh interpreter, without paying numpy's, pandas' and numba's start-up once per module. A child
that finds one of landnav's modules already imported says so instead of importing."""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
import os
import sys
import traceback

PRELOADED = ("numpy", "pandas", "scipy", "numba", "yaml", "pyarrow", "matplotlib")
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


def failures(modules: list[str]) -> dict[str, str]:
    """module -> error of every module of ``modules`` that does not import on its own."""
    if "forkserver" in multiprocessing.get_all_start_methods():
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(list(PRELOADED))
    else:  # Windows: a spawned interpreter per module
        context = multiprocessing.get_context("spawn")
    with cf.ProcessPoolExecutor(os.cpu_count() or 1, mp_context=context,
                                max_tasks_per_child=1) as pool:
        errors = pool.map(import_error, modules)
        return {module: error for module, error in zip(modules, errors, strict=True) if error}
