"""The campaign folder on disk, which is also the state that lets a campaign resume.

``DIR/campaign.json`` records the plan and its fingerprint; ``DIR/parts/PART.parquet`` holds
the rows of one finished run, written under a temporary name and renamed when complete, so an
interrupted campaign leaves only whole runs; ``DIR/runs.parquet`` is every requested run's rows
merged at the end (written the same way). A rerun with the same plan skips the runs whose part
exists; a different plan is refused unless ``force``, which starts over. While a campaign runs,
it holds an exclusive lock on ``.DIR.lock`` beside the folder (``campaign_lock``, removed at the
end), so that a second campaign into the same folder is refused instead of mixing its runs in.

Public names
------------
CAMPAIGN_FILE, PARTS, RUNS_FILE, campaign_lock, check_campaign_dir, init_campaign_dir,
done_parts, write_part, merge_parts, write_frame.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
from collections.abc import Iterator
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq

from simulator.campaign.plan import PLAN_FORMAT
from simulator.campaign.worker import RUN_COLUMNS, STATUS_FAILED, score_unit
from simulator.dataset.parquet import read_table, write_table
from simulator.errors import InputError, Problem
from simulator.outputs import (
    make_parent,
    open_lock_file,
    os_problem,
    real_subfolder,
    replace_file,
)

CAMPAIGN_FILE = "campaign.json"
PARTS = "parts"  # sub-folder with one Parquet file per finished run
RUNS_FILE = "runs.parquet"


def _stored(out: Path) -> dict | None:
    path = out / CAMPAIGN_FILE
    if not path.is_file():
        return None
    try:
        stored = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return stored if isinstance(stored, dict) else {}


@contextlib.contextmanager
def campaign_lock(out: Path) -> Iterator[None]:
    """Hold the campaign folder ``out`` for this process: an exclusive ``flock`` on the hidden
    file ``.NAME.lock`` beside it (holding this process id). The system releases the lock when
    the campaign ends or its process dies, so it is never stale; the file is removed while still
    held when the campaign ends, and a taker checks that the file it locked is still the one at
    that name (else it locked a removed file and tries again), so no file is left behind and the
    folder is never held twice. Without ``fcntl`` (Windows) there is no lock.

    Raises
    ------
    InputError
        Another process holds the folder.
    """
    try:
        import fcntl
    except ImportError:  # not POSIX
        yield
        return
    make_parent(out)
    path = out.parent / f".{out.name}.lock"
    while True:
        fd = open_lock_file(path)  # never through a link planted at that name
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.read(fd, 32).decode(errors="replace").strip() or "?"
            os.close(fd)
            raise InputError([Problem(str(out), None, "", f"another landnav campaign (process "
                                      f"{holder}) is writing this folder; wait for it to end "
                                      "or choose another -o DIR")]) from None
        try:
            same = os.stat(path, follow_symlinks=False).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)  # the holder removed it between our open and our lock: take the new one
    try:
        try:
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        except OSError as exc:  # a full disk: the lock's few bytes cannot be written
            raise os_problem(out, exc) from None
        yield
    finally:
        path.unlink(missing_ok=True)
        fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)


def check_campaign_dir(out: Path, record: dict, fingerprint: str, force: bool) -> None:
    """Refuse an output folder this campaign cannot use (writes nothing).

    ``out`` must be absent, empty, or a campaign folder: of the same fingerprint (then the
    campaign resumes) or, with ``force``, of any (then it starts over). A folder that is not a
    campaign is never replaced, even with ``force``.

    Raises
    ------
    InputError
        ``out`` is a file, a folder that is not a campaign, or a campaign of another plan
        without ``force`` (naming what differs).
    """
    if out.is_symlink() and not out.exists():
        raise InputError([Problem(str(out), None, "", "is a dangling symbolic link; remove it "
                                  "or choose another -o DIR")])
    if out.exists() and not out.is_dir():
        raise InputError([Problem(str(out), None, "", "exists and is not a directory")])
    if not out.exists() or not any(out.iterdir()):
        return
    stored = _stored(out)
    if stored is None or stored.get("format") != PLAN_FORMAT:
        raise InputError([Problem(str(out), None, "", "exists and is not a landnav campaign "
                                  "folder (no campaign.json); choose another -o DIR")])
    if stored.get("fingerprint") != fingerprint and not force:
        differs = [k for k in ("scenario", "base_seed", "overrides", "sweep", "labels")
                   if stored.get(k) != record.get(k)] or ["the resolved scenario content"]
        raise InputError([Problem(str(out), None, "", "holds a campaign of another scenario or"
                                  f" options (differs in: {', '.join(differs)}); rerun the same"
                                  " command to resume it, or use --force to start over")])


def init_campaign_dir(out: Path, record: dict, fingerprint: str, force: bool) -> None:
    """Create (or, with ``force``, recreate) the folder and write ``campaign.json``."""
    if force and out.exists():
        shutil.rmtree(out)
    out.mkdir(parents=True, exist_ok=True)
    real_subfolder(out / PARTS)
    if _stored(out) is None:
        text = json.dumps({"format": PLAN_FORMAT, "fingerprint": fingerprint, **record},
                          indent=2, default=str)
        replace_file(out / CAMPAIGN_FILE,
                     lambda tmp: tmp.write_text(text + "\n", encoding="utf-8"))


def _part_path(out: Path, part: str) -> Path:
    return out / PARTS / f"{part}.parquet"


def done_parts(out: Path, retry_failed: bool = False) -> set[str]:
    """The runs already finished (part names); with ``retry_failed`` a run with a failed row
    counts as not done."""
    done = set()
    for path in (out / PARTS).glob("*.parquet"):
        if path.name.startswith("."):
            continue
        if retry_failed:
            status = pq.read_table(path, columns=["status"]).column("status").to_pylist()
            if STATUS_FAILED in status:
                continue
        done.add(path.stem)
    return done


def write_frame(frame: pd.DataFrame, path: Path) -> None:
    """Write a runs table as Parquet (each score's unit in its field metadata) under a
    temporary name, then rename it into place."""
    replace_file(path, lambda tmp: write_table(frame, tmp,
                                               {c: score_unit(c) for c in frame.columns}))


def write_part(out: Path, part: str, rows: list[dict]) -> None:
    """Record one finished run's rows."""
    write_frame(pd.DataFrame(rows), _part_path(out, part))


def merge_parts(out: Path, parts: list[str], sweep_keys: list[str]) -> pd.DataFrame:
    """The rows of ``parts`` (in that order) with the columns ``run_id, seed, label, status``,
    the sweep columns, the scores and ``error``."""
    frames = [read_table(_part_path(out, p)) for p in parts]
    runs = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(
        columns=[*RUN_COLUMNS, *sweep_keys, "error"])
    lead = [*RUN_COLUMNS, *sweep_keys]
    scores = [c for c in runs.columns if c not in lead and c != "error"]
    return runs[[*lead, *scores, "error"]]
