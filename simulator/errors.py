"""User-facing errors: everything that should end in one clear message and exit code 2.

Public classes
--------------
Problem, InputError, StorageError, Terminated, refuse_undecodable, storage_error,
STORAGE_ERRNOS, not_regular, refuse_unless_regular.
"""

from __future__ import annotations

import errno
import os
import re
import stat
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
    if not isinstance(exc, OSError):
        return None
    number = exc.errno
    if number is None:  # Arrow's writers give the system's error number only in the text
        found = re.search(r"\[errno (\d+)\]", str(exc), re.IGNORECASE)
        number = int(found.group(1)) if found else None
    if number not in STORAGE_ERRNOS:
        return None
    reason = "no space left on the device" if number == errno.ENOSPC else os.strerror(number)
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


_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a named pipe"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISSOCK, "a socket"))


def not_regular(path: object, folder: bool = False) -> str | None:
    """What ``path`` is (links followed) when it is not a regular file (or, with ``folder``,
    not a folder), for a message: ``"missing"``, ``"a dangling symbolic link"``, ``"a named
    pipe"``, ``"a character device"`` (``/dev/zero``), ...; None when it is what is wanted.
    Only ``stat`` is asked: nothing is opened, so a pipe or a device is never waited on or
    read."""
    try:
        mode = os.stat(str(path)).st_mode
    except FileNotFoundError:
        return "a dangling symbolic link" if os.path.islink(str(path)) else "missing"
    except OSError as exc:
        return f"not accessible ({exc.strerror})"
    if (stat.S_ISDIR if folder else stat.S_ISREG)(mode):
        return None
    if stat.S_ISREG(mode):
        return "a file"
    return next((kind for test, kind in _KINDS if test(mode)), "not a regular file")


def refuse_unless_regular(path: object, what: str, folder: bool = False) -> None:
    """Raise InputError naming ``path`` unless it is a regular file (with ``folder``, a
    folder): ``what`` names what it should be (``"solution file"``); a device, a pipe or a
    socket is refused unread, as what it is."""
    kind = not_regular(path, folder)
    if kind == "missing":
        raise InputError([Problem(str(path), None, "", f"no such {what}")])
    if kind is not None:
        raise InputError([Problem(str(path), None, "", f"{kind}, not a {what}")])
