"""GNSS signal and receiver simulation: broadcast orbits, navigation files, the nominal GPS
constellation, atmospheric models, raw measurement synthesis and the receiver's own fixes.

Modules
-------
constants      physical and GPS interface constants (one home)
ephemeris      broadcast Keplerian elements -> satellite position, velocity, clock (IS-GPS-200)
navfiles       RINEX 2/3 navigation and YUMA almanac readers -> one navigation table
constellation  the nominal 24-slot GPS constellation as broadcast elements
atmosphere     Klobuchar ionosphere, Saastamoinen troposphere with the Niell mapping
receiver       signal geometry (light time, Sagnac), look angles, clock, C/N0, tracking noise,
               Gauss-Markov and multipath processes
errors         the receiver's error budget: draws every error term, reports its 1-sigma
fix            weighted least-squares position, Doppler velocity, DOPs, fix type, smoothing
rinex_writer   RINEX 3.04 observation and navigation files
nmea           NMEA 0183 GGA, RMC, VTG, GSA, GSV sentences

The sensor that ties them together is ``simulator.sensors.gnss``; the canyon sky geometry is in
``simulator.environment.sky``.
"""
