"""GPS constants: the one home of the speed of light, the L1 carrier and the GPS interface
constants used by the broadcast orbit and clock models.

Earth-shape constants (WGS-84 ellipsoid) live in ``simulator.earth``; the two GPS-specific values
below (``MU_GPS_M3_S2`` and ``OMEGA_E_DOT_RAD_S``) are the ones IS-GPS-200 prescribes for the
user algorithm and must be used there even where they coincide with the WGS-84 values.

Public names
------------
C_M_S, F_L1_HZ, LAMBDA_L1_M, CHIP_L1CA_M, MU_GPS_M3_S2, OMEGA_E_DOT_RAD_S, F_REL_S_SQRTM,
SECONDS_PER_WEEK.

References
----------
IS-GPS-200N, *Navstar GPS Space Segment/Navigation User Segment Interfaces*, 2022, section
20.3.3.4.3 and Table 20-IV (mu, Omega_e_dot, F); section 3.3.1.1 (L1 = 154 x 10.23 MHz).
"""

from __future__ import annotations

from simulator.timebase import SECONDS_PER_WEEK

C_M_S = 299792458.0  # speed of light in vacuum, m/s (IS-GPS-200 20.3.4.3)
F_L1_HZ = 1575.42e6  # L1 carrier frequency, Hz (154 x 10.23 MHz)
LAMBDA_L1_M = C_M_S / F_L1_HZ  # L1 carrier wavelength, m (0.1903 m)
CHIP_L1CA_M = C_M_S / 1.023e6  # C/A-code chip length, m (293.05 m)
MU_GPS_M3_S2 = 3.986005e14  # GPS value of the Earth's gravitational constant, m^3/s^2 (Table 20-IV)
OMEGA_E_DOT_RAD_S = 7.2921151467e-5  # GPS value of the Earth rotation rate, rad/s (Table 20-IV)
F_REL_S_SQRTM = -4.442807633e-10  # relativistic clock constant F = -2 sqrt(mu)/c^2, s/m^0.5

__all__ = [
    "C_M_S", "F_L1_HZ", "LAMBDA_L1_M", "CHIP_L1CA_M", "MU_GPS_M3_S2", "OMEGA_E_DOT_RAD_S",
    "F_REL_S_SQRTM", "SECONDS_PER_WEEK",
]
