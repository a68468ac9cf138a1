"""The GNSS signals a receiver tracks: carrier frequency, code chip rate, pilot or data channel,
the broadcast group delay that applies, and the power against GPS L1 C/A; the signal sets of the
receiver presets; the ionosphere's 1/f^2 scaling.

Signals are keyed by (system letter, RINEX 3 band-and-attribute code), e.g. ("G", "2W"); every
function takes the system, the signal and, for GLONASS FDMA, the satellite's frequency channel,
so that a constellation plugs in by (system, sv, signal, frequency).

Public names
------------
Signal, SIGNALS, PRESET_SIGNALS, PRIMARY_SIGNAL, signal, carrier_frequency_hz,
iono_factor, group_delay_factor, signal_group_delay_s, default_signals.

References
----------
IS-GPS-200N (2022) 3.3.1.1 (L1 = 154 f0, L2 = 120 f0, f0 = 10.23 MHz), 20.3.3.3.3.2 (the L2
P(Y) group delay gamma T_GD, gamma = (f_L1 / f_L2)^2), Table 3-Va (minimum received powers:
L1 C/A -158.5 dBW, L2 P(Y) -161.5 dBW); IS-GPS-705J (L5 = 115 f0; I5 and Q5 -157.9 dBW each).
Galileo OS SIS ICD 2.1 (2023) 2.3 (E1 1575.42, E5a 1176.45, E5b 1207.14 MHz; E1-C, E5a-Q and
E5b-Q pilots) and 5.1.5 (BGD). BeiDou ICD B1I 3.0 (1561.098 MHz, 2.046 Mchip/s; 5.2.4.10
TGD1, TGD2) and B2a 1.0 (1176.45 MHz pilot). GLONASS ICD 5.1 (2008) 3.3.1.1 (G1 1602 + k
0.5625 MHz, G2 1246 + k 0.4375 MHz). RINEX 3.04 (2018) section 5.1 and Table 4 (observation codes).
Ionosphere: first-order delay 40.3 TEC / f^2 (m, TEC in electrons/m^2), the code delayed and
the phase advanced by it (Misra & Enge 2011, *Global Positioning System*, 2nd ed., eq. 5.14;
Hofmann-Wellenhof, Lichtenegger & Wasle 2008, *GNSS*, eq. 5.72).
Signal strengths against L1 C/A: measured in the refdata 1f observation files (a Septentrio
PolaRx4 geodetic receiver: S2W - S1C = -7.0 dB over 20 signals, S2L - S1C = -1.4 dB over 14;
a Pixel 6: S5Q - S1C = -3.4 dB (GPS, 262) and -2.7 dB (Galileo, 161)); elsewhere the ICDs'
minimum received powers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simulator.gnss.constants import F_L1_HZ

F0_HZ = 10.23e6  # GPS fundamental frequency


@dataclass(frozen=True)
class Signal:
    """One trackable signal.

    ``frequency_hz`` is the carrier (for GLONASS FDMA the channel-0 frequency, with
    ``channel_step_hz`` per channel); ``chip_rate_hz`` the ranging code's chip rate (the DLL's
    chip length c / chip rate); ``pilot``: tracked on a data-free channel by a pure PLL, so no
    half-cycle ambiguity (a data channel's Costas loop has one until the navigation message's
    preamble resolves it, which takes up to one ``frame_s``); ``cn0_offset_db``: C/N0 against
    L1 C/A at the same elevation; ``group_delay``: the broadcast term and factor of the code's
    group delay (``group_delay_factor``).
    """

    frequency_hz: float
    chip_rate_hz: float
    pilot: bool
    frame_s: float
    cn0_offset_db: float
    group_delay: str
    channel_step_hz: float = 0.0


_F_L2 = 120 * F0_HZ
_F_L5 = 115 * F0_HZ
_F_E5B = 118 * F0_HZ
_F_B1I = 1561.098e6
SIGNALS: dict[tuple[str, str], Signal] = {
    # GPS: L1 C/A (LNAV data, 6 s subframes), P(Y) semicodeless, L2C (CL pilot / CM data), L5
    ("G", "1C"): Signal(F_L1_HZ, 1.023e6, False, 6.0, 0.0, "tgd_l1"),
    ("G", "1W"): Signal(F_L1_HZ, 10.23e6, False, 6.0, -7.0, "tgd_l1"),
    ("G", "2W"): Signal(_F_L2, 10.23e6, False, 6.0, -7.0, "tgd_l2"),
    ("G", "2L"): Signal(_F_L2, 1.023e6, True, 0.0, -1.4, "tgd_l2"),
    ("G", "2S"): Signal(_F_L2, 1.023e6, False, 12.0, -1.4, "tgd_l2"),
    ("G", "5Q"): Signal(_F_L5, 10.23e6, True, 0.0, 0.6, "tgd_l5"),
    ("G", "5I"): Signal(_F_L5, 10.23e6, False, 6.0, 0.6, "tgd_l5"),
    # QZSS: the GPS-compatible signals
    ("J", "1C"): Signal(F_L1_HZ, 1.023e6, False, 6.0, 0.0, "tgd_l1"),
    ("J", "2L"): Signal(_F_L2, 1.023e6, True, 0.0, -1.4, "tgd_l2"),
    ("J", "5Q"): Signal(_F_L5, 10.23e6, True, 0.0, 0.6, "tgd_l5"),
    # Galileo: E1-C, E5a-Q, E5b-Q pilots (BGD E1-E5a / E1-E5b)
    ("E", "1C"): Signal(F_L1_HZ, 1.023e6, True, 0.0, 0.0, "bgd_e1"),
    ("E", "5Q"): Signal(_F_L5, 10.23e6, True, 0.0, 0.6, "bgd_e5a"),
    ("E", "7Q"): Signal(_F_E5B, 10.23e6, True, 0.0, 0.6, "bgd_e5b"),
    # BeiDou: B1I (D1 data, 6 s subframes), B2a pilot, B2I data
    ("C", "2I"): Signal(_F_B1I, 2.046e6, False, 6.0, -1.0, "tgd_b1i"),
    ("C", "5P"): Signal(_F_L5, 10.23e6, True, 0.0, 0.6, "tgd_b2a"),
    ("C", "7I"): Signal(1207.14e6, 2.046e6, False, 6.0, -1.0, "tgd_b2i"),
    # GLONASS FDMA: C/A on G1 and G2 (2 s strings)
    ("R", "1C"): Signal(1602.0e6, 0.511e6, False, 2.0, -1.0, "glo_l1", 0.5625e6),
    ("R", "2C"): Signal(1246.0e6, 0.511e6, False, 2.0, -3.0, "glo_l2", 0.4375e6),
}

# the signals of each receiver class (RINEX codes per system), what real receivers of the class
# record: a geodetic receiver (refdata 1f, Septentrio PolaRx4: GPS 1C 1W 2W 2L 5Q, Galileo 1C
# 5Q 7Q, BeiDou 2I 7I, GLONASS 1C 2P 2C), a u-blox ZED-F9P-class dual-band module (UBX-17051259
# datasheet: GPS L1C/A L2C, Galileo E1 E5b, BeiDou B1I B2I, GLONASS L1OF L2OF, QZSS L1C/A L2C;
# its RAWX L2C is the CL pilot, RINEX 2L), a dual-frequency phone (refdata 1f, Pixel 6: GPS 1C
# 5Q, Galileo 1C 5Q, GLONASS 1C) and a mass-market single-band module (u-blox M8: L1 only)
_GEODETIC = {"gps": ["1C", "2W", "5Q"], "galileo": ["1C", "5Q", "7Q"], "beidou": ["2I", "5P"],
             "glonass": ["1C", "2C"], "qzss": ["1C", "2L", "5Q"]}
PRESET_SIGNALS: dict[str, dict[str, list[str]]] = {
    "geodetic": _GEODETIC,
    "dual-band": {"gps": ["1C", "2L"], "galileo": ["1C", "7Q"], "beidou": ["2I", "7I"],
                  "glonass": ["1C", "2C"], "qzss": ["1C", "2L"]},
    "smartphone": {"gps": ["1C", "5Q"], "galileo": ["1C", "5Q"], "beidou": ["2I"],
                   "glonass": ["1C"], "qzss": ["1C", "5Q"]},
    "automotive": {"gps": ["1C"], "galileo": ["1C"], "beidou": ["2I"], "glonass": ["1C"],
                   "qzss": ["1C"]},
}
# the signal a single-frequency user (the receiver's fix, the single-frequency estimators)
# takes from each system: the open L1/E1/B1/G1 signal
PRIMARY_SIGNAL = {"G": "1C", "E": "1C", "C": "2I", "R": "1C", "J": "1C"}


def signal(system: str, code: str) -> Signal:
    """The signal ``code`` of ``system`` (RINEX letter); KeyError names what is known."""
    try:
        return SIGNALS[(system, code)]
    except KeyError:
        known = sorted(c for s, c in SIGNALS if s == system)
        raise KeyError(f"unknown signal {system}{code}; known for {system}: "
                       f"{', '.join(known)}") from None


def carrier_frequency_hz(system: str, code: str, channel: np.ndarray | int = 0) -> np.ndarray:
    """Carrier frequency, Hz; ``channel`` the GLONASS frequency channel k (ignored elsewhere)."""
    s = signal(system, code)
    return s.frequency_hz + s.channel_step_hz * np.asarray(channel, dtype=float)


def iono_factor(frequency_hz: np.ndarray) -> np.ndarray:
    """The first-order ionosphere at f relative to L1: (f_L1 / f)^2 (delay 40.3 TEC / f^2)."""
    return (F_L1_HZ / np.asarray(frequency_hz, dtype=float)) ** 2


def group_delay_factor(system: str, code: str) -> float:
    """The multiple of GPS/QZSS T_GD a signal's code carries, so that the satellite clock a
    user of that signal applies is dt_sv - factor T_GD: 1 on L1 and gamma = (f_L1 / f_L2)^2
    on L2 (IS-GPS-200 20.3.3.3.3.2). L5 without the CNAV ISCs takes the same frequency law,
    (f_L1 / f_L5)^2 (the group delay difference of a dispersive hardware path; ISC_L5 = 0).
    0 for the other systems (``signal_group_delay_s`` has their terms)."""
    term = signal(system, code).group_delay
    if term == "tgd_l1":
        return 1.0
    if term in ("tgd_l2", "tgd_l5"):
        return float(iono_factor(signal(system, code).frequency_hz))
    return 0.0


def signal_group_delay_s(system: str, code: str, primary_s: np.ndarray, tgd_s: np.ndarray,
                         tgd2_s: np.ndarray) -> np.ndarray:
    """The group delay of signal ``code``'s ranging code against the broadcast clock's
    reference, s: a user of the signal applies dt_sv - this (dt_sv the clock polynomial with
    the relativistic term), as each interface document has it.

    - GPS, QZSS: ``group_delay_factor`` x T_GD (``tgd_s``).
    - Galileo (OS SIS ICD 2.1, 5.1.5): the clock is for the E1,E5b (I/NAV) or E1,E5a (F/NAV)
      ionosphere-free pair, and E1 carries the BGD of that pair (``primary_s``: BGD(E1,E5b)
      or BGD(E1,E5a), what ``satellite_state`` subtracts). On the pair's other signal the ICD
      gives (f_E1 / f_E5x)^2 BGD(E1,E5x). E1 being the same signal whichever clock is used,
      dt_FNAV - BGD(E1,E5a) = dt_INAV - BGD(E1,E5b), so on E5x against either clock the delay is
      ``primary_s`` + ((f_E1 / f_E5x)^2 - 1) BGD(E1,E5x): with E5x of the clock's own pair it
      is the ICD's formula, with the other pair the same formula moved to that clock.
      ``tgd_s`` is BGD(E1,E5a), ``tgd2_s`` BGD(E1,E5b).
    - BeiDou (BDS SIS ICD B1I 3.0, 5.2.4.10: the clock refers to B3I): TGD1 on B1I
      (``tgd_s``), TGD2 on B2I (``tgd2_s``); B2a has no term in the D1/D2 messages (its
      TGD_B2ap is broadcast in B-CNAV only): 0.
    - GLONASS: no group delay in the broadcast G1/G2 record: 0.
    """
    spec = signal(system, code)
    term = spec.group_delay
    if system in ("G", "J"):
        return group_delay_factor(system, code) * np.asarray(tgd_s, dtype=float)
    if term == "bgd_e1":
        return np.asarray(primary_s, dtype=float)
    if term in ("bgd_e5a", "bgd_e5b"):
        bgd = tgd_s if term == "bgd_e5a" else tgd2_s
        return primary_s + (float(iono_factor(spec.frequency_hz)) - 1.0) * np.asarray(bgd)
    if term == "tgd_b1i":
        return np.asarray(tgd_s, dtype=float)
    if term == "tgd_b2i":
        return np.asarray(tgd2_s, dtype=float)
    return np.zeros(np.shape(primary_s))


def default_signals(preset: str, systems: list[str]) -> dict[str, list[str]]:
    """The signals of ``preset`` (``PRESET_SIGNALS``; another preset, ``ideal`` among them: the
    automotive set, L1 only) for each of ``systems``."""
    table = PRESET_SIGNALS.get(preset, PRESET_SIGNALS["automotive"])
    return {name: list(table[name]) for name in systems}
