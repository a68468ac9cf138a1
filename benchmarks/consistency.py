"""Consistency of the built-in filters over drives and seeds: the table of docs/scores.md,
"Consistency of the built-in filters".

Run:  python benchmarks/consistency.py --seeds 10 -o OUT [--drives unseen,quickstart]
      [--filters gnss_wls,ins_odo_ekf] [--workers K | --scheduler tcp://HOST:PORT]
      [--set KEY.PATH=VALUE ...]

Each drive is one landnav campaign (``simulator.campaign``: seeds 1..N, every filter of the
list whose streams the drive has, each run's dataset generated once and shared by the filters,
scored with the code of ``landnav score``) into ``OUT/DRIVE/``, on local processes or a Dask
cluster; rerunning the same command resumes, a larger ``--seeds`` adds seeds. A drive is a
name of ``benchmarks/consistency/`` (the drives the filters were not tuned on: ``open_road``,
``outages``, ``canyon``, ``garage``, ``sumo_city``), a name of ``scenarios/``, or a YAML path;
``unseen`` and ``shipped`` name the groups. A drive with a GNSS receiver writes both its fixes
and its raw measurements (``sensors.gnss.outputs=[fix,raw]``), so that every filter can run.

The figure per filter, drive and axis (n, e, d, vn, ve, vd, roll r, pitch p, yaw y) is each
seed's mean of (error / sigma)^2 after the solution's first 60 s (``consistency`` of
docs/scores.md), then the mean over the seeds with the largest seed in brackets. The goal: a
mean between 0.3 and 3 and no seed above 10; the last column names the axes outside it (and
the failed runs). ``OUT/consistency.md`` holds the Markdown sections, one per filter, rows
sorted by drive.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
from pathlib import Path

import numpy as np
import pandas as pd

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from estimators.registry import get_estimator  # noqa: E402
from simulator.campaign.campaign import CampaignOptions, run_campaign  # noqa: E402
from simulator.campaign.plan import plan_campaign  # noqa: E402
from simulator.campaign.worker import STATUS_OK  # noqa: E402
from simulator.errors import InputError  # noqa: E402
from simulator.pipeline import load_scenario  # noqa: E402
from simulator.scoring.consistency import AXES  # noqa: E402

DRIVES_DIR = REPO / "benchmarks" / "consistency"
UNSEEN = ("open_road", "outages", "canyon", "garage", "sumo_city")
# the built-in filters that write std columns, in the order of docs/scores.md (the GTSAM
# smoothers, an extra, and rtk_ins_ekf, which needs a base station, are named on request)
FILTERS = ("gnss_wls", "ins_odo_ekf", "dr3d_ekf", "dr2d_odo_ekf", "tc_ekf", "tc_ukf",
           "riss3d_tc_ekf", "dr2d_drm2_ekf", "dr2d_drm2_spkf", "dr2d_drm1_ekf", "ins_lkf")
COLUMNS = {"n": "n", "e": "e", "d": "d", "vn": "vn", "ve": "ve", "vd": "vd", "roll": "r",
           "pitch": "p", "yaw": "y"}
GOAL = (0.3, 3.0)  # the mean over seeds of each axis's mean (error / sigma)^2
SEED_CEILING = 10.0  # no seed above it
OUTPUT = "consistency.md"


def shipped_drives() -> list[str]:
    """Every shipped scenario's name (``scenarios/*.yaml``)."""
    return sorted(p.stem for p in (REPO / "scenarios").glob("*.yaml"))


def drive_path(drive: str) -> Path:
    """The scenario file of a drive name (``benchmarks/consistency/``, then ``scenarios/``) or
    path."""
    for candidate in (DRIVES_DIR / f"{drive}.yaml", REPO / "scenarios" / f"{drive}.yaml"):
        if candidate.is_file():
            return candidate
    path = Path(drive)
    if path.is_file():
        return path
    raise InputError(f"--drives: {drive!r} is neither a drive of {DRIVES_DIR}, a scenario of "
                     f"{REPO / 'scenarios'} nor a file")


def scenario_streams(sensors: dict) -> set[str]:
    """The streams a scenario's ``sensors`` block produces."""
    streams = {name for name in ("imu", "odometer", "baro", "mag") if sensors.get(name)}
    gnss = sensors.get("gnss") or {}
    streams |= {f"gnss_{kind}" for kind in gnss.get("outputs", ())}
    if sensors.get("gnss_base"):
        streams.add("gnss_base_raw")
    return streams


def drive_overrides(path: Path, sets: list[str], filters: list[str]) -> tuple[list[str], list[str]]:
    """The ``--set`` overrides of a drive's campaign and the filters it runs: every one of
    ``filters`` whose streams the drive (with ``sets`` and GNSS fixes and raw measurements)
    has."""
    base = load_scenario(path, [*sets, "estimators=[gnss_only]"])
    if base.data["sensors"].get("gnss"):
        sets = [*sets, "sensors.gnss.outputs=[fix,raw]"]
        base = load_scenario(path, [*sets, "estimators=[gnss_only]"])
    streams = scenario_streams(base.data["sensors"])
    runnable = [f for f in filters if set(get_estimator(f).needs) <= streams]
    return [*sets, f"estimators=[{','.join(runnable)}]"], runnable


