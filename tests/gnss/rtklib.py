"""RTKLIB's ``rnx2rtkp`` (the Debian ``rtklib`` package) as the independent engine of the
carrier-phase tests: kinematic relative positioning of a rover against a base with the options
of the refdata README's figures (L1+L2, elevation mask 15 deg, fix-and-hold, ratio 3, the base
at a given position), its solutions and the double-difference residuals it writes with
``-y 2`` (the ``$SAT`` lines)."""

from __future__ import annotations

import datetime as dt
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


def code_observations(path: Path, rx_xyz_m: np.ndarray, start_gpst: dt.datetime,
                      seconds: np.ndarray, sats: list[tuple[str, int]],
                      pseudorange_m: np.ndarray, glonass_channels: dict[int, int]) -> None:
    """A minimal RINEX 3.04 observation file for single-point tests: one code observable per
    system (C1C, BeiDou C2I), epochs ``start_gpst`` + ``seconds``, row i of ``pseudorange_m``
    for satellite ``sats[i]``, the GLONASS slots' channels in GLONASS SLOT / FRQ #."""
    def label(text: str, name: str) -> str:
        return f"{text:<60}{name}"

    lines = [label("     3.04           OBSERVATION DATA    M", "RINEX VERSION / TYPE"),
             label("landnav", "PGM / RUN BY / DATE"), label("TEST", "MARKER NAME"),
             label("".join(f"{x:14.4f}" for x in rx_xyz_m), "APPROX POSITION XYZ")]
    lines += [label(f"{s}    1 {'C2I' if s == 'C' else 'C1C'}", "SYS / # / OBS TYPES")
              for s in "GERJC"]
    slots = [(n, glonass_channels[n]) for s, n in sats if s == "R"]
    lines += [label(f"{len(slots):3d} " + "".join(f"R{n:02d} {k:2d} " for n, k in slots),
                    "GLONASS SLOT / FRQ #"), label("", "END OF HEADER")]
    for k, sec in enumerate(seconds):
        at = start_gpst + dt.timedelta(seconds=float(sec))
        lines.append(f"> {at.year:4d} {at.month:02d} {at.day:02d} {at.hour:02d} "
                     f"{at.minute:02d}{at.second + at.microsecond / 1e6:11.7f}  0{len(sats):3d}")
        lines += [f"{s}{n:02d}{pseudorange_m[i, k]:14.3f}  " for i, (s, n) in enumerate(sats)]
    path.write_text("\n".join(lines) + "\n")


def single_point(obs: Path, nav: Path, systems_mask: int = 61) -> dict[str, np.ndarray]:
    """Run rnx2rtkp single-point on L1 without atmosphere (``pos1-navsys`` = ``systems_mask``,
    61: GPS, Galileo, QZSS, BeiDou, GLONASS) and read its status file: ``pos`` (epochs solved,
    ECEF m), ``clock`` ($CLK: receiver clock and inter-system biases, ns) and ``sat`` ($SAT
    rows as text fields: tow, sat, az, el, code residual, ...)."""
    exe = need_rnx2rtkp()
    conf = obs.with_suffix(".conf")
    conf.write_text("pos1-posmode=single\npos1-frequency=l1\npos1-elmask=5\npos1-ionoopt=off\n"
                    f"pos1-tropopt=off\npos1-navsys={systems_mask}\nout-solformat=xyz\n")
    out = obs.with_suffix(".pos")
    subprocess.run([exe, "-k", str(conf), "-y", "2", "-o", str(out), str(obs), str(nav)],
                   check=True, capture_output=True, timeout=600)
    status = Path(str(out) + ".stat").read_text().splitlines()
    pos = np.array([[float(x) for x in line.split(",")[4:7]] for line in status
                    if line.startswith("$POS") and line.split(",")[3] != "0"]).reshape(-1, 3)
    clock = np.array([[float(x) for x in line.split(",")[5:9]] for line in status
                      if line.startswith("$CLK")]).reshape(-1, 4)
    sat = [line.split(",") for line in status if line.startswith("$SAT")]
    return {"pos": pos, "clock": clock, "sat": sat}


SYSTEM_MASKS = {"G": 1, "R": 4, "E": 8, "J": 16, "C": 32}  # RTKLIB's pos1-navsys bits


def _systems_options(out: Path, systems: str | None, more: str = "") -> list[str]:
    """rnx2rtkp's ``-k`` options file beside ``out`` that sets ``pos1-navsys`` to ``systems``
    (RINEX letters; rnx2rtkp 2.4.3's ``-sys`` falls through its switch and enables every
    later system) and the ``more`` lines; none without ``systems``."""
    if systems is None:
        return []
    conf = Path(str(out) + ".conf")
    conf.write_text(f"pos1-navsys={sum(SYSTEM_MASKS[s] for s in systems)}\n{more}")
    return ["-k", str(conf)]


def kinematic(rover: Path, base: Path, nav: Path, base_xyz: np.ndarray, out: Path,
              systems: str | None = None) -> dict[str, np.ndarray]:
    """Run rnx2rtkp kinematic (``-p 2 -f 2 -m 15 -h -v 3 -e -y 2 -r X Y Z``) and read the
    solution: ``tow`` (s), ``xyz`` (n, 3, m), ``q`` (1 fixed, 2 float), and the residual lines
    ``sat`` as a dict of arrays (tow, frequency 1/2, elevation deg, code and carrier residual m,
    valid) restricted to the fixed epochs. ``systems`` (RINEX letters, e.g. ``"GEC"``) goes
    to ``pos1-navsys`` in an options file (rnx2rtkp 2.4.3's ``-sys`` falls through its switch
    and enables every later system); without it, rnx2rtkp's default GPS + GLONASS. The other
    options are RTKLIB's defaults: frequency index 2 is GPS L2, Galileo E5b, BeiDou B2I."""
    exe = need_rnx2rtkp()
    # an options file resets rnx2rtkp's own time format
    cmd = [exe, *_systems_options(out, systems, "out-timeform=tow\n"), "-p", "2", "-f", "2",
           "-m", "15", "-h", "-v", "3", "-e", "-y", "2",
           "-r", *(f"{v:.4f}" for v in base_xyz), "-o", str(out), str(rover), str(base),
           str(nav)]
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


def kinematic_solution(rover: Path, base: Path, nav: Path, base_xyz: np.ndarray, out: Path,
                       systems: str | None = None) -> float:
    """Run rnx2rtkp kinematic with the options of ``kinematic`` (``-p 2 -f 2 -m 15 -h``,
    the base at ``base_xyz``, ``systems`` as there), writing its latitude-longitude-height
    solution to ``out`` (a ``.pos`` file ``landnav score`` reads); returns the CPU seconds
    rnx2rtkp took."""
    import resource

    exe = need_rnx2rtkp()
    cmd = [exe, *_systems_options(out, systems), "-p", "2", "-f", "2", "-m", "15", "-h", "-r",
           *(f"{v:.4f}" for v in base_xyz), "-o", str(out), str(rover), str(base), str(nav)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, capture_output=True, timeout=1800)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
