"""Results that do not depend on the user's thread settings.

OpenBLAS splits a large matrix product among its threads, and the rows at a split are summed
by another kernel path, in another order: with ``OPENBLAS_NUM_THREADS=2`` a few truth rows
differed in the last bit (3e-17) from one thread's. The computations of landnav (the drive,
the streams, the replay) therefore run with one BLAS thread, whatever the environment says
(``threadpoolctl``; landnav's products are of 3 x 3 to 20 x 20 matrices on long arrays, where
more threads only add wake-ups).

Public functions
----------------
one_blas_thread.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any, TypeVar

from threadpoolctl import threadpool_limits

F = TypeVar("F", bound=Callable)


def one_blas_thread(function: F) -> F:
    """Decorate ``function`` to run with the BLAS libraries limited to one thread (the
    previous limits restored after)."""
    @functools.wraps(function)
    def limited(*args: Any, **kwargs: Any) -> Any:
        with threadpool_limits(limits=1, user_api="blas"):
            return function(*args, **kwargs)
    return limited  # type: ignore[return-value]
