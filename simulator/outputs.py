"""Writing what the user named, and nothing else: atomic, claimed, never overwriting unasked.

Every command that writes goes through these two context managers:

* ``atomic_output_dir(out_dir, force, inputs)`` claims ``out_dir`` by creating its temporary
  sibling ``.NAME.tmp`` (an atomic ``mkdir``: a second writer of the same folder is refused
  at once, naming the process that holds it; a temporary left by a killed process is taken
  over), yields it, and renames it into place when the block ends without error. The folder
  carries the marker ``.landnav-output``.
* ``atomic_output_file(path, force, inputs, kind)`` yields a temporary file inside a private
  folder made by ``tempfile.mkdtemp`` beside ``path`` (an unpredictable name, created
  exclusively, so a link planted beside the output cannot redirect it) and moves it into
  place at the end: with a hard link when ``force`` is not given (which fails if the name
  exists, atomically), with a rename otherwise.

Both resolve the output (symbolic links included) before anything is written and refuse it
when it lies inside one of the ``inputs`` (dataset, scenario, solution files) or contains one;
refuse an existing output without ``force``, and with ``force`` replace only what landnav
wrote (``is_own_output``: a folder with the marker or a landnav manifest, an empty folder, a
file of the writer's own ``kind``); refuse an output inside the folder of a running campaign
(its lock, ``refuse_locked``); turn a file-system error (read-only or missing parent, no
space, a file where a folder is needed, a dangling link) into one ``InputError`` naming the
path and the reason; and remove their temporaries on any error, interruption included.

Public functions
----------------
atomic_output_dir, atomic_output_file, refuse_inside, refuse_locked, resolved, is_own_output,
private_temp_dir, open_lock_file, replace_file, real_subfolder, check_output_file,
make_parent, os_problem.
"""

from __future__ import annotations

import contextlib
import dataclasses
import errno
import json
import os
import re
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

from simulator.errors import (
    InputError,
    Problem,
    StorageError,
    refuse_undecodable,
    storage_error,
)

OWNER_FILE = ".landnav-owner"  # inside a claimed temporary folder: the writer's process id
MARKER_FILE = ".landnav-output"  # inside every folder written here: what --force may replace
_SNIFF_BYTES = 65536  # how much of an existing file is read to recognise its kind
_JSON_BYTES = 16 * 1024**2  # a JSON file landnav wrote (scores, manifest) is read whole up to this
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)


def _problem(path: Path | str, message: str) -> InputError:
    return InputError([Problem(str(path), None, "", message)])


def os_problem(path: Path | str, exc: OSError) -> InputError:
    """A file-system error writing ``path`` as one message with the reason (a
    ``StorageError`` when the storage refused it: full, over a size limit, read-only)."""
    return storage_error(path, exc) or _problem(path, f"cannot write here: "
                                                      f"{exc.strerror or exc}")


def resolved(path: Path | str) -> Path:
    """``path`` absolute with every symbolic link of its existing part resolved."""
    return Path(os.path.realpath(path))


def refuse_inside(path: Path | str, inputs: Iterable[Path | str]) -> None:
    """Raise ``InputError`` if ``path``, links resolved, is one of ``inputs``, lies inside one of
    them, or contains one (which replacing it would remove)."""
    target = resolved(path)
    for item in inputs:
        base = resolved(item)
        if target == base or base in target.parents:
            raise _problem(path, f"is inside the input {base}; write the output elsewhere "
                                 "(an input is never modified)")
        if target in base.parents:
            raise _problem(path, f"contains the input {base}; write the output elsewhere "
                                 "(an input is never replaced)")


def open_lock_file(path: Path) -> int:
    """Open (or create) the lock file ``path`` for reading and writing without following a
    link; a name that is a link, not a regular file, or a hard link to another file is
    refused. Returns the descriptor."""
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | _NOFOLLOW, 0o644)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise _problem(path, "is a symbolic link; a lock file is never followed: remove "
                                 "it") from None
        raise os_problem(path, exc) from None
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode) or info.st_nlink != 1:
        os.close(fd)
        raise _problem(path, "is not a lock file landnav made (not a plain file, or linked "
                             "elsewhere); remove it")
    return fd