def run_drive(drive: str, filters: list[str], seeds: int, sets: list[str], out: Path,
              options: dict) -> pd.DataFrame | None:
    """One drive's campaign over seeds 1..``seeds`` into ``out``; its rows (None when no filter
    can run on it)."""
    path = drive_path(drive)
    overrides, runnable = drive_overrides(path, sets, filters)
    if not runnable:
        print(f"{drive}: none of the filters has the streams it needs; skipped", flush=True)
        return None
    print(f"{drive}: {seeds} seed(s) x {len(runnable)} filter(s) -> {out}", flush=True)
    plan = plan_campaign(path, overrides, 1, [])
    result = run_campaign(plan, out, CampaignOptions(runs=seeds, **options))
    return result.runs


def axis_values(runs: pd.DataFrame, label: str) -> tuple[dict[str, pd.Series], int]:
    """Per axis, each successful seed's mean (error / sigma)^2 of the filter ``label``
    (whichever consistency block holds the axis), and the number of its failed runs."""
    rows = runs[runs["label"] == label]
    ok = rows[rows["status"] == STATUS_OK].set_index("seed")
    out = {}
    for axis in AXES:
        found = [c for c in ok.columns
                 if c.startswith("consistency.") and c.endswith(f".nse.{axis}")]
        if found:
            values = ok[found].bfill(axis=1).iloc[:, 0].dropna()
            if len(values):
                out[axis] = values
    return out, int(len(rows) - len(ok))


def _number(x: float) -> str:
    return f"{x:.2g}" if x < 100 else f"{x:.0f}"


def table_row(drive: str, values: dict[str, pd.Series], failed: int) -> str:
    """A Markdown row: the drive with its seed count, per axis the mean over the seeds (the
    largest seed in brackets), the axes outside the goal (and the failed runs)."""
    seeds = sorted({s for v in values.values() for s in v.index})
    cells, outside = [], []
    for axis in AXES:
        if axis not in values:
            cells.append("")
            continue
        v = values[axis].to_numpy(float)
        mean, worst = float(np.mean(v)), float(np.max(v))
        cells.append(_number(mean) if len(v) == 1 else f"{_number(mean)} ({_number(worst)})")
        if not GOAL[0] <= mean <= GOAL[1] or worst > SEED_CEILING:
            outside.append(COLUMNS[axis])
    verdict = ", ".join(outside) or "none"
    if failed:
        verdict += f"; {failed} run(s) failed"
    return f"| {drive} ({len(seeds)}) | " + " | ".join(cells) + f" | {verdict} |"


def markdown(results: dict[str, pd.DataFrame], filters: list[str]) -> str:
    """The sections of docs/scores.md: per filter, one row per drive it ran on."""
    header = ("| drive (seeds) | " + " | ".join(COLUMNS.values()) + " | outside the goal |\n"
              + "|---|" + "---|" * (len(COLUMNS) + 1))
    parts = []
    for label in filters:
        rows = []
        for drive in sorted(results):
            runs = results[drive]
            if label in set(runs["label"]):
                values, failed = axis_values(runs, label)
                if values or failed:
                    rows.append(table_row(drive, values, failed))
        if rows:
            parts.append(f"### `{label}`\n\n{header}\n" + "\n".join(rows) + "\n")
    return "\n".join(parts)


def _names(text: str, groups: dict[str, list[str]]) -> list[str]:
    out: list[str] = []
    for name in text.split(","):
        name = name.strip()
        out += groups.get(name, [name] if name else [])
    return list(dict.fromkeys(out))


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=10, help="seeds 1..N per drive")
    parser.add_argument("--drives", default="unseen",
                        help="comma-separated drive names or paths; 'unseen' (the five drives of "
                             "benchmarks/consistency/), 'shipped' (scenarios/*.yaml)")
    parser.add_argument("--filters", default=",".join(FILTERS),
                        help="comma-separated estimator names (default: every built-in with "
                             "std columns but the smoothers and rtk_ins_ekf)")
    parser.add_argument("--workers", type=int, default=None,
                        help="local worker processes (default: the CPU count)")
    parser.add_argument("--scheduler", default=None, help="a Dask scheduler's address instead")
    parser.add_argument("--set", dest="sets", action="append", default=[],
                        metavar="KEY.PATH=VALUE", help="override every drive's scenario")
    parser.add_argument("-o", "--output", required=True, type=Path, help="output folder")
    args = parser.parse_args(argv)
    if args.seeds < 1 or (args.workers is not None and args.workers < 1):
        parser.error("--seeds and --workers must be at least 1")
    if args.workers is not None and args.scheduler:
        parser.error("give --workers or --scheduler, not both")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    # SIGTERM as Ctrl-C: the campaign stops its workers and keeps the finished runs
    previous = signal.signal(signal.SIGTERM, signal.default_int_handler)
    try:
        return _measure(args)
    finally:
        signal.signal(signal.SIGTERM, previous)


def _measure(args: argparse.Namespace) -> int:
    drives = _names(args.drives, {"unseen": list(UNSEEN), "shipped": shipped_drives()})
    filters = _names(args.filters, {})
    options = {"workers": args.workers or os.cpu_count() or 1, "scheduler": args.scheduler}
    results = {}
    try:
        for i, drive in enumerate(drives, 1):
            print(f"drive {i} of {len(drives)}: ", end="", flush=True)
            runs = run_drive(drive, filters, args.seeds, args.sets,
                             args.output / Path(drive).stem, options)
            if runs is not None:
                results[Path(drive).stem] = runs
    except InputError as exc:
        print(exc, file=sys.stderr)
        return 2
    text = markdown(results, filters)
    args.output.mkdir(parents=True, exist_ok=True)
    tmp = args.output / f".{OUTPUT}.tmp"
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(args.output / OUTPUT)
    print(text)
    print(f"wrote {args.output / OUTPUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
