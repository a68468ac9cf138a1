"""The timing the benchmarks share: process CPU time (``time.process_time``, steadier than wall
time on a shared machine) and wall time of a call over several runs, the best reported."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TypeVar

import numpy as np

T = TypeVar("T")


def timed_runs(call: Callable[[int], T], repeat: int) -> tuple[list[float], list[float], T]:
    """``call(k)`` for k = 0 .. ``repeat`` - 1: the CPU seconds and the wall seconds of each
    run, and the last run's result."""
    cpu, wall, result = [], [], None
    for k in range(repeat):
        start_cpu, start_wall = time.process_time(), time.perf_counter()
        result = call(k)
        cpu.append(time.process_time() - start_cpu)
        wall.append(time.perf_counter() - start_wall)
    return cpu, wall, result


def best_replay(dataset, entry, repeat: int) -> tuple[float, float, object]:
    """An estimator replayed ``repeat`` times (``simulator.replay.run_estimator``): the best
    wall time of its message loop, the best CPU time of the whole call, the last solution."""
    from simulator.replay import run_estimator

    loop_s = np.inf

    def replay(_: int):
        nonlocal loop_s
        solution, info = run_estimator(dataset, entry, show_progress=False)
        loop_s = min(loop_s, info["runtime_s"])
        return solution

    cpu, _, solution = timed_runs(replay, repeat)
    return loop_s, min(cpu), solution