def refuse_locked(path: Path | str) -> None:
    """Raise ``InputError`` if ``path`` (links resolved) is, or lies inside, the folder of a
    campaign that is running: its lock ``.NAME.lock`` beside the folder is held."""
    try:
        import fcntl
    except ImportError:  # not POSIX: campaigns hold no lock
        return
    target = resolved(path)
    for folder in (target, *target.parents):
        if folder.parent == folder:
            break
        lock = folder.parent / f".{folder.name}.lock"
        try:
            fd = os.open(lock, os.O_RDONLY | _NOFOLLOW | os.O_NONBLOCK)
        except OSError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
            fcntl.flock(fd, fcntl.LOCK_UN)
        except BlockingIOError:
            holder = os.read(fd, 32).decode(errors="replace").strip() or "?"
            raise _problem(path, f"is inside the folder {folder} of a running landnav campaign "
                                 f"(process {holder}); wait for it to end or name another "
                                 "output") from None
        except OSError:
            continue
        finally:
            os.close(fd)


def _head(path: Path, size: int = _SNIFF_BYTES) -> bytes:
    """The first ``size`` bytes of ``path`` (empty when it cannot be read; never a link)."""
    try:
        fd = os.open(path, os.O_RDONLY | _NOFOLLOW)
    except OSError:
        return b""
    try:
        chunks, left = [], size
        while left > 0:
            chunk = os.read(fd, min(left, 1 << 20))
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
        return b"".join(chunks)
    finally:
        os.close(fd)


def _landnav_json(path: Path) -> bool:
    """Whether ``path`` is a plain file holding a JSON object whose ``format`` is landnav's."""
    if path.is_symlink() or not path.is_file():
        return False
    try:
        value = json.loads(_head(path, _JSON_BYTES).decode("utf-8"))
    except ValueError:
        return False
    return isinstance(value, dict) and str(value.get("format", "")).startswith("landnav-")


def _scores_json(path: Path) -> bool:
    """A JSON object of scores keyed by label (``landnav score --json``), or empty."""
    try:
        value = json.loads(_head(path, _JSON_BYTES).decode("utf-8"))
    except ValueError:
        return False
    return isinstance(value, dict) and all(isinstance(v, dict) and "horizontal" in v
                                           for v in value.values())


def _landnav_parquet(path: Path) -> bool:
    """A Parquet file whose every field carries a ``unit`` (what landnav writes)."""
    if not _head(path).startswith(b"PAR1"):
        return False
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        schema = pq.read_schema(path)
    except (pa.ArrowException, OSError):
        return False
    return all(b"unit" in (f.metadata or {}) for f in schema)


_NMEA = re.compile(rb"^\$[A-Z]{5},")


def _parquet_columns(path: Path) -> set[str]:
    """The column names of a Parquet file (empty when it is not one)."""
    if not _head(path, 4).startswith(b"PAR1"):
        return set()
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        return set(pq.read_schema(path).names)
    except (pa.ArrowException, OSError):
        return set()


def _file_kinds() -> dict:
    return {
        "parquet": _landnav_parquet,
        "json": _scores_json,
        "nmea": lambda p: bool(_NMEA.match(_head(p))),
        "rinex": lambda p: _head(p)[60:80].startswith(b"RINEX VERSION / TYPE"),
        "mcap": lambda p: _head(p, 8) == b"\x89MCAP0\r\n",
        "twin-scenario": lambda p: _head(p).startswith(b"# The twin of "),
        "twin-drive": lambda p: {"t", "lat", "lon", "alt"} <= _parquet_columns(p),
    }


def is_own_output(path: Path, kind: str | None = None) -> bool:
    """Whether ``path`` is something landnav wrote, that ``--force`` may replace: a folder that
    is empty, carries the marker, or holds a landnav manifest (a dataset, a campaign, a run's
    ``dataset/``); a file of the writer's ``kind`` (``parquet``, ``json``, ``nmea``,
    ``rinex``, ``mcap``, ``twin-scenario``, ``twin-drive``)."""
    if path.is_dir():
        try:
            if not any(path.iterdir()):
                return True
        except OSError:
            return False
        marker = path / MARKER_FILE
        if marker.is_file() and not marker.is_symlink():
            return True
        return any(_landnav_json(path / name) for name in
                   ("manifest.json", "campaign.json", "dataset/manifest.json"))
    recognise = _file_kinds().get(kind or "")
    return bool(recognise and path.is_file() and recognise(path))


