"""GNSS system names and time systems: how each system's time relates to GPS time (GPST).

Every satellite computation in ``simulator.gnss`` runs on one axis, GPS time in seconds since the
start of a reference GPS week; each system's broadcast times are moved onto it here.

- GPS and QZSS: GPST (QZSST is steered to GPST; IS-QZSS-PNT-005 3.1.3).
- Galileo: GST starts at GPST (it has no offset by whole seconds); RINEX 3 writes the Galileo
  week continuous with the GPS week (RINEX 3.04 Table A8), so week and seconds of week read as
  GPS ones. GST - GPST = the GGTO, a few ns (Galileo OS SIS ICD 5.1.8), broadcast as ``GAGP``.
- BeiDou: BDT started at 2006-01-01 00:00:00 UTC, when GPST - UTC was 14 s: BDT = GPST - 14 s,
  and BDT week 0 is GPS week 1356 (BDS SIS ICD B1I 3.0, 4.2).
- GLONASS: GLONASST = UTC(SU) + 3 h, with the UTC leap seconds (GLONASS ICD 2008, 3.3.3); RINEX
  writes GLONASS epochs in UTC, so GPST = UTC + (GPS - UTC leap seconds). GLONASST - GPST,
  beyond the whole seconds, is -tau_GPS (ICD 2008 4.5: tau_GPS = T_GPS - T_GL, fractional part).

The fractional offsets (ns to tens of ns) are what a receiver's inter-system clock bias absorbs;
``offset_polynomials`` gives them from a navigation file's ``TIME SYSTEM CORR`` lines (RINEX 3.04
Table A5; the signs are in ``HEADER_OFFSET_SIGN``) or zero.

Public names
------------
SYSTEMS, SYSTEM_LETTERS, BDT_MINUS_GPST_S, BDS_WEEK_OFFSET, GLONASST_MINUS_UTC_S,
HEADER_OFFSET_SIGN, system_letter, offset_polynomials.
"""

from __future__ import annotations

import numpy as np

from simulator.timebase import SECONDS_PER_WEEK

# scenario name -> RINEX 3 system letter
SYSTEMS: dict[str, str] = {"gps": "G", "galileo": "E", "beidou": "C", "glonass": "R", "qzss": "J"}
SYSTEM_LETTERS: dict[str, str] = {v: k for k, v in SYSTEMS.items()}
BDT_MINUS_GPST_S = -14.0  # BDT = GPST - 14 s (BDS SIS ICD 4.2)
BDS_WEEK_OFFSET = 1356  # GPS week of BDT week 0 (2006-01-01)
GLONASST_MINUS_UTC_S = 3 * 3600.0  # GLONASST = UTC(SU) + 3 h
# TIME SYSTEM CORR label of each system's offset to GPST and the sign that turns its a0 + a1 dt
# into (system time - GPST): GAGP (GPGA in RINEX 3.00-3.02) holds A0G, A1G of the GGTO, GST -
# GPST (Galileo OS SIS ICD 5.1.8; refdata 1e confirms the sign: the Galileo clocks then agree
# with CODE's within 0.8 m, 4.5 m with the other sign); GLGP is
# tau_GPS = GPST - GLONASST (ICD 2008 4.5; GNSSTk's TimeSystemCorrection, an independent
# reading, also adds it going from GLONASS to GPS time; refdata 1e cannot tell, its precise
# GLONASS clocks carry the analysis' own system bias); BDGP and QZGP are system time - GPST
# (BDS SIS ICD 5.2.4.19: t_GPS = t_BDT - (A0GPS + A1GPS t); RINEX 3.04
# Table A5: "correction to transform the system time to GPS time").
HEADER_OFFSET_SIGN: dict[str, tuple[tuple[str, ...], float]] = {
    "E": (("GAGP", "GPGA"), 1.0), "R": (("GLGP",), -1.0), "C": (("BDGP",), 1.0),
    "J": (("QZGP",), 1.0),
}


def system_letter(name: str) -> str:
    """RINEX letter of a system named as the scenario names it (``gps``, ``galileo``, ...)."""
    return SYSTEMS[name]


def offset_polynomials(system: np.ndarray, corrections: dict, week0: int
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per satellite record, the polynomial of its system's time minus GPS time (beyond whole
    seconds): offset(t) = a0 + a1 (t - t_ref), t and t_ref GPS seconds since the start of GPS
    week ``week0``.

    Parameters
    ----------
    system : array of str, RINEX letters of the records
    corrections : dict
        The navigation table's ``attrs["time_corrections"]``: label -> (a0 s, a1 s/s, reference
        seconds of week, reference week), as read from ``TIME SYSTEM CORR``. A system without
        its label has offset 0 (GPS always).
    week0 : int

    Returns
    -------
    a0 (s), a1 (s/s), t_ref (s): arrays of the shape of ``system``, signed by
    ``HEADER_OFFSET_SIGN`` so that they give system time - GPST.
    """
    system = np.asarray(system)
    a0, a1, t_ref = np.zeros(system.shape), np.zeros(system.shape), np.zeros(system.shape)
    for letter, (labels, sign) in HEADER_OFFSET_SIGN.items():
        for label in labels:
            if label not in corrections:
                continue
            c0, c1, tow_ref, week_ref = corrections[label]
            here = system == letter
            a0[here], a1[here] = sign * c0, sign * c1
            t_ref[here] = tow_ref + (week_ref - week0) * SECONDS_PER_WEEK
            break
    return a0, a1, t_ref


__all__ = ["SYSTEMS", "SYSTEM_LETTERS", "BDT_MINUS_GPST_S", "BDS_WEEK_OFFSET",
           "GLONASST_MINUS_UTC_S", "HEADER_OFFSET_SIGN", "system_letter", "offset_polynomials"]
