"""One campaign run, as a worker process executes it: generate the dataset, run every estimator
of the scenario, score each solution (SPEC section 8) and return one flat row per estimator.

Any exception inside the run is caught and recorded: a failed dataset fails every estimator's
row, a failed estimator (or its scoring) fails its own row; the row's ``error`` holds the
traceback. The scores are flattened into ``group.key`` columns; ``outages`` becomes the mean of
each per-outage score over the run's outages (NaN when one outage lacks it), ``outages.count``
and ``outages.missing``.

Public names
------------
STATUS_OK, STATUS_FAILED, RUN_COLUMNS, flatten_scores, score_unit, execute_run, failed_rows,
time_limit, TimeLimitExceeded.
"""

from __future__ import annotations

import contextlib
import signal
import socket
import tempfile
import threading
import traceback
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from simulator import pipeline
from simulator.campaign.plan import RunTask, entry_labels
from simulator.errors import StorageError, storage_error

STATUS_OK = "ok"
STATUS_FAILED = "failed"
RUN_COLUMNS = ("run_id", "seed", "label", "status")  # the leading columns of runs.parquet
# bookkeeping, not performance
_SKIPPED = {"rows", "nees.expected", "outages.start", "degraded.start", "degraded.kind"}
_SKIPPED_KEYS = {"nees_expected", "epochs", "updates"}  # at any depth (``consistency``, ``nis``)
_BLOCK_GROUPS = {"consistency"}  # groups of sub-groups: a sub-group that is None has no columns
# unit of a flattened score column, by column or else by group (SPEC section 8)
_UNITS = {"horizontal": "m", "vertical": "m", "velocity": "m/s", "attitude": "deg",
          "runtime.seconds": "s", "coverage.longest_gap": "s",
          **{f"{group}.{key}": unit for group in ("outages", "degraded")
             for key, unit in (("duration", "s"), ("distance", "m"), ("max_horizontal", "m"),
                               ("end_horizontal", "m"), ("end_percent", "%"),
                               ("coverage.longest_gap", "s"))}}


def _number(x: Any) -> float:
    return float("nan") if x is None else float(x)


def _window_mean(entries: list[dict], key: str) -> float:
    """The mean of a per-window score over a run's windows, NaN when any window lacks it (a
    window where the solution was silent is never averaged away); ``end_percent`` is taken
    over the windows with a distance (it is undefined for a stationary one)."""
    if key == "end_percent":
        entries = [e for e in entries if (e.get("distance") or 0.0) > 0.0]
    values = np.array([_number(e.get(key)) for e in entries])
    return float(values.mean()) if values.size else float("nan")


def _flatten_windows(group: str, entries: list[dict]) -> dict[str, float]:
    """A window list as ``group.count``, ``group.missing`` (windows without an end error) and
    the mean of each per-window score, nested ones (``coverage``) as ``group.coverage.fraction``.
    """
    out = {f"{group}.count": float(len(entries)),
           f"{group}.missing": float(sum(e.get("end_horizontal") is None for e in entries))}
    keys = dict.fromkeys(k for entry in entries for k in entry)
    for key in keys:
        if f"{group}.{key}" in _SKIPPED:
            continue
        nested = [e.get(key) for e in entries if isinstance(e.get(key), dict)]
        if nested:
            for sub in dict.fromkeys(k for n in nested for k in n):
                out[f"{group}.{key}.{sub}"] = _window_mean(
                    [{sub: (e.get(key) or {}).get(sub)} for e in entries], sub)
        else:
            out[f"{group}.{key}"] = _window_mean(entries, key)
    return out


def flatten_scores(scores: dict) -> dict[str, float]:
    """Scores of one solution (SPEC section 8) as ``{"horizontal.rms": value, ...}``.

    Missing values are NaN. The ``outages`` and ``degraded`` lists become ``outages.count``,
    ``outages.missing`` (the windows without an end error) and, for each per-window score, its
    mean over the windows, NaN when any window lacks it; a solution without GNSS has no outage
    columns. Nested groups flatten to ``sensor_errors.gyro_bias_z.rms``,
    ``consistency.position.nse.n``; a list of numbers (``rtk.refix_times``) to its mean (NaN
    when one is missing), ``.count`` and ``.missing``; bookkeeping (``rows``, expected values,
    epoch counts) is left out.
    """
    out: dict[str, float] = {}
    for group, value in scores.items():
        if group in _SKIPPED:
            continue
        if isinstance(value, dict):
            for k, v in value.items():
                if (k in _SKIPPED_KEYS or f"{group}.{k}" in _SKIPPED
                        or (v is None and group in _BLOCK_GROUPS)):
                    continue
                if isinstance(v, dict | list):
                    out.update(flatten_scores({f"{group}.{k}": v}))
                else:
                    out[f"{group}.{k}"] = _number(v)
        elif isinstance(value, list) and all(isinstance(e, dict) for e in value):
            out.update(_flatten_windows(group, value))
        elif isinstance(value, list):  # numbers, None where missing (``rtk.refix_times``)
            numbers = [{"value": v} for v in value]
            out.update({f"{group}.count": float(len(value)),
                        f"{group}.missing": float(sum(v is None for v in value)),
                        group: _window_mean(numbers, "value")})
    return out