def _refuse_existing(path: Path, force: bool, want_dir: bool, kind: str | None = None) -> None:
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
    if not is_own_output(path, kind):
        what = "folder" if want_dir else f"{kind or ''} file".lstrip()
        raise _problem(path, f"exists and is not a landnav {what}; --force replaces only "
                             "what landnav wrote: remove it yourself or name another output")


def make_parent(path: Path) -> list[Path]:
    """Make the folder ``path`` goes into; InputError naming what is in the way. Returns the
    folders made, outermost first (``_remove_made`` removes them when no output is written)."""
    missing = []
    for folder in path.parents:
        if os.path.lexists(folder):
            break
        missing.append(folder)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise _problem(path, f"cannot be created: {path.parent} is a file, not a folder") from None
    except OSError as exc:
        _remove_made(missing[::-1])
        raise os_problem(path.parent, exc) from None
    return missing[::-1]


def _remove_made(folders: list[Path]) -> None:
    """Remove the folders ``make_parent`` made (innermost first) that are still empty: an
    output that was not written leaves no folder of its own behind."""
    for folder in reversed(folders):
        try:
            folder.rmdir()
        except OSError:
            return


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _claim(tmp: Path, out_dir: Path, claimed: list[Path]) -> None:
    """Create ``tmp`` atomically (appended to ``claimed`` at once, so that an interruption
    anywhere after leaves nothing); take over one left by a process that no longer runs."""
    for _ in range(2):
        try:
            tmp.mkdir()
            claimed.append(tmp)
        except FileExistsError:
            try:
                owner = int(_head(tmp / OWNER_FILE)) if not tmp.is_symlink() else None
            except ValueError:
                owner = None
            if owner is not None and _pid_alive(owner):
                raise _problem(out_dir, f"another landnav (process {owner}) is writing it; "
                                        "wait for it or name another output") from None
            stale = Path(tempfile.mkdtemp(prefix=f"{tmp.name}.stale-", dir=tmp.parent))
            try:
                tmp.rename(stale / "x")  # one taker wins the rename; a link is moved, not followed
            except OSError:
                shutil.rmtree(stale, ignore_errors=True)
                raise _problem(out_dir, "another landnav is writing it; wait for it or name "
                                        "another output") from None
            shutil.rmtree(stale, ignore_errors=True)
            continue
        except OSError as exc:
            raise os_problem(out_dir, exc) from None
        _write_new(tmp / OWNER_FILE, str(os.getpid()))
        return
    raise _problem(out_dir, "another landnav is writing it; wait for it or name another output")


