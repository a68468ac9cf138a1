"""The registered papers: an explicit table of paper key -> ``module:NAME`` of its ``Paper``
(``simulator.reproduce.paper``), imported only when asked for, so that listing the keys (the
command's --help) imports no paper module.

Public names
------------
PAPERS, load_paper, paper_keys.
"""

from __future__ import annotations

import importlib
import importlib.util
from typing import TYPE_CHECKING

from simulator.errors import InputError, Problem

if TYPE_CHECKING:
    from simulator.reproduce.paper import Paper

__all__ = ["PAPERS", "load_paper", "paper_keys"]

PAPERS: dict[str, str] = {
    "cho2006": "simulator.reproduce.cho2006:PAPER",
    "tan2008": "simulator.reproduce.tan2008:PAPER",
    "park2019": "simulator.reproduce.park2019:PAPER",
    "chan": "simulator.reproduce.chan:PAPER",
    "karamat2015": "simulator.reproduce.karamat2015:PAPER",
}


def paper_keys() -> list[str]:
    """The keys of the papers whose module is present (a paper being written may be missing)."""
    return [key for key, path in PAPERS.items()
            if importlib.util.find_spec(path.split(":")[0]) is not None]


def load_paper(key: str) -> Paper:
    """The ``Paper`` registered under ``key``.

    Raises
    ------
    InputError
        When no paper has that key (naming the known ones).
    """
    if key not in paper_keys():
        raise InputError([Problem("PAPER", None, key, "no such paper; known: "
                                  + ", ".join(paper_keys()))])
    module, name = PAPERS[key].split(":")
    return getattr(importlib.import_module(module), name)
