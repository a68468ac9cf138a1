"""A whole campaign from its validated plan: check the folder, reach the executor, run what is
not done yet (recording each run as it finishes), then merge the rows into ``runs.parquet`` and
write ``summary.json`` and ``report.md``.

Public names
------------
CampaignOptions, CampaignResult, run_campaign.
"""

from __future__ import annotations

import functools
import json
import traceback
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from simulator.campaign.execute import completed, open_executor
from simulator.campaign.plan import CampaignPlan
from simulator.campaign.report import write_campaign_report
from simulator.campaign.store import (
    PARTS,
    RUNS_FILE,
    campaign_lock,
    check_campaign_dir,
    done_parts,
    init_campaign_dir,
    merge_parts,
    write_frame,
    write_part,
)
from simulator.campaign.summary import summarise
from simulator.campaign.worker import STATUS_OK, execute_run, failed_rows
from simulator.errors import InputError, Problem, StorageError
from simulator.outputs import os_problem, refuse_inside, replace_file
from simulator.progress import progress

SUMMARY_FILE = "summary.json"
# runs one campaign plans over all sweep points (its task list, about 2 kB a task, is in memory)
MAX_TASKS = 1_000_000
DATASETS = "datasets"  # sub-folder of the kept datasets (--keep-datasets)


@dataclass(frozen=True)
class CampaignOptions:
    """How to run a campaign (none of these changes its results)."""

    runs: int
    workers: int
    scheduler: str | None = None
    scheduler_timeout_s: float = 10.0
    force: bool = False
    keep_datasets: bool = False
    retry_failed: bool = False
    show_progress: bool = True
    time_limit_s: float | None = None  # per estimator of a run


@dataclass(frozen=True)
class CampaignResult:
    """What a campaign did: the merged rows and how many runs were computed now."""

    runs: pd.DataFrame
    computed: int
    skipped: int

    @property
    def ok(self) -> int:
        return int((self.runs["status"] == STATUS_OK).sum())

    @property
    def failed(self) -> int:
        return len(self.runs) - self.ok


def run_campaign(plan: CampaignPlan, out: Path, options: CampaignOptions) -> CampaignResult:
    """Run (or resume) a campaign into ``out``.

    Raises
    ------
    InputError
        ``out`` cannot be used (another campaign without ``force``, a campaign that another
        process is running into it, or a folder holding the scenario's files), or the
        scheduler does not answer; nothing is written then.
    """
    out = Path(out)
    tasks = options.runs * len(plan.points)
    if tasks > MAX_TASKS:
        raise InputError([Problem("landnav campaign", None, "--runs",
                                  f"{options.runs:,} runs x {len(plan.points):,} sweep points is "
                                  f"{tasks:,} runs, more than one campaign plans "
                                  f"({MAX_TASKS:,}); split the sweep or the seeds into "
                                  "several campaigns")])
    refuse_inside(out, plan.base.input_files)  # --force would remove the scenario
    fingerprint, record = plan.fingerprint(), plan.record()
    check_campaign_dir(out, record, fingerprint, options.force)  # refused: nothing written
    with campaign_lock(out):
        # checked again: another campaign may have written the folder in between
        check_campaign_dir(out, record, fingerprint, options.force)
        try:
            return _run_locked(plan, out, options, fingerprint, record)
        except (StorageError, OSError) as exc:  # no space, a read-only volume: runs kept
            problem = exc if isinstance(exc, InputError) else os_problem(out, exc)
            if isinstance(problem, StorageError):
                raise _stopped(problem, out) from None
            raise problem from None


def _stopped(refused: StorageError, out: Path) -> InputError:
    """The one message of a campaign that the storage stopped: where, why, the finished runs
    kept and how to go on."""
    kept = len(done_parts(out)) if (out / PARTS).is_dir() else 0
    return InputError([Problem(refused.folder, None, "", (
        f"cannot write here: {refused.reason}; the campaign stopped, its {kept} finished "
        f"run(s) kept in {out}: free space there (or raise the limit), then run the same "
        "command again: the campaign resumes from them"))])


def _run_locked(plan: CampaignPlan, out: Path, options: CampaignOptions, fingerprint: str,
                record: dict) -> CampaignResult:
    tasks = plan.tasks(options.runs,
                       out.resolve() / DATASETS if options.keep_datasets else None)
    with open_executor(options.workers, options.scheduler, options.scheduler_timeout_s) as (
            executor, in_flight):
        init_campaign_dir(out, record, fingerprint, options.force)
        done = done_parts(out, options.retry_failed)
        todo = [t for t in tasks if t.part not in done]
        run = functools.partial(execute_run, time_limit_s=options.time_limit_s)
        finished = completed(executor, in_flight, run, todo)
        for task, future in progress(finished, "runs", options.show_progress, len(todo)):
            try:
                rows = future.result()
            except StorageError:  # the machine's problem: the campaign stops (run_campaign)
                raise
            except Exception as exc:  # the run never returned: its worker died or was lost
                rows = failed_rows(task, "".join(traceback.format_exception(exc)))
            write_part(out, task.part, rows)
    runs = merge_parts(out, [t.part for t in tasks], plan.sweep_keys)
    write_frame(runs, out / RUNS_FILE)
    header = {"scenario": plan.base.name, "runs": options.runs, "base_seed": plan.base.seed,
              "sweep": plan.sweep_values(),
              "labels": plan.labels, "fingerprint": fingerprint}
    summary = summarise(runs, plan.labels, [p.values for p in plan.points], header)
    text = json.dumps(summary, indent=2, allow_nan=False) + "\n"
    replace_file(out / SUMMARY_FILE, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    write_campaign_report(out, runs, summary)
    return CampaignResult(runs, len(todo), len(tasks) - len(todo))

