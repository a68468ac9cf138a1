"""Writing what the user named, and nothing else: atomic, claimed, never overwriting unasked.

Every command that writes goes through these two context managers:

* ``atomic_output_dir(out_dir, force, inputs)`` claims ``out_dir`` by creating its temporary
  sibling ``.NAME.tmp`` (an atomic ``mkdir``: a second writer of the same folder is refused
  at once, naming the process that holds it; a temporary left by a killed process is taken
  over), yields it, and renames it into place when the block ends without error. An
  existing ``out_dir`` is refused unless ``force``, both before the work and again at the
  rename, so a folder someone else created meanwhile is never replaced.
* ``atomic_output_file(path, force, inputs)`` yields a temporary sibling file and moves it
  into place at the end: with a hard link when ``force`` is not given (which fails if the
  name exists, atomically), with a rename otherwise.

Both refuse an output inside one of the ``inputs`` folders (a dataset being read is never
written into), turn a file-system error (read-only or missing parent, no space, a file where a
folder is needed, a dangling link) into one ``InputError`` naming the path and the reason, and
remove their temporaries on any error, interruption included.

Public functions
----------------
atomic_output_dir, atomic_output_file, refuse_inside.
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
from collections.abc import Iterable, Iterator
from pathlib import Path

from simulator.errors import InputError, Problem

OWNER_FILE = ".landnav-owner"  # inside a claimed temporary folder: the writer's process id


def _problem(path: Path | str, message: str) -> InputError:
    return InputError([Problem(str(path), None, "", message)])


def _os_problem(path: Path | str, exc: OSError) -> InputError:
    reason = exc.strerror or str(exc)
    if exc.errno == errno.ENOSPC:
        reason = "no space left on the device"
    return _problem(path, f"cannot write here: {reason}")


def refuse_inside(path: Path, inputs: Iterable[Path | str]) -> None:
    """Raise ``InputError`` if ``path`` is one of ``inputs`` or lies inside one of them."""
    target = Path(os.path.abspath(path))
    for folder in inputs:
        base = Path(os.path.abspath(folder))
        if target == base or base in target.parents:
            raise _problem(path, f"is inside the input {base}; write the output elsewhere "
                                 "(an input is never modified)")


def _refuse_existing(path: Path, force: bool, want_dir: bool) -> None:
    if os.path.islink(path) and not path.exists():
        raise _problem(path, "is a dangling symbolic link; remove it or name another output")
    if not path.exists():
        return
    if want_dir and not path.is_dir():
        raise _problem(path, "exists and is not a folder")
    if not want_dir and path.is_dir():
        raise _problem(path, "is a folder; name a file")
    if not force:
        raise _problem(path, "already exists; use --force to overwrite it")


def _make_parent(path: Path) -> None:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise _problem(path, f"cannot be created: {path.parent} is a file, not a folder") from None
    except OSError as exc:
        raise _os_problem(path.parent, exc) from None


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _claim(tmp: Path, out_dir: Path) -> None:
    """Create ``tmp`` atomically; take over one left by a process that no longer runs."""
    for _ in range(2):
        try:
            tmp.mkdir()
        except FileExistsError:
            try:
                owner = int((tmp / OWNER_FILE).read_text())
            except (OSError, ValueError):
                owner = None
            if owner is not None and _pid_alive(owner):
                raise _problem(out_dir, f"another landnav (process {owner}) is writing it; "
                                        "wait for it or name another output") from None
            stale = tmp.with_name(f"{tmp.name}.stale-{os.getpid()}")
            try:
                tmp.rename(stale)  # one taker wins the rename
            except OSError:
                raise _problem(out_dir, "another landnav is writing it; wait for it or name "
                                        "another output") from None
            shutil.rmtree(stale, ignore_errors=True)
            continue
        except OSError as exc:
            raise _os_problem(out_dir, exc) from None
        (tmp / OWNER_FILE).write_text(str(os.getpid()))
        return
    raise _problem(out_dir, "another landnav is writing it; wait for it or name another output")


@contextlib.contextmanager
def atomic_output_dir(out_dir: Path | str, force: bool,
                      inputs: Iterable[Path | str] = ()) -> Iterator[Path]:
    """Yield a claimed temporary folder beside ``out_dir``; on success it becomes ``out_dir``.

    Raises
    ------
    InputError
        ``out_dir`` exists (without ``force``), is inside an input, is being written by another
        process, or cannot be written (with the reason).
    """
    out_dir = Path(out_dir)
    refuse_inside(out_dir, inputs)
    _refuse_existing(out_dir, force, want_dir=True)
    _make_parent(out_dir)
    tmp = out_dir.parent / f".{out_dir.name}.tmp"
    _claim(tmp, out_dir)
    try:
        yield tmp
        (tmp / OWNER_FILE).unlink()
        _refuse_existing(out_dir, force, want_dir=True)  # created by someone else meanwhile?
        old = out_dir.parent / f".{out_dir.name}.old-{os.getpid()}"
        if out_dir.exists():
            out_dir.rename(old)
        tmp.rename(out_dir)
        shutil.rmtree(old, ignore_errors=True)
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        raise _os_problem(out_dir, exc) from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


@contextlib.contextmanager
def atomic_output_file(path: Path | str, force: bool,
                       inputs: Iterable[Path | str] = ()) -> Iterator[Path]:
    """Yield a temporary file name beside ``path``; on success the file becomes ``path``.

    Raises
    ------
    InputError
        As ``atomic_output_dir``.
    """
    path = Path(path)
    refuse_inside(path, inputs)
    _refuse_existing(path, force, want_dir=False)
    _make_parent(path)
    tmp = path.parent / f".{path.name}.tmp-{os.getpid()}"
    try:
        yield tmp
        if force:
            os.replace(tmp, path)
        else:
            try:
                os.link(tmp, path)  # fails if the name exists: never replaces another's file
            except FileExistsError:
                raise _problem(path, "already exists (created while this ran); use --force "
                                     "to overwrite it") from None
            except OSError as exc:
                if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EXDEV):
                    raise
                _refuse_existing(path, force, want_dir=False)  # no hard links on this volume
                os.replace(tmp, path)
    except OSError as exc:
        raise _os_problem(path, exc) from None
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink()
