"""GNSS constants: the one home of the speed of light, the L1 carrier and each system's interface
constants used by the broadcast orbit and clock models (GPS, QZSS, Galileo, BeiDou, GLONASS).

Earth-shape constants (WGS-84 ellipsoid) live in ``simulator.earth``; the two GPS-specific values
below (``MU_GPS_M3_S2`` and ``OMEGA_E_DOT_RAD_S``) are the ones IS-GPS-200 prescribes for the
user algorithm and must be used there even where they coincide with the WGS-84 values.

Public names
------------
C_M_S, F_L1_HZ, LAMBDA_L1_M, F_B1I_HZ, CHIP_L1CA_M, MU_GPS_M3_S2, OMEGA_E_DOT_RAD_S, F_REL_S_SQRTM,
SECONDS_PER_WEEK, MU_GAL_M3_S2, OMEGA_E_GAL_RAD_S, MU_BDS_M3_S2, OMEGA_E_BDS_RAD_S,
MU_GLO_M3_S2, OMEGA_E_GLO_RAD_S, A_E_GLO_M, J2_GLO, KEPLER_CONSTANTS, relativistic_constant.

References
----------
IS-GPS-200N, *Navstar GPS Space Segment/Navigation User Segment Interfaces*, 2022, section
20.3.3.4.3 and Table 20-IV (mu, Omega_e_dot, F); section 3.3.1.1 (L1 = 154 x 10.23 MHz).
IS-QZSS-PNT-005 (2022), 4.1.2: QZSS uses the GPS values.
Galileo OS SIS ICD issue 2.1 (2023), 5.1.1 and Table 59 (mu = 3.986004418e14, Omega_e =
7.2921151467e-5; F = -4.442807309e-10).
BeiDou SIS ICD B1I 3.0 (2019), 5.2.4.10 and Table 5-11 (CGCS2000: mu = 3.986004418e14,
Omega_e = 7.2921150e-5).
GLONASS ICD edition 5.1 (2008), 3.1.3 and Appendix A.3.1 (PZ-90: GM = 398600.4418 km^3/s^2,
a_e = 6378136 m, J2 = 1082625.75e-9, omega_E = 7.292115e-5 rad/s).
"""

from __future__ import annotations

from simulator.timebase import SECONDS_PER_WEEK

C_M_S = 299792458.0  # speed of light in vacuum, m/s (IS-GPS-200 20.3.4.3)
F_L1_HZ = 1575.42e6  # L1 carrier frequency, Hz (154 x 10.23 MHz)
LAMBDA_L1_M = C_M_S / F_L1_HZ  # L1 carrier wavelength, m (0.1903 m)
F_B1I_HZ = 1561.098e6  # BeiDou B1I carrier, Hz (BDS SIS ICD B1I 3.0, 3.2); Galileo E1 = L1
CHIP_L1CA_M = C_M_S / 1.023e6  # C/A-code chip length, m (293.05 m)
MU_GPS_M3_S2 = 3.986005e14  # GPS value of the Earth's gravitational constant, m^3/s^2 (Table 20-IV)
OMEGA_E_DOT_RAD_S = 7.2921151467e-5  # GPS value of the Earth rotation rate, rad/s (Table 20-IV)
F_REL_S_SQRTM = -4.442807633e-10  # relativistic clock constant F = -2 sqrt(mu)/c^2, s/m^0.5
MU_GAL_M3_S2 = 3.986004418e14  # Galileo (OS SIS ICD 5.1.1), m^3/s^2
OMEGA_E_GAL_RAD_S = 7.2921151467e-5  # Galileo Earth rotation rate, rad/s (the GPS value)
MU_BDS_M3_S2 = 3.986004418e14  # BeiDou CGCS2000 GM, m^3/s^2
OMEGA_E_BDS_RAD_S = 7.2921150e-5  # BeiDou CGCS2000 Earth rotation rate, rad/s
MU_GLO_M3_S2 = 3.986004418e14  # GLONASS PZ-90 GM, m^3/s^2
OMEGA_E_GLO_RAD_S = 7.292115e-5  # GLONASS PZ-90 Earth rotation rate, rad/s
A_E_GLO_M = 6378136.0  # GLONASS PZ-90 equatorial radius, m
J2_GLO = 1082625.75e-9  # GLONASS PZ-90 second zonal harmonic
# (mu m^3/s^2, Omega_e rad/s) of the Keplerian broadcast algorithm, per RINEX system letter
KEPLER_CONSTANTS: dict[str, tuple[float, float]] = {
    "G": (MU_GPS_M3_S2, OMEGA_E_DOT_RAD_S),
    "J": (MU_GPS_M3_S2, OMEGA_E_DOT_RAD_S),
    "E": (MU_GAL_M3_S2, OMEGA_E_GAL_RAD_S),
    "C": (MU_BDS_M3_S2, OMEGA_E_BDS_RAD_S),
}


def relativistic_constant(mu_m3_s2: float) -> float:
    """F = -2 sqrt(mu) / c^2 (s/m^0.5), the factor of the eccentricity clock term F e sqrt(A)
    sin E (IS-GPS-200 20.3.3.3.3.1; Galileo OS SIS ICD 5.1.4; BDS SIS ICD 5.2.4.10)."""
    return -2.0 * mu_m3_s2**0.5 / C_M_S**2


__all__ = [
    "C_M_S", "F_L1_HZ", "LAMBDA_L1_M", "F_B1I_HZ", "CHIP_L1CA_M", "MU_GPS_M3_S2",
    "OMEGA_E_DOT_RAD_S",
    "F_REL_S_SQRTM", "SECONDS_PER_WEEK", "MU_GAL_M3_S2", "OMEGA_E_GAL_RAD_S", "MU_BDS_M3_S2",
    "OMEGA_E_BDS_RAD_S", "MU_GLO_M3_S2", "OMEGA_E_GLO_RAD_S", "A_E_GLO_M", "J2_GLO",
    "KEPLER_CONSTANTS", "relativistic_constant",
]
