"""Progress of long work on stderr: a bar on a terminal, plain lines in a log.

On a terminal, a tqdm bar. When stderr is not a terminal (a log file, a pipe, CI), one line every
``LINE_INTERVAL_S`` seconds with what is done and what is left, e.g.
``reproduce: 12 of 45 done (27 %), 33 left; 2 min 10 s so far, about 6 min 0 s to go``, and a
closing line if any was printed. The lines come from a timer thread, so they keep coming while
one item takes long (a reproduction run of several minutes); work shorter than the interval
prints nothing.

Public names
------------
progress, LINE_INTERVAL_S.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterable, Iterator
from typing import TypeVar

T = TypeVar("T")

LINE_INTERVAL_S = 5.0  # seconds between two progress lines when stderr is not a terminal


def progress(items: Iterable[T], description: str, enabled: bool = True,
             total: int | None = None) -> Iterable[T]:
    """``items``, with their progress on stderr when ``enabled``: a tqdm bar on a terminal
    (tqdm is imported only for a bar shown: about 15 ms of a start), plain lines otherwise."""
    if not enabled:
        return items
    if total is None and hasattr(items, "__len__"):
        total = len(items)
    if not sys.stderr.isatty():
        return _with_lines(items, description, total)
    from tqdm import tqdm

    return tqdm(items, desc=description, total=total, leave=False, file=sys.stderr)


def _duration(seconds: float) -> str:
    minutes, s = divmod(int(round(seconds)), 60)
    return f"{minutes} min {s} s" if minutes else f"{s} s"


class _Lines:
    """The timer thread that prints the state of one loop every ``LINE_INTERVAL_S``."""

    def __init__(self, description: str, total: int | None) -> None:
        self.description, self.total = description, total
        self.done = 0
        self.printed = False
        self.start = time.monotonic()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True,
                                        name=f"progress {description}")
        self._thread.start()

    def line(self) -> str:
        elapsed = time.monotonic() - self.start
        done, total = self.done, self.total
        if total is None:
            return f"{self.description}: {done} done; {_duration(elapsed)} so far"
        left = max(total - done, 0)
        text = (f"{self.description}: {done} of {total} done ({100 * done / max(total, 1):.0f} %)"
                f", {left} left; {_duration(elapsed)} so far")
        if 0 < done < total:
            text += f", about {_duration(elapsed / done * left)} to go"
        return text

    def _run(self) -> None:
        while not self._stop.wait(LINE_INTERVAL_S):
            print(self.line(), file=sys.stderr, flush=True)
            self.printed = True

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        if self.printed:
            elapsed = _duration(time.monotonic() - self.start)
            print(f"{self.description}: {self.done} done in {elapsed}", file=sys.stderr,
                  flush=True)


def _with_lines(items: Iterable[T], description: str, total: int | None) -> Iterator[T]:
    lines = _Lines(description, total)
    try:
        for item in items:
            yield item
            lines.done += 1
    finally:
        lines.close()
