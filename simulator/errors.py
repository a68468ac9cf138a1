"""User-facing errors: everything that should end in one clear message and exit code 2.

Public classes
--------------
Problem, InputError, StorageError, Terminated, refuse_undecodable, storage_error,
STORAGE_ERRNOS.
"""

from __future__ import annotations

import errno
import os
from dataclasses import dataclass

# a write refused by the machine's storage, whatever is written: no space left, a file larger
# than the volume (or the process's limit) allows, a disk quota, a read-only volume
STORAGE_ERRNOS = frozenset(getattr(errno, name) for name in ("ENOSPC", "EFBIG", "EDQUOT", "EROFS")
                           if hasattr(errno, name))


@dataclass(frozen=True)
class Problem:
    """One problem in an input file, printed as ``file:line: key.path: message``."""

    file: str
    line: int | str | None
    key_path: str
    message: str

    def __str__(self) -> str:
        where = self.file if self.line is None else f"{self.file}:{self.line}"
        return f"{where}: {self.key_path}: {self.message}" if self.key_path else (
            f"{where}: {self.message}"
        )


class InputError(Exception):
    """Bad user input: a malformed or invalid file, a missing file, a corrupt dataset.

    The command line prints the problems (all of them, one per line) and exits with code 2.
    """

    def __init__(self, problems: list[Problem] | str):
        if isinstance(problems, str):
            problems = [Problem("landnav", None, "", problems)]
        self.problems = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))


class StorageError(InputError):
    """A write into ``folder`` refused by the storage (``STORAGE_ERRNOS``): the machine's
    problem, not the input's. A command stops at it with one message; a campaign stops rather
    than record its runs as failed. Pickled whole (a campaign's worker process raises it)."""

    def __init__(self, folder: str, reason: str):
        self.folder, self.reason = str(folder), reason
        super().__init__([Problem(self.folder, None, "", f"cannot write here: {reason}")])

    def __reduce__(self) -> tuple:
        return type(self), (self.folder, self.reason)


def storage_error(path: object, exc: BaseException) -> StorageError | None:
    """``exc`` as a ``StorageError`` naming ``path`` when it is an ``OSError`` the storage
    raised (``STORAGE_ERRNOS``), else None."""
    if not isinstance(exc, OSError) or exc.errno not in STORAGE_ERRNOS:
        return None
    reason = ("no space left on the device" if exc.errno == errno.ENOSPC
              else os.strerror(exc.errno))
    return StorageError(str(path), reason)


class Terminated(BaseException):
    """The process was asked to stop (SIGTERM). Raised in the main thread by the command line's
    handler so that, as with Ctrl-C, every ``with`` block unwinds and removes its temporaries;
    the command line then exits with 143 (128 + SIGTERM)."""


def refuse_undecodable(path: object, what: str = "name") -> None:
    """Raise InputError for a path whose name is not valid text (bytes that are not UTF-8 come
    in as lone surrogates): the file formats, the manifest and the messages need text names."""
    text = str(path)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        shown = text.encode("utf-8", "backslashreplace").decode("ascii", "backslashreplace")
        raise InputError([Problem(shown, None, "", f"the {what} is not valid UTF-8 text; "
                                  "rename it")]) from None
