"""RTKLIB's ``rnx2rtkp`` (the Debian ``rtklib`` package) as the independent engine of the
carrier-phase tests: kinematic relative positioning of a rover against a base with the options
of the refdata README's figures (L1+L2, elevation mask 15 deg, fix-and-hold, ratio 3, the base
at a given position), its solutions and the double-difference residuals it writes with
``-y 2`` (the ``$SAT`` lines)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

ELEVATION_BANDS_DEG = ((15.0, 30.0), (30.0, 45.0), (45.0, 90.0))


def need_rnx2rtkp() -> str:
    """The path of rnx2rtkp, or skip the test (the Debian package ``rtklib`` provides it)."""
    path = shutil.which("rnx2rtkp")
    if path is None:
        pytest.skip("rnx2rtkp not found: install the Debian package rtklib "
                    "(apt-get install rtklib) to run the RTKLIB comparisons")
    return path


def kinematic(rover: Path, base: Path, nav: Path, base_xyz: np.ndarray, out: Path
              ) -> dict[str, np.ndarray]:
    """Run rnx2rtkp kinematic (``-p 2 -f 2 -m 15 -h -v 3 -e -y 2 -r X Y Z``) and read the
    solution: ``tow`` (s), ``xyz`` (n, 3, m), ``q`` (1 fixed, 2 float), and the residual lines
    ``sat`` as a dict of arrays (tow, frequency 1/2, elevation deg, code and carrier residual m,
    valid) restricted to the fixed epochs."""
    exe = need_rnx2rtkp()
    cmd = [exe, "-p", "2", "-f", "2", "-m", "15", "-h", "-v", "3", "-e", "-y", "2", "-r",
           *(f"{v:.4f}" for v in base_xyz), "-o", str(out), str(rover), str(base), str(nav)]
    subprocess.run(cmd, check=True, capture_output=True, timeout=600)
    rows = [line.split() for line in out.read_text().splitlines()
            if line and not line.startswith("%")]
    sol = np.array([[float(r[1]), float(r[2]), float(r[3]), float(r[4]), float(r[5])]
                    for r in rows])
    stat = Path(str(out) + ".stat").read_text().splitlines()
    sat = np.array([[float(f[2]), float(f[4]), float(f[6]), float(f[7]), float(f[8]),
                     float(f[9])] for f in (line.split(",") for line in stat)
                    if f[0] == "$SAT"]).reshape(-1, 6)
    fixed_tow = sol[sol[:, 4] == 1, 0]
    keep = np.isin(np.round(sat[:, 0], 3), np.round(fixed_tow, 3)) & (sat[:, 5] == 1)
    sat = sat[keep]
    return {"tow": sol[:, 0], "xyz": sol[:, 1:4], "q": sol[:, 4].astype(int),
            "sat": {"tow": sat[:, 0], "frequency": sat[:, 1].astype(int),
                    "elevation": sat[:, 2], "code": sat[:, 3], "carrier": sat[:, 4]}}


def residual_std_by_band(sat: dict[str, np.ndarray], frequency: int, kind: str) -> np.ndarray:
    """Standard deviation of the ``kind`` ('code' or 'carrier') residuals of ``frequency`` in
    each of ``ELEVATION_BANDS_DEG``, m."""
    out = []
    for lo, hi in ELEVATION_BANDS_DEG:
        sel = (sat["frequency"] == frequency) & (sat["elevation"] >= lo) & (sat["elevation"] < hi)
        out.append(np.std(sat[kind][sel]) if sel.sum() > 2 else np.nan)
    return np.array(out)


def kinematic_solution(rover: Path, base: Path, nav: Path, base_xyz: np.ndarray, out: Path
                       ) -> float:
    """Run rnx2rtkp kinematic with the options of ``kinematic`` (``-p 2 -f 2 -m 15 -h``,
    the base at ``base_xyz``), writing its latitude-longitude-height solution to ``out`` (a
    ``.pos`` file ``landnav score`` reads); returns the CPU seconds rnx2rtkp took."""
    import resource

    exe = need_rnx2rtkp()
    cmd = [exe, "-p", "2", "-f", "2", "-m", "15", "-h", "-r",
           *(f"{v:.4f}" for v in base_xyz), "-o", str(out), str(rover), str(base), str(nav)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, capture_output=True, timeout=1800)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
