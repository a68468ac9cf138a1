"""The first row of a CSV file with fewer fields than its header names, found without parsing
the file: pandas fills the missing fields of such a row with NaN, which would make a solution
row without a position or a velocity out of a truncated or hand-edited line.

The file is scanned in blocks of ``SCAN_BYTES`` (bounded memory whatever its size): the
separators of each line are counted with numpy, and only the lines that look short or hold a
quote character (a quoted field may hold separators) are split by Python's ``csv`` module.
Blank lines are skipped, as pandas skips them. A line longer than a block (no solution row is)
is passed over, not held.

Public names
------------
ShortRow, first_short_row, SCAN_BYTES.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

SCAN_BYTES = 2 * 2**20  # bytes read at a time
_NEWLINE, _QUOTE = ord("\n"), ord('"')
_SPACE = ord(" ")  # a line of bytes up to this one (spaces, tabs, CR) is blank


@dataclass(frozen=True)
class ShortRow:
    """A row of fewer fields than the header: its line (1-based), its fields and the header's
    names."""

    line: int
    fields: int
    header: tuple[str, ...]

    def missing(self) -> tuple[str, ...]:
        """The header's names that the row has no field for."""
        return self.header[self.fields:]


def _fields(line: bytes, sep: str) -> list[str]:
    text = line.decode("utf-8", "replace").rstrip("\r")
    return next(csv.reader([text], delimiter=sep, skipinitialspace=True), [])


def _per_line(mask: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """How many of each line's bytes ``mask`` marks (lines start at ``starts`` and run, their
    newline included, to the next one's start)."""
    return np.add.reduceat(mask.view(np.uint8), starts, dtype=np.int64)


def first_short_row(path: Path, sep: str = ",") -> ShortRow | None:
    """The first line after the header (the first line that is not blank) with fewer fields
    than the header, or None."""
    header: tuple[str, ...] | None = None
    line_no = 0  # lines before the current block's first
    carry = b""
    with path.open("rb") as stream:
        while True:
            block = stream.read(SCAN_BYTES)
            if not block and not carry:
                return None
            data = carry + block if block else carry + b"\n"
            codes = np.frombuffer(data, dtype=np.uint8)
            ends = np.flatnonzero(codes == _NEWLINE)
            if not ends.size:  # a line longer than a block: passed over to its end
                while block and _NEWLINE not in block:
                    block = stream.read(SCAN_BYTES)
                line_no += 1
                carry = block[block.find(b"\n") + 1:] if block else b""
                continue
            starts = np.concatenate(([0], ends[:-1] + 1))
            lines = codes[:ends[-1] + 1]
            fields = _per_line(lines == ord(sep), starts) + 1
            first = 0
            if header is None:
                found = np.flatnonzero(_per_line(lines > _SPACE, starts))
                if found.size:
                    first = int(found[0]) + 1
                    header = tuple(name.strip() for name in _fields(
                        data[starts[first - 1]:ends[first - 1]], sep))
            if header is not None:
                look = fields < len(header)
                if _QUOTE in data:
                    look |= _per_line(lines == _QUOTE, starts) > 0
                look[:first] = False
                if look.any():
                    look &= _per_line(lines > _SPACE, starts) > 0  # blank lines are skipped
                for i in np.flatnonzero(look):
                    count = len(_fields(data[starts[i]:ends[i]], sep))
                    if count < len(header):
                        return ShortRow(line_no + int(i) + 1, count, header)
            line_no += int(ends.size)
            carry = data[ends[-1] + 1:]
            if not block:
                return None
