"""Progress bars for long work: shown on a terminal, silent when output is not a terminal.

Public functions
----------------
progress.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable
from typing import TypeVar

T = TypeVar("T")


def progress(items: Iterable[T], description: str, enabled: bool = True,
             total: int | None = None) -> Iterable[T]:
    """Wrap ``items`` in a tqdm bar on stderr when it is a terminal and ``enabled``; otherwise
    return them as they are (tqdm is imported only for a bar shown: about 15 ms of a start)."""
    if not (enabled and sys.stderr.isatty()):
        return items
    from tqdm import tqdm

    return tqdm(items, desc=description, total=total, leave=False, file=sys.stderr)
