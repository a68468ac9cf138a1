"""Real recordings as landnav datasets (SPEC section 9): each reader maps a recording's streams
to landnav's files and columns (units and frames converted and stated, timing kept) and puts its
reference trajectory in place of the truth; ``common.write_recording`` writes the dataset.

Modules
-------
common      the reference as truth, the datasheet of the recording's sensors, writing
comma2k19   comma2k19 segments (phone IMU, CAN speed, u-blox raw GNSS, comma's pose)
gsdc        Google Smartphone Decimeter Challenge traces (device_gnss.csv, ground_truth.csv)
smartloc    TU Chemnitz smartLoc traces (u-blox raw measurements, reference, NLOS labels)
rinex       a receiver's RINEX observation and navigation files with a reference position
twin        a dataset's twin scenario

Public names
------------
KINDS, import_recording.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from simulator.errors import not_regular, refuse_unless_regular

if TYPE_CHECKING:  # imported where a recording is read: `landnav import --help` lists KINDS
    from simulator.recordings.common import Recording


def _comma2k19(sources: list[str]) -> Recording:
    from simulator.recordings.comma2k19 import read_comma2k19

    return read_comma2k19(sources)


def _smartloc(sources: list[str]) -> Recording:
    from simulator.recordings.smartloc import read_smartloc

    return read_smartloc(sources)


def _rinex(sources: list[str], reference: str | None = None) -> Recording:
    from simulator.recordings.rinex import read_rinex_recording

    return read_rinex_recording(sources, reference)


def _gsdc(sources: list[str]) -> Recording:
    from simulator.recordings.gsdc import read_gsdc

    return read_gsdc(sources)


KINDS: dict[str, tuple[Callable[[list[str]], Recording], str]] = {
    "comma2k19": (_comma2k19, "a comma2k19 segment folder (processed_log/, global_pose/)"),
    "gsdc": (_gsdc, "a Google Smartphone Decimeter Challenge trace: device_gnss.csv and "
                    "ground_truth.csv (or the folder holding them)"),
    "smartloc": (_smartloc, "a TU Chemnitz smartLoc CSV (u-blox raw, reference, NLOS labels)"),
    "rinex": (_rinex, "a RINEX observation file and a navigation file (2 or 3); the reference "
                      "from --reference"),
}


def import_recording(kind: str, sources: list[str], out_dir: str | Path,
                     force: bool = False, reference: str | None = None) -> Path:
    """Read a recording of ``kind`` from ``sources`` and write it as a dataset at ``out_dir``;
    ``reference`` (the ``rinex`` kind only) is a position or a trajectory file."""
    from simulator.recordings.common import write_recording

    reader, _ = KINDS[kind]
    for source in sources:  # a device or a pipe is refused unread (a reader would wait on it)
        if not_regular(source, folder=True) not in (None, "missing"):
            refuse_unless_regular(source, "recording file")
    if reference is not None and os.path.lexists(reference):  # a file, not LAT,LON,HEIGHT
        refuse_unless_regular(reference, "reference file")
    if kind == "rinex":
        recording = _rinex([str(s) for s in sources], reference)
    else:
        recording = reader([str(s) for s in sources])
    return write_recording(recording, out_dir, force, sources)
