"""User-facing errors: everything that should end in one clear message and exit code 2.

Public classes
--------------
Problem, InputError, Terminated, refuse_undecodable.
"""

from __future__ import annotations

from dataclasses import dataclass


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
