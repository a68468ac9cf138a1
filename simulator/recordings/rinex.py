"""A receiver's RINEX observation file with a navigation file (and a reference position) as a
dataset: ``landnav import rinex OBS NAV [REFERENCE] -o DIR``.

* ``gnss_raw``: one row per satellite and epoch with the primary code of its system (RINEX 3
  ``C1C``, RINEX 2 ``C1``, else ``P1``/``C1W``), the Doppler (``D1*``), C/N0 (``S1*``) and
  carrier phase (``L1*``, cycles, RINEX sign) of the same band, and the loss-of-lock indicator
  of the phase. Epochs keep their receiver time tags. The satellite states come from the
  navigation file (``simulator.gnss.ephemeris``, every system's own algorithm) at the
  transmission time found from the code (three light-time iterations, the Sagnac rotation),
  given at transmission in the ECEF frame of transmission as SPEC section 5 asks;
  ``sat_clock`` c dt_s (with the relativistic term and the primary signal's group delay),
  ``iono`` the header's Klobuchar model and ``tropo`` the standard-atmosphere model at the
  reference position, as a single-frequency receiver applies them.
* ``truth``: the reference: a position ``LAT,LON,HEIGHT`` (deg, deg, m ellipsoidal) or a file
  with ``t`` (s since the first epoch) or ``tow`` (GPS s of the first epoch's week), ``lat``,
  ``lon``, ``alt``; without one, the header's APPROX POSITION XYZ, which the manifest then
  names as an approximate reference (receivers write it from their own solution, metres off).
  A static reference has zero velocity and no attitude (NaN).

The observation file is read with georinex (RINEX 2 and 3).

Public names
------------
read_rinex_recording.
"""

from __future__ import annotations

import datetime as dt
import os
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from simulator.earth import ecef_to_geodetic, geodetic_to_ecef, ned_to_ecef_matrix
from simulator.errors import InputError, Problem
from simulator.gnss.atmosphere import klobuchar_delay, tropo_delay
from simulator.gnss.constants import C_M_S, SECONDS_PER_WEEK
from simulator.gnss.ephemeris import ephemeris_arrays, primary_frequency_hz, satellites_at
from simulator.gnss.navfiles import read_navigation
from simulator.gnss.receiver import rotate_to_reception_frame
from simulator.recordings.common import Recording, reference_truth
from simulator.timebase import GPS_EPOCH

CODES = ("C1C", "C1", "P1", "C1W", "C1X", "C2I")
BAND_PREFIX = {"C1C": "1C", "C1": "1", "P1": "1", "C1W": "1W", "C1X": "1X", "C2I": "2I"}


def _kind_of(path: Path) -> str:
    """'obs' or 'nav' from the RINEX header's first line (column 21: the file type)."""
    try:
        first = path.open(encoding="ascii", errors="replace").readline()
    except OSError as exc:
        raise InputError([Problem(str(path), None, "", f"cannot read: {exc}")]) from None
    file_type = first[20:21].upper()
    if "RINEX" not in first.upper() or file_type not in ("O", "N", "G", "L", "E", "C"):
        return "other"
    return "obs" if file_type == "O" else "nav"


def _observations(path: Path) -> tuple[pd.DataFrame, np.ndarray]:
    import georinex

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        try:
            ds = georinex.load(path)
        except Exception as exc:  # georinex raises many types for a malformed file
            raise InputError([Problem(str(path), None, "", f"not a readable RINEX "
                                      f"observation file: {exc}")]) from None
    approx = np.asarray(ds.attrs.get("position") or [np.nan] * 3, dtype=float)
    frame = ds.to_dataframe().reset_index()
    return frame, approx


