"""What every hostile case asserts: exit 2, one message with the words expected, no traceback,
and the watched folders unchanged (every path with its size and modification time); the one
message of a command run in a process of its own (``one_message``); and whether a process is
still alive (``alive``)."""

from __future__ import annotations

import re
from pathlib import Path

from simulator.cli import main


def tree(root: Path) -> dict[str, tuple[int, int]]:
    """Every path under ``root`` (links not followed) with its size and modification time."""
    out = {}
    for path in sorted(root.rglob("*")):
        stat = path.lstat()
        out[str(path.relative_to(root))] = (stat.st_size, stat.st_mtime_ns)
    return out


def refused(args: list[str], capsys, watch: list[Path], words: str,
            prefix: str = "error:") -> str:
    """Run ``landnav ARGS``; assert it is refused as above (one line starting with ``prefix``:
    ``validate`` prints its problems as ``file:line: ...``); the printed text."""
    before = {str(w): tree(w) for w in watch}
    code = main(args)
    out = capsys.readouterr()
    text = out.err + out.out
    assert code == 2, text
    assert "Traceback" not in text
    assert words in text, text
    errors = [line for line in text.splitlines() if line.startswith(prefix)]
    assert len(errors) == 1, text
    assert {str(w): tree(w) for w in watch} == before
    return text


PROGRESS_LINE = re.compile(r"^[\w -]+: \d+ (of \d+ done|done in |done; )")  # simulator.progress


def one_message(stderr: str) -> str:
    """The one line a stopped command printed (its progress lines apart), asserted to be an
    error and no traceback."""
    lines = [line for line in stderr.splitlines()
             if line.strip() and not PROGRESS_LINE.match(line)]
    assert len(lines) == 1, stderr
    assert lines[0].startswith("error: ") and "Traceback" not in stderr
    return lines[0]


def alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie, ended and waiting to be reaped, does not)."""
    try:
        state = (Path("/proc") / str(pid) / "stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"
