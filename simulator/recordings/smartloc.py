"""TU Chemnitz smartLoc traces (Reisdorf et al., "The Problem of Comparable GNSS Results: An
Approach for a Uniform Dataset with Low-Cost and Reference Data", 2016): a car's u-blox raw
measurements (UBX-RXM-RAWX fields) with a reference trajectory and an NLOS label per signal,
in one semicolon-separated CSV with one row per measurement.

Columns are found by the names in brackets that the header gives them (``(prMes)``,
``(GT Lat)``, ...), so the order and the unit suffixes may change.

* ``gnss_raw``: one row per measurement with a valid pseudorange (``trkStat`` bit 0), stamped
  with its epoch's GPS time (``rcvTow``, ``week``): ``prMes`` (m), ``doMes`` (Hz, positive
  when the satellite approaches, as SPEC section 5), the pseudorange rate ``-doMes c / f``,
  ``cpMes`` (cycles) where ``trkStat`` bit 1 says valid, ``cno``, ``prStdev`` and the rate's
  std from ``doStdev``, ``locktime`` (ms to s), ``lli`` 2 (half-cycle ambiguity) where
  ``trkStat`` bit 2 is not set; GLONASS FDMA frequencies from ``freqId`` (k = freqId - 7);
  the NLOS label in the extra column ``nlos`` (1 NLOS, 0 LOS, NaN unknown). SBAS rows are
  left out. No ephemeris comes with the trace: satellite states and model delays are NaN
  (``lacks``).
* ``truth``: the ``GT`` columns, one row per epoch: latitude, longitude, ellipsoidal height,
  heading (0 = east, counter-clockwise: yaw = pi/2 - heading), speed along that heading;
  roll, pitch and the down velocity are not given (NaN; vd 0 would be a made-up value).

Public names
------------
read_smartloc.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from simulator.earth import geodetic_to_ecef, ned_to_ecef_matrix
from simulator.errors import InputError, Problem
from simulator.recordings.comma2k19 import (
    C_M_S,
    GLONASS_G1_HZ,
    GLONASS_G1_STEP_HZ,
    GPS_L1_HZ,
    NOT_ON_RECORD,
)
from simulator.recordings.common import Recording, reference_truth

SYSTEMS = {"GPS": "G", "GLONASS": "R", "GALILEO": "E", "BEIDOU": "C", "QZSS": "J"}
FREQUENCY_HZ = {"G": GPS_L1_HZ, "E": GPS_L1_HZ, "J": GPS_L1_HZ, "C": 1561.098e6}
FIELDS = {"week": "GPS week number (week)", "tow": "(rcvTow)", "pr": "(prMes)",
          "cp": "(cpMes)", "doppler": "(doMes)", "system": "(gnssId)", "sv": "(svId)",
          "slot": "(freqId)", "lock": "(locktime)", "cn0": "(cno)", "pr_std": "(prStdev)",
          "do_std": "(doStdev)", "trk": "(trkStat)", "lat": "(GT Lat)", "lon": "(GT Lon)",
          "height": "(GT Height)", "heading": "(GT Heading)", "speed": "(GT Velocity)"}
OPTIONAL = ("cp", "slot", "lock", "pr_std", "do_std", "trk", "heading", "speed")


def _column(header: list[str], key: str) -> str | None:
    tag = FIELDS[key]
    found = [h for h in header if tag in h and "Cov" not in h]
    return found[0] if found else None


def read_smartloc(sources: list[str]) -> Recording:
    """Read one smartLoc CSV (see the module docstring)."""
    if len(sources) != 1 or not Path(sources[0]).is_file():
        raise InputError([Problem(" ".join(sources), None, "SOURCE",
                                  "give one smartLoc CSV file (semicolon-separated)")])
    path = Path(sources[0])
    try:
        frame = pd.read_csv(path, sep=";", low_memory=False)
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise InputError([Problem(str(path), None, "", f"not a readable CSV: {exc}")]) from None
    header = list(frame.columns)
    names = {k: _column(header, k) for k in FIELDS}
    missing = [FIELDS[k] for k, v in names.items() if v is None and k not in OPTIONAL]
    if missing:
        raise InputError([Problem(str(path), None, ", ".join(missing), "missing column(s)")])

    def num(key: str, default: float = np.nan) -> np.ndarray:
        name = names[key]
        if name is None:
            return np.full(len(frame), default)
        return pd.to_numeric(frame[name], errors="coerce").to_numpy(dtype=float)

    system = frame[names["system"]].astype(str).str.upper().map(SYSTEMS)
    trk = num("trk", 1.0).astype(int)
    keep = system.notna().to_numpy() & np.isfinite(num("pr")) & (trk & 1).astype(bool)
    week = int(np.nanmin(num("week")))
    gps_s = num("tow") + (num("week") - week) * 604800.0
    tow0 = float(np.nanmin(gps_s))
    letters = system.to_numpy()[keep]
    slot = num("slot")[keep]
    freq = np.array([FREQUENCY_HZ.get(s, GPS_L1_HZ) for s in letters])
    glonass = letters == "R"
    freq[glonass] = GLONASS_G1_HZ + GLONASS_G1_STEP_HZ * (slot[glonass] - 7)
    doppler = num("doppler")[keep]
    nlos_name = next((h for h in header if h.startswith("NLOS")), None)
    nlos = (pd.to_numeric(frame[nlos_name], errors="coerce").to_numpy(float)[keep]
            if nlos_name else np.full(keep.sum(), np.nan))
    unknown = np.full(keep.sum(), np.nan)
    raw = pd.DataFrame({
        "t": gps_s[keep] - tow0, "sv": num("sv")[keep].astype(int),
        "pseudorange": num("pr")[keep], "pseudorange_rate": -doppler * C_M_S / freq,
        "doppler": doppler, "cn0": num("cn0")[keep],
        **{c: unknown for c in ("sat_x", "sat_y", "sat_z", "sat_vx", "sat_vy", "sat_vz",
                                "sat_clock", "sat_clock_drift", "iono", "tropo", "elevation",
                                "azimuth")},
        "pseudorange_std": num("pr_std")[keep],
        "pseudorange_rate_std": num("do_std")[keep] * C_M_S / freq,
        "system": letters, "signal": "1C", "frequency": freq,
        "carrier_phase": np.where(trk[keep] & 2, num("cp")[keep], np.nan),
        "lli": np.where(trk[keep] & 4, 0, 2), "lock_time": num("lock")[keep] / 1000.0,
        "nlos": nlos})
    raw = raw.sort_values(["t", "system", "sv"], kind="stable").reset_index(drop=True)
    raw.attrs["units"] = {"nlos": "1"}

    epochs = pd.DataFrame({"t": gps_s - tow0, "lat": num("lat"), "lon": num("lon"),
                           "alt": num("height"), "heading": num("heading"),
                           "speed": num("speed")}).dropna(subset=["t", "lat", "lon", "alt"])
    epochs = epochs.drop_duplicates("t").sort_values("t")
    lat = np.radians(epochs["lat"].to_numpy())
    lon = np.radians(epochs["lon"].to_numpy())
    yaw = np.pi / 2 - epochs["heading"].to_numpy()
    speed = epochs["speed"].to_numpy()
    v_ned = np.column_stack([speed * np.cos(yaw), speed * np.sin(yaw), np.zeros(len(yaw))])
    c_ne = ned_to_ecef_matrix(lat, lon)
    truth = reference_truth(epochs["t"].to_numpy(),
                            geodetic_to_ecef(lat, lon, epochs["alt"].to_numpy()).reshape(-1, 3),
                            np.einsum("nij,nj->ni", c_ne, v_ned), None)
    truth["vd"] = np.nan
    truth["yaw"] = np.angle(np.exp(1j * yaw))
    if truth["t"].size < 2:
        raise InputError([Problem(str(path), None, FIELDS["lat"],
                                  "fewer than two epochs with a reference position")])
    return Recording(
        kind="smartloc", sources=[str(path)], gps_week=week, gps_tow=tow0,
        streams={"gnss_raw": raw, "truth": truth},
        reference="smartLoc ground truth (GT columns: NovAtel SPAN INS/GNSS reference per "
                  "epoch; heading and speed, no roll or pitch)",
        sensors={"gnss": {"preset": "automotive", "rate": 1.0 / float(
            np.median(np.diff(truth["t"]))), "outputs": ["raw"]}},
        lacks={"gnss_raw": NOT_ON_RECORD.replace("the segment", "the trace")},
        notes=[f"{int((~keep).sum())} row(s) left out: SBAS, or no valid pseudorange",
               "nlos: the trace's NLOS label (1 NLOS, 0 LOS, NaN unknown)",
               "truth vd unknown (NaN); yaw = pi/2 - the GT heading (0 = east, CCW)"])