def score_unit(column: str) -> str:
    """The unit of a flattened score column (``""`` for counts, ratios and other columns)."""
    return _UNITS.get(column, _UNITS.get(column.partition(".")[0], ""))


def _row(task: RunTask, label: str, status: str, scores: dict[str, float] | None = None,
         error: str = "") -> dict[str, Any]:
    return {"run_id": task.run_id, "seed": task.seed, "label": label, "status": status,
            **task.point.values, **(scores or {}), "error": error}


def failed_rows(task: RunTask, error: str) -> list[dict[str, Any]]:
    """The rows of a run that failed as a whole (every label failed with ``error``)."""
    return [_row(task, label, STATUS_FAILED, error=error)
            for label in entry_labels(task.scenario.data["estimators"])]


def _raise_storage(exc: Exception, folder: Path) -> None:
    """Raise ``exc`` again when the storage refused a write (``StorageError``, or the
    ``OSError`` of a full disk written into ``folder``): the machine's problem, which stops the
    campaign, not the run's failure."""
    if isinstance(exc, StorageError):
        raise exc
    refused = storage_error(folder, exc)
    if refused is not None:
        raise refused from None


def _score_all(task: RunTask, dataset_dir: Path, time_limit_s: float | None
               ) -> list[dict[str, Any]]:
    labels = entry_labels(task.scenario.data["estimators"])
    try:
        dataset = pipeline.generate(task.scenario, dataset_dir, force=True, honour_lock=False)
    except Exception as exc:
        _raise_storage(exc, dataset_dir.parent)
        return failed_rows(task, traceback.format_exc())
    rows = []
    for label, entry in zip(labels, task.scenario.data["estimators"], strict=True):
        try:
            frame, info = _estimate(dataset, entry, label, time_limit_s)
            scores = pipeline.score(dataset, {label: (frame, info)}).scores()[label]
            rows.append(_row(task, label, STATUS_OK, flatten_scores(scores)))
        except Exception as exc:
            _raise_storage(exc, dataset_dir.parent)
            rows.append(_row(task, label, STATUS_FAILED, error=traceback.format_exc()))
    return rows


class TimeLimitExceeded(Exception):
    """An estimator ran past the campaign's ``--time-limit``."""


@contextlib.contextmanager
def time_limit(seconds: float | None, label: str) -> Iterator[None]:
    """Raise ``TimeLimitExceeded`` in the block after ``seconds`` (a SIGALRM timer: call it
    in the main thread only). Whatever the block raises once the timer has fired is reported
    as the time limit: the timer's exception can surface as another (an extension module
    interrupted while it initialises raises ImportError)."""
    if seconds is None:
        yield
        return
    message = f"estimator {label!r} did not finish within the time limit of {seconds:g} s"
    fired = False

    def expire(signum: int, frame: object) -> None:
        nonlocal fired
        fired = True
        raise TimeLimitExceeded(message)

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    except TimeLimitExceeded:
        raise
    except Exception as exc:
        if fired:
            raise TimeLimitExceeded(message) from exc
        raise
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _in_main_thread() -> bool:
    """Whether this runs in a local worker process's main thread (not a Dask worker's)."""
    return threading.current_thread() is threading.main_thread()


def _estimate(dataset: Any, entry: Any, label: str, time_limit_s: float | None
              ) -> tuple[Any, dict]:
    """One estimator of a run within ``time_limit_s``: here under a timer in a local worker
    (its main thread runs the tasks); in a child process that is killed at the limit in a
    thread of a Dask worker, where no timer signal can reach the estimator."""
    if time_limit_s is not None and not _in_main_thread():
        return pipeline.estimate(dataset, entry, time_limit_s=time_limit_s)
    with time_limit(time_limit_s, label):
        return pipeline.estimate(dataset, entry, isolate=False)


def execute_run(task: RunTask, time_limit_s: float | None = None) -> list[dict[str, Any]]:
    """Run one campaign run; never raises for a failure inside the run, only when the storage
    refuses its writes (``StorageError``: no space, a file size limit, a read-only volume),
    which is the machine's problem (the campaign stops; the run's temporaries are removed).

    Parameters
    ----------
    task : the run (its scenario already carries the run's seed and sweep values).
    time_limit_s : how long each estimator may run, s (None: no limit).

    Returns
    -------
    One row per label: ``run_id, seed, label, status``, the sweep columns, the flattened scores
    (none when failed) and ``error`` (the traceback, or "").
    """
    if task.keep is not None:
        return _score_all(task, Path(task.keep), time_limit_s)
    try:
        with tempfile.TemporaryDirectory(prefix="landnav-run-") as tmp:
            return _score_all(task, Path(tmp) / "dataset", time_limit_s)
    except (StorageError, OSError) as exc:  # named by the temporary folder, not the run's own
        refused = exc if isinstance(exc, StorageError) else storage_error("", exc)
        if refused is None:
            raise
        on = "" if _in_main_thread() else f" on the Dask worker's host {socket.gethostname()}"
        raise StorageError(tempfile.gettempdir(), f"{refused.reason} (the temporary folder of "
                           f"the campaign's runs{on}; TMPDIR chooses it)") from None
