"""GNSS signal and receiver simulation: broadcast orbits, navigation files, the nominal GPS
constellation, atmospheric models, raw measurement synthesis and the receiver's own fixes.

Modules
-------
constants      physical and GPS interface constants (one home)
ephemeris      broadcast Keplerian elements -> satellite position, velocity, clock (IS-GPS-200)
navfiles       RINEX 2/3 navigation and YUMA almanac readers -> one navigation table
constellation  the nominal 24-slot GPS constellation as broadcast elements
atmosphere     Klobuchar ionosphere and Saastamoinen troposphere
receiver       raw pseudorange / Doppler / C/N0 synthesis with their error processes
fix            weighted least-squares position, Doppler velocity, DOPs, fix type
"""