def _write_new(path: Path, text: str) -> None:
    """Write ``text`` into a file that must not exist yet (never through a link)."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW, 0o644)
    with os.fdopen(fd, "w", encoding="utf-8") as handle:
        handle.write(text)


@contextlib.contextmanager
def private_temp_dir(parent: Path, name: str) -> Iterator[Path]:
    """A new folder ``parent/.NAME.tmp-XXXXXX`` (``mkdtemp``: unpredictable, created
    exclusively), removed with what is left in it when the block ends."""
    try:
        folder = Path(tempfile.mkdtemp(prefix=f".{name}.tmp-", dir=parent))
    except OSError as exc:
        raise os_problem(parent / name, exc) from None
    try:
        yield folder
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def check_output_file(path: Path | str, force: bool, inputs: Iterable[Path | str] = (),
                      kind: str | None = None) -> None:
    """The checks of ``atomic_output_file`` alone, writing nothing: for a command with several
    outputs, all checked before any is begun."""
    _check_target(Path(path), force, False, list(inputs), kind, True)


def _check_target(path: Path, force: bool, want_dir: bool, inputs: Iterable[Path | str],
                  kind: str | None, honour_lock: bool) -> None:
    refuse_undecodable(path, "output's name")
    refuse_inside(path, inputs)
    if honour_lock:
        refuse_locked(path)
    _refuse_existing(path, force, want_dir, kind)


@contextlib.contextmanager
def atomic_output_dir(out_dir: Path | str, force: bool, inputs: Iterable[Path | str] = (),
                      honour_lock: bool = True) -> Iterator[Path]:
    """Yield a claimed temporary folder beside ``out_dir``; on success it becomes ``out_dir``.

    ``honour_lock=False`` only for a campaign's own runs writing into its locked folder.

    Raises
    ------
    InputError
        ``out_dir`` exists (without ``force``, or with it when landnav did not write it), is
        inside an input or contains one, is inside a running campaign's folder, is being
        written by another process, or cannot be written (with the reason).
    """
    out_dir = Path(out_dir)
    inputs = list(inputs)
    _check_target(out_dir, force, True, inputs, None, honour_lock)
    made = make_parent(out_dir)
    tmp = out_dir.parent / f".{out_dir.name}.tmp"
    claimed: list[Path] = []
    try:
        _claim(tmp, out_dir, claimed)
        yield tmp
        (tmp / OWNER_FILE).unlink()
        _write_new(tmp / MARKER_FILE, "written by landnav; `--force` may replace this folder\n")
        # checked again: created by someone else meanwhile, or a campaign started?
        _check_target(out_dir, force, True, inputs, None, honour_lock)
        with private_temp_dir(out_dir.parent, f"{out_dir.name}.old") as old:
            if out_dir.exists() or out_dir.is_symlink():
                out_dir.rename(old / out_dir.name)
            tmp.rename(out_dir)
    except BaseException as exc:
        for folder in claimed:
            shutil.rmtree(folder, ignore_errors=True)
        _remove_made(made)
        if isinstance(exc, OSError):
            raise os_problem(out_dir, exc) from None
        if isinstance(exc, InputError):  # a problem inside: named by the output, not its draft
            raise _named_by(exc, tmp, out_dir) from None
        raise


def _named_by(exc: InputError, draft: Path, out_dir: Path) -> InputError:
    """``exc`` with the files under ``draft`` named by where they were to be, in ``out_dir``
    (a ``StorageError`` stays one)."""
    def named(file: Path) -> str:
        in_draft = file == draft or draft in file.parents
        return str(out_dir / file.relative_to(draft) if in_draft else file)

    if isinstance(exc, StorageError):
        return StorageError(named(Path(exc.folder)), exc.reason)
    return InputError([dataclasses.replace(p, file=named(Path(p.file))) for p in exc.problems])


@contextlib.contextmanager
def atomic_output_file(path: Path | str, force: bool, inputs: Iterable[Path | str] = (),
                       kind: str | None = None) -> Iterator[Path]:
    """Yield a temporary file name in a private folder beside ``path``; on success the file
    becomes ``path``. ``kind`` (``parquet``, ``json``, ``nmea``, ``rinex``) is what an existing
    file must be for ``force`` to replace it.

    Raises
    ------
    InputError
        As ``atomic_output_dir``.
    """
    path = Path(path)
    inputs = list(inputs)
    _check_target(path, force, False, inputs, kind, True)
    made = make_parent(path)
    try:
        with private_temp_dir(path.parent, path.name) as folder:
            tmp = folder / path.name
            yield tmp
            _check_target(path, force, False, inputs, kind, True)
            _move_into_place(tmp, path, force)
    except OSError as exc:
        _remove_made(made)
        raise os_problem(path, exc) from None
    except BaseException:
        _remove_made(made)
        raise


def _move_into_place(tmp: Path, path: Path, force: bool) -> None:
    """``tmp`` renamed to ``path``: replacing it with ``force``, else only if the name is
    still free (a hard link, which fails atomically if it exists)."""
    if force:
        os.replace(tmp, path)
        return
    try:
        os.link(tmp, path)  # fails if the name exists: never replaces another's file
    except FileExistsError:
        raise _problem(path, "already exists (created while this ran); use --force "
                             "to overwrite it") from None
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EXDEV):
            raise
        _refuse_existing(path, force, want_dir=False)  # no hard links here
        os.replace(tmp, path)


def replace_file(path: Path, write: Callable[[Path], object]) -> None:
    """Inside a folder landnav owns (a campaign's): ``write(tmp)`` a temporary in a private
    folder beside ``path``, then rename it over ``path`` (a link at that name is replaced,
    never followed)."""
    with private_temp_dir(path.parent, path.name) as folder:
        tmp = folder / path.name
        write(tmp)
        os.replace(tmp, path)


def real_subfolder(path: Path) -> Path:
    """``path`` (inside a folder landnav owns) as a real folder: a link or a file at that name
    is removed first, so nothing is written through it."""
    if path.is_symlink() or (path.exists() and not path.is_dir()):
        path.unlink()
    path.mkdir(exist_ok=True)
    return path
