"""Time scales: UTC to GPS time (week, seconds of week) with the leap-second table.

Public functions
----------------
parse_utc, utc_to_gps, gps_to_utc, leap_seconds.
"""

from __future__ import annotations

import datetime as dt

GPS_EPOCH = dt.datetime(1980, 1, 6)
SECONDS_PER_WEEK = 604800.0

# UTC dates from which GPS - UTC equals the given number of seconds (IERS Bulletin C; the last
# leap second was inserted at the end of 2016-12-31).
_LEAPS = [
    (dt.datetime(1981, 7, 1), 1), (dt.datetime(1982, 7, 1), 2), (dt.datetime(1983, 7, 1), 3),
    (dt.datetime(1985, 7, 1), 4), (dt.datetime(1988, 1, 1), 5), (dt.datetime(1990, 1, 1), 6),
    (dt.datetime(1991, 1, 1), 7), (dt.datetime(1992, 7, 1), 8), (dt.datetime(1993, 7, 1), 9),
    (dt.datetime(1994, 7, 1), 10), (dt.datetime(1996, 1, 1), 11), (dt.datetime(1997, 7, 1), 12),
    (dt.datetime(1999, 1, 1), 13), (dt.datetime(2006, 1, 1), 14), (dt.datetime(2009, 1, 1), 15),
    (dt.datetime(2012, 7, 1), 16), (dt.datetime(2015, 7, 1), 17), (dt.datetime(2017, 1, 1), 18),
]


def parse_utc(text: str) -> dt.datetime:
    """Parse ``YYYY-MM-DDTHH:MM:SS[.f]Z`` into a naive UTC datetime."""
    stamp = dt.datetime.fromisoformat(text.replace("Z", "+00:00"))
    if stamp.tzinfo is not None:
        stamp = stamp.astimezone(dt.UTC).replace(tzinfo=None)
    return stamp


def leap_seconds(utc: dt.datetime) -> int:
    """GPS - UTC in seconds at a UTC time."""
    n = 0
    for start, value in _LEAPS:
        if utc >= start:
            n = value
    return n


def utc_to_gps(utc: dt.datetime) -> tuple[int, float]:
    """GPS week and seconds of week of a UTC time."""
    seconds = (utc - GPS_EPOCH).total_seconds() + leap_seconds(utc)
    week = int(seconds // SECONDS_PER_WEEK)
    return week, seconds - week * SECONDS_PER_WEEK


def gps_to_utc(week: int, tow: float) -> dt.datetime:
    """UTC time of a GPS week and seconds of week."""
    gps = GPS_EPOCH + dt.timedelta(seconds=week * SECONDS_PER_WEEK + tow)
    return gps - dt.timedelta(seconds=leap_seconds(gps - dt.timedelta(seconds=18)))
