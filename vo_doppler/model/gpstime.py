"""Calendar ↔ GPS time (seconds since 1980-01-06 00:00:00 GPST, no leap seconds).

System time offsets (RINEX 3.05 sec. 6.1): GPS, Galileo (GST), QZSS and NavIC run on GPS time;
BeiDou time BDT = GPST − 14 s; GLONASS time is UTC(SU) + 3 h, RINEX writes it as UTC.
"""

from __future__ import annotations

import numpy as np

SECONDS_PER_DAY = 86400.0
SECONDS_PER_WEEK = 604800.0
BDT_MINUS_GPST_S = -14.0
UNIX_TIME_AT_GPS_EPOCH_S = 315964800.0
"""Unix time of the GPS epoch, 1980-01-06 00:00:00 UTC (GPS − UTC was 0 then)."""
_LEAP_SECOND_DATES = (  # UTC dates from which GPS − UTC grew by one second (IERS Bulletin C)
    (1981, 7),
    (1982, 7),
    (1983, 7),
    (1985, 7),
    (1988, 1),
    (1990, 1),
    (1991, 1),
    (1992, 7),
    (1993, 7),
    (1994, 7),
    (1996, 1),
    (1997, 7),
    (1999, 1),
    (2006, 1),
    (2009, 1),
    (2012, 7),
    (2015, 7),
    (2017, 1),
)
GPS_MINUS_UTC_LATEST_S = float(len(_LEAP_SECOND_DATES))
"""GPS − UTC after the table's last leap second (18 s since 2017-01-01)."""


def days_from_civil(year, month, day) -> np.ndarray:
    """Proleptic Gregorian date to a day count (vectorised integer arithmetic)."""
    y = np.asarray(year, dtype=np.int64) - (np.asarray(month) <= 2)
    m = np.asarray(month, dtype=np.int64)
    d = np.asarray(day, dtype=np.int64)
    era = np.floor_divide(y, 400)
    yoe = y - era * 400
    doy = (153 * (m + np.where(m > 2, -3, 9)) + 2) // 5 + d - 1
    doe = yoe * 365 + yoe // 4 - yoe // 100 + doy
    return era * 146097 + doe + 60


def calendar_to_gps_seconds(year, month, day, hour, minute, second) -> np.ndarray:
    """Calendar date and time of day, read as GPS time, to GPS seconds (float64)."""
    days = days_from_civil(year, month, day) - days_from_civil(1980, 1, 6)
    return (
        days * SECONDS_PER_DAY
        + np.asarray(hour, dtype=float) * 3600.0
        + np.asarray(minute, dtype=float) * 60.0
        + np.asarray(second, dtype=float)
    )


def _leap_table() -> tuple[np.ndarray, np.ndarray]:
    """UTC instants (as calendar seconds) from which GPS − UTC takes each value."""
    years, months = np.array(_LEAP_SECOND_DATES).T
    starts_utc = calendar_to_gps_seconds(years, months, 1, 0, 0, 0)
    return starts_utc, np.arange(1.0, len(years) + 1.0)


def gps_minus_utc(gps_seconds) -> np.ndarray:
    """Leap seconds GPS − UTC in force at the given GPS times (IERS Bulletin C history)."""
    starts_utc, counts = _leap_table()
    index = np.searchsorted(starts_utc + counts, np.asarray(gps_seconds, float), side="right")
    return np.concatenate(([0.0], counts))[index]


def utc_to_gps_seconds(utc_as_gps_seconds, leap_seconds: float | None = None) -> np.ndarray:
    """UTC calendar time (converted as if it were GPS time) to true GPS seconds."""
    t = np.asarray(utc_as_gps_seconds, dtype=float)
    if leap_seconds is not None:
        return t + leap_seconds
    starts_utc, counts = _leap_table()
    return t + np.concatenate(([0.0], counts))[np.searchsorted(starts_utc, t, side="right")]


def unix_to_gps_seconds(unix_seconds) -> np.ndarray:
    """Unix time (UTC, as logs and phones write it) to GPS seconds, leap seconds added."""
    return utc_to_gps_seconds(np.asarray(unix_seconds, dtype=float) - UNIX_TIME_AT_GPS_EPOCH_S)


def time_of_week(gps_seconds) -> tuple[np.ndarray, np.ndarray]:
    """GPS week number and seconds of week."""
    t = np.asarray(gps_seconds, dtype=float)
    week = np.floor(t / SECONDS_PER_WEEK)
    return week.astype(np.int64), t - week * SECONDS_PER_WEEK
