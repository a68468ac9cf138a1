"""Google Smartphone Decimeter Challenge traces (2022 layout): a phone's raw GNSS
measurements with Google's derived satellite states (``device_gnss.csv``) and the reference
trajectory (``ground_truth.csv``), as documented on the challenge's data page.

* ``gnss_raw``: one row per ``Raw`` record (satellite and signal of an epoch), stamped with its
  epoch's GPS time (``ArrivalTimeNanosSinceGpsEpoch``, the receiver's estimate of GPS time at
  the measurement). ``RawPseudorangeMeters`` and its uncertainty, the pseudorange rate and its
  uncertainty, C/N0, ``CarrierFrequencyHz``; the satellite states are Google's:
  ``SvPosition*EcefMeters`` and ``SvVelocity*`` at transmission in the ECEF frame of
  transmission (SPEC section 5 takes them as they are), ``SvClockBiasMeters`` (with the
  relativistic term and the group delay), ``IonosphericDelayMeters`` (Klobuchar),
  ``TroposphericDelayMeters``, elevation and azimuth. ``IsrbMeters`` (the inter-signal range
  bias Google estimated for the phone) is kept as the extra column ``isrb``: the SPEC identity
  ``pseudorange + sat_clock - iono - tropo = range + receiver clock`` holds per system, each
  system with its own clock. The carrier phase is ``AccumulatedDeltaRangeMeters`` over the
  wavelength where the ADR state says valid (bit 1), with ``lli`` 1 where it says reset (2)
  or cycle slip (4). ``system`` from ``ConstellationType`` (1 G, 3 R, 4 J, 5 C, 6 E) and
  ``signal`` from ``SignalType`` (GPS_L1 1C, GPS_L5 5Q, GAL_E1 1C, GAL_E5A 5Q, GLO_G1 1C,
  BDS_B1I 2I, QZS_J1 1C, QZS_J5 5Q).
* ``gnss_fix``: Google's weighted-least-squares positions (``WlsPosition*EcefMeters``), one per
  epoch, with no velocity (NaN) and no DOP (NaN): what the trace gives as a fix.
* ``truth``: ``ground_truth.csv`` (1 Hz, a survey-grade INS/GNSS reference: latitude,
  longitude, ellipsoidal altitude, speed, bearing). North and east velocity from speed and
  bearing, the down velocity from the altitude's central differences; yaw the bearing where
  the car moves faster than 1 m/s (NaN at standstill, where a bearing is not a heading); roll
  and pitch NaN (the reference does not give them).

``t = 0`` is the earliest of the first ground-truth time and the first measurement epoch.

Public names
------------
read_gsdc.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from simulator.earth import ecef_to_geodetic, geodetic_to_ecef, ned_to_ecef_matrix
from simulator.errors import InputError, Problem
from simulator.recordings.common import Recording, reference_truth
from simulator.timebase import SECONDS_PER_WEEK, utc_to_gps

C_M_S = 299792458.0
SYSTEMS = {1: "G", 3: "R", 4: "J", 5: "C", 6: "E"}
SIGNALS = {"GPS_L1": "1C", "GPS_L5": "5Q", "GAL_E1": "1C", "GAL_E5A": "5Q", "GLO_G1": "1C",
           "BDS_B1I": "2I", "QZS_J1": "1C", "QZS_J5": "5Q"}
ADR_VALID, ADR_RESET, ADR_CYCLE_SLIP = 1, 2, 4
MOVING_M_S = 1.0
RAW_COLUMNS = ("ArrivalTimeNanosSinceGpsEpoch", "Svid", "ConstellationType", "SignalType",
               "RawPseudorangeMeters", "PseudorangeRateMetersPerSecond", "Cn0DbHz",
               "CarrierFrequencyHz", "SvPositionXEcefMeters", "SvPositionYEcefMeters",
               "SvPositionZEcefMeters", "SvVelocityXEcefMetersPerSecond",
               "SvVelocityYEcefMetersPerSecond", "SvVelocityZEcefMetersPerSecond",
               "SvClockBiasMeters", "SvClockDriftMetersPerSecond", "IonosphericDelayMeters",
               "TroposphericDelayMeters", "SvElevationDegrees", "SvAzimuthDegrees")
TRUTH_COLUMNS = ("LatitudeDegrees", "LongitudeDegrees", "AltitudeMeters", "SpeedMps",
                 "BearingDegrees", "UnixTimeMillis")


def _files(sources: list[str]) -> tuple[Path, Path]:
    paths = [Path(s) for s in sources]
    if len(paths) == 1 and paths[0].is_dir():
        paths = [paths[0] / "device_gnss.csv", paths[0] / "ground_truth.csv"]
    by_name = {p.name: p for p in paths}
    missing = [n for n in ("device_gnss.csv", "ground_truth.csv") if n not in by_name]
    if missing or not all(p.is_file() for p in by_name.values()):
        raise InputError([Problem(" ".join(sources), None, "SOURCE",
                                  "give device_gnss.csv and ground_truth.csv of a trace, or "
                                  "the folder holding both")])
    return by_name["device_gnss.csv"], by_name["ground_truth.csv"]


def _read_csv(path: Path, needed: tuple[str, ...]) -> pd.DataFrame:
    try:
        frame = pd.read_csv(path, low_memory=False)
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise InputError([Problem(str(path), None, "", f"not a readable CSV: {exc}")]) from None
    missing = [c for c in needed if c not in frame]
    if missing:
        raise InputError([Problem(str(path), None, ", ".join(missing), "missing column(s)")])
    return frame


def read_gsdc(sources: list[str]) -> Recording:
    """Read a GSDC 2022 trace (see the module docstring)."""
    gnss_path, truth_path = _files(sources)
    device = _read_csv(gnss_path, RAW_COLUMNS)
    if "MessageType" in device:
        device = device[device["MessageType"] == "Raw"]
    device = device[device["ConstellationType"].isin(list(SYSTEMS))]
    # rows without an epoch time or a pseudorange carry no measurement (a signal the phone
    # lists but does not track)
    measured = (device["ArrivalTimeNanosSinceGpsEpoch"].notna()
                & device["RawPseudorangeMeters"].notna())
    untracked = int((~measured).sum())
    device = device[measured]
    if device.empty:
        raise InputError([Problem(str(gnss_path), None, "", "no Raw row with an epoch time "
                                  "and a pseudorange")])
    device = device.sort_values("ArrivalTimeNanosSinceGpsEpoch", kind="stable")
    truth_csv = _read_csv(truth_path, TRUTH_COLUMNS)

    arrival_s = device["ArrivalTimeNanosSinceGpsEpoch"].to_numpy(dtype=np.int64) // 1000 * 1e-6
    week = int(arrival_s[0] // SECONDS_PER_WEEK)
    gps_s = arrival_s - week * SECONDS_PER_WEEK          # seconds of ``week``
    utc_ms = truth_csv["UnixTimeMillis"].to_numpy(dtype=np.int64)
    truth_gps = np.array([utc_to_gps(pd.Timestamp(ms, unit="ms").to_pydatetime())
                          for ms in utc_ms])
    truth_s = truth_gps[:, 1] + (truth_gps[:, 0] - week) * SECONDS_PER_WEEK
    tow0 = float(min(gps_s[0], truth_s[0]))

    freq = device["CarrierFrequencyHz"].to_numpy(dtype=float)
    adr_state = device["AccumulatedDeltaRangeState"].fillna(0).to_numpy(dtype=int) \
        if "AccumulatedDeltaRangeState" in device else np.zeros(len(device), dtype=int)
    adr = (device["AccumulatedDeltaRangeMeters"].to_numpy(dtype=float)
           if "AccumulatedDeltaRangeMeters" in device else np.full(len(device), np.nan))
    phase = np.where(adr_state & ADR_VALID, adr * freq / C_M_S, np.nan)
    lli = np.where(adr_state & (ADR_RESET | ADR_CYCLE_SLIP), 1, 0)

    def column(name: str, default: float = np.nan) -> np.ndarray:
        return (device[name].to_numpy(dtype=float) if name in device
                else np.full(len(device), default))

    signal = device["SignalType"].map(SIGNALS)
    gnss_raw = pd.DataFrame({
        "t": gps_s - tow0, "sv": device["Svid"].to_numpy(dtype=int),
        "pseudorange": column("RawPseudorangeMeters"),
        "pseudorange_rate": column("PseudorangeRateMetersPerSecond"),
        "doppler": -column("PseudorangeRateMetersPerSecond") * freq / C_M_S,
        "cn0": column("Cn0DbHz"),
        "sat_x": column("SvPositionXEcefMeters"), "sat_y": column("SvPositionYEcefMeters"),
        "sat_z": column("SvPositionZEcefMeters"),
        "sat_vx": column("SvVelocityXEcefMetersPerSecond"),
        "sat_vy": column("SvVelocityYEcefMetersPerSecond"),
        "sat_vz": column("SvVelocityZEcefMetersPerSecond"),
        "sat_clock": column("SvClockBiasMeters"),
        "sat_clock_drift": column("SvClockDriftMetersPerSecond"),
        "iono": column("IonosphericDelayMeters"), "tropo": column("TroposphericDelayMeters"),
        "elevation": np.radians(column("SvElevationDegrees")),
        "azimuth": np.radians(column("SvAzimuthDegrees")),
        "pseudorange_std": column("RawPseudorangeUncertaintyMeters"),
        "pseudorange_rate_std": column("PseudorangeRateUncertaintyMetersPerSecond"),
        "health": np.zeros(len(device)),
        "system": device["ConstellationType"].map(SYSTEMS).to_numpy(),
        "signal": signal.fillna("").to_numpy(), "frequency": freq,
        "carrier_phase": phase, "lli": lli, "isrb": column("IsrbMeters", 0.0)})
    gnss_raw = gnss_raw[gnss_raw["signal"] != ""]

    gnss_raw = gnss_raw.reset_index(drop=True)
    gnss_raw.attrs["units"] = {"isrb": "m"}
    streams: dict[str, pd.DataFrame] = {"gnss_raw": gnss_raw}
    wls = device[["ArrivalTimeNanosSinceGpsEpoch", "WlsPositionXEcefMeters",
                  "WlsPositionYEcefMeters", "WlsPositionZEcefMeters"]].dropna() \
        if "WlsPositionXEcefMeters" in device else None
    if wls is not None and len(wls):
        epochs = wls.drop_duplicates("ArrivalTimeNanosSinceGpsEpoch")
        t_fix = epochs["ArrivalTimeNanosSinceGpsEpoch"].to_numpy(np.int64) // 1000 * 1e-6 \
            - week * SECONDS_PER_WEEK - tow0
        lat, lon, alt = ecef_to_geodetic(epochs.iloc[:, 1:4].to_numpy(dtype=float))
        nan = np.full(len(epochs), np.nan)
        streams["gnss_fix"] = pd.DataFrame({
            "t": t_fix, "lat": np.degrees(lat), "lon": np.degrees(lon), "alt": alt,
            "vn": nan, "ve": nan, "vd": nan, "speed": nan, "course": nan, "num_sats": nan,
            "hdop": nan, "vdop": nan, "fix": np.full(len(epochs), 2)})

    t_truth = truth_s - tow0
    lat_r = np.radians(truth_csv["LatitudeDegrees"].to_numpy(dtype=float))
    lon_r = np.radians(truth_csv["LongitudeDegrees"].to_numpy(dtype=float))
    alt = truth_csv["AltitudeMeters"].to_numpy(dtype=float)
    speed = truth_csv["SpeedMps"].to_numpy(dtype=float)
    bearing = np.radians(truth_csv["BearingDegrees"].to_numpy(dtype=float))
    vd = -np.gradient(alt, t_truth) if len(alt) > 1 else np.zeros(1)
    v_ned = np.column_stack([speed * np.cos(bearing), speed * np.sin(bearing), vd])
    c_ne = ned_to_ecef_matrix(lat_r, lon_r)
    truth = reference_truth(t_truth, geodetic_to_ecef(lat_r, lon_r, alt).reshape(-1, 3),
                            np.einsum("nij,nj->ni", c_ne, v_ned), None)
    truth["yaw"] = np.where(speed > MOVING_M_S, np.angle(np.exp(1j * bearing)), np.nan)
    streams["truth"] = truth

    return Recording(
        kind="gsdc", sources=[str(gnss_path), str(truth_path)], gps_week=week, gps_tow=tow0,
        streams=streams,
        reference="GSDC ground_truth.csv (1 Hz survey-grade INS/GNSS reference; no attitude "
                  "but the bearing; the down velocity from its altitude's differences)",
        sensors={"gnss": {"preset": "automotive", "rate": 1.0, "outputs": ["fix", "raw"]}},
        notes=["gnss_raw: Google's satellite states, clocks and model delays as given; "
               "IsrbMeters in the extra column isrb",
               f"{untracked} Raw row(s) without an epoch time or a pseudorange left out",
               "gnss_fix: Google's WLS positions, no velocity or DOP (NaN)",
               "the receiver preset is landnav's automotive one, not the phone's datasheet"])