def _reference(text: str | None, week: int, tow0: float) -> pd.DataFrame | None:
    if text is None:
        return None
    if "," in text and not os.path.lexists(text):
        try:
            lat, lon, alt = (float(x) for x in text.split(","))
        except ValueError:
            raise InputError([Problem(text, None, "REFERENCE", "give LAT,LON,HEIGHT (deg, deg, "
                                      "m) or a CSV file")]) from None
        return pd.DataFrame({"lat": [lat], "lon": [lon], "alt": [alt]})
    try:
        frame = pd.read_csv(text)
    except (OSError, ValueError) as exc:
        raise InputError([Problem(text, None, "REFERENCE", f"not a readable CSV: {exc}")]
                         ) from None
    if "tow" in frame and "t" not in frame:
        frame["t"] = frame["tow"] - tow0
    missing = [c for c in ("lat", "lon", "alt") if c not in frame]
    if missing:
        raise InputError([Problem(text, None, ", ".join(missing), "missing column(s)")])
    return frame


def read_rinex_recording(sources: list[str], reference: str | None = None) -> Recording:
    """Read an observation and a navigation file (see the module docstring)."""
    paths = [Path(s) for s in sources]
    kinds = {p: _kind_of(p) for p in paths}
    obs_files = [p for p, k in kinds.items() if k == "obs"]
    nav_files = [p for p, k in kinds.items() if k == "nav"]
    if len(obs_files) != 1 or len(nav_files) != 1:
        raise InputError([Problem(" ".join(sources), None, "SOURCE",
                                  "give one RINEX observation file and one navigation file "
                                  f"(found {len(obs_files)} and {len(nav_files)})")])
    frame, approx = _observations(obs_files[0])
    nav = read_navigation(nav_files[0])
    code = next((c for c in CODES if c in frame), None)
    if code is None:
        raise InputError([Problem(str(obs_files[0]), None, "observation types",
                                  f"none of the codes {', '.join(CODES)}")])
    band = BAND_PREFIX[code][0]
    frame = frame[np.isfinite(frame[code]) & (frame[code] > 0)].copy()
    frame["system"] = frame["sv"].str[0]
    frame["prn"] = frame["sv"].str[1:].astype(int)
    frame = frame[frame["system"].isin(sorted(set(nav["system"]) if "system" in nav
                                               else {"G"}))]
    gps_s = (frame["time"] - pd.Timestamp(GPS_EPOCH)).dt.total_seconds().to_numpy()
    week = int(gps_s.min() // SECONDS_PER_WEEK)
    t_rx = gps_s - week * SECONDS_PER_WEEK      # GPS s of ``week``
    tow0 = float(t_rx.min())

    ref = _reference(reference, week, tow0)
    if ref is None:
        if not np.isfinite(approx).all():
            raise InputError([Problem(str(obs_files[0]), None, "APPROX POSITION XYZ",
                                      "missing: give a reference position")])
        lat0, lon0, alt0 = (float(x) for x in ecef_to_geodetic(approx))
        ref = pd.DataFrame({"lat": [np.degrees(lat0)], "lon": [np.degrees(lon0)],
                            "alt": [alt0]})
        source = "the RINEX header's APPROX POSITION XYZ (approximate, not a survey value)"
    else:
        source = f"reference position {reference}"
    static = len(ref) == 1
    if static:
        rx = geodetic_to_ecef(np.radians(ref["lat"].iloc[0]), np.radians(ref["lon"].iloc[0]),
                              ref["alt"].iloc[0]).reshape(1, 3).repeat(len(frame), axis=0)
    else:
        t_obs = t_rx - tow0
        rx = geodetic_to_ecef(np.radians(np.interp(t_obs, ref["t"], ref["lat"])),
                              np.radians(np.interp(t_obs, ref["t"], ref["lon"])),
                              np.interp(t_obs, ref["t"], ref["alt"])).reshape(-1, 3)

    eph = ephemeris_arrays(nav, week)
    system = frame["system"].to_numpy()
    prn = frame["prn"].to_numpy()
    pr = frame[code].to_numpy(float)
    t_tx = t_rx - pr / C_M_S
    for _ in range(3):
        state = satellites_at(eph, system, prn, t_tx)
        tau = np.linalg.norm(rotate_to_reception_frame(state["pos"], np.linalg.norm(
            state["pos"] - rx, axis=1) / C_M_S) - rx, axis=1) / C_M_S
        t_tx = t_rx - tau
    state = satellites_at(eph, system, prn, t_tx)
    rel = rotate_to_reception_frame(state["pos"], tau) - rx
    rng = np.linalg.norm(rel, axis=1)
    los = rel / rng[:, None]
    lat, lon, alt = ecef_to_geodetic(rx)
    los_ned = np.einsum("nji,nj->ni", ned_to_ecef_matrix(lat, lon), los)
    elevation = np.arcsin(np.clip(-los_ned[:, 2], -1.0, 1.0))
    azimuth = np.mod(np.arctan2(los_ned[:, 1], los_ned[:, 0]), 2 * np.pi)
    alpha = nav.attrs.get("iono_alpha")
    beta = nav.attrs.get("iono_beta")
    channel = np.zeros(len(frame))
    freq = primary_frequency_hz(system, channel)
    if alpha is not None and beta is not None:
        iono = klobuchar_delay(lat, lon, azimuth, elevation, t_rx, np.asarray(alpha),
                               np.asarray(beta)) * (1575.42e6 / freq) ** 2
    else:
        iono = np.full(len(frame), np.nan)
    day = (GPS_EPOCH + dt.timedelta(seconds=week * SECONDS_PER_WEEK + tow0)).timetuple().tm_yday
    tropo = tropo_delay(lat, alt, elevation, float(day))
    doppler_col = next((c for c in frame if c.startswith("D" + band)), None)
    cn0_col = next((c for c in frame if c.startswith("S" + band)), None)
    phase_col = next((c for c in frame if c.startswith("L" + band) and "lli" not in c
                      and "ssi" not in c), None)

    def values(column: str | None) -> np.ndarray:
        return frame[column].to_numpy(float) if column else np.full(len(frame), np.nan)

    doppler = values(doppler_col)
    raw = pd.DataFrame({
        "t": t_rx - tow0, "sv": prn, "pseudorange": pr,
        "pseudorange_rate": -doppler * C_M_S / freq, "doppler": doppler, "cn0": values(cn0_col),
        "sat_x": state["pos"][:, 0], "sat_y": state["pos"][:, 1], "sat_z": state["pos"][:, 2],
        "sat_vx": state["vel"][:, 0], "sat_vy": state["vel"][:, 1], "sat_vz": state["vel"][:, 2],
        "sat_clock": C_M_S * state["clock_s"], "sat_clock_drift": C_M_S
        * state["clock_drift_s_s"], "iono": iono, "tropo": tropo, "elevation": elevation,
        "azimuth": azimuth, "health": np.where(state["valid"], 0, 1), "system": system,
        "signal": code[1:] if len(code) == 3 else "1C", "frequency": freq,
        "carrier_phase": values(phase_col)})
    raw = raw[state["valid"]].sort_values(["t", "system", "sv"], kind="stable")
    raw = raw.reset_index(drop=True)

    epochs = np.unique(raw["t"].to_numpy())
    if static:
        n = len(epochs)
        pos = rx[:1].repeat(n, axis=0)
        truth = reference_truth(epochs, pos, np.zeros((n, 3)), None)
    else:
        ecef = geodetic_to_ecef(np.radians(ref["lat"].to_numpy(float)),
                                np.radians(ref["lon"].to_numpy(float)),
                                ref["alt"].to_numpy(float)).reshape(-1, 3)
        t_ref = ref["t"].to_numpy(float)
        vel = np.gradient(ecef, t_ref, axis=0) if len(t_ref) > 1 else np.zeros_like(ecef)
        truth = reference_truth(t_ref, ecef, vel, None)
    interval = float(np.median(np.diff(epochs))) if len(epochs) > 1 else 1.0
    return Recording(
        kind="rinex", sources=[str(p) for p in paths], gps_week=week, gps_tow=tow0,
        streams={"gnss_raw": raw, "truth": truth}, reference=source,
        sensors={"gnss": {"preset": "geodetic", "rate": round(1.0 / interval, 6),
                          "outputs": ["raw"]}},
        notes=[f"code {code}, Doppler {doppler_col}, C/N0 {cn0_col}, phase {phase_col}",
               "satellite states from the navigation file at the code's transmission time",
               f"{int((~state['valid']).sum())} observation(s) without a navigation record "
               "left out"])
