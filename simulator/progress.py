"""Progress bars for long work: shown on a terminal, silent when output is not a terminal.

Public functions
----------------
progress.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable
from typing import TypeVar

from tqdm import tqdm

T = TypeVar("T")


def progress(items: Iterable[T], description: str, enabled: bool = True,
             total: int | None = None) -> Iterable[T]:
    """Wrap ``items`` in a tqdm bar on stderr when it is a terminal and ``enabled``."""
    show = enabled and sys.stderr.isatty()
    return tqdm(items, desc=description, total=total, disable=not show, leave=False,
                file=sys.stderr)
