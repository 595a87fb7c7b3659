"""Unix time to GPS time across the 2017 leap second, and the constants the messages use."""

from __future__ import annotations

import numpy as np

from vo_doppler.model.gpstime import (
    GPS_MINUS_UTC_LATEST_S,
    calendar_to_gps_seconds,
    unix_to_gps_seconds,
)

NEW_YEAR_2017_UNIX = 1483228800.0


def test_unix_time_gets_the_leap_seconds_in_force():
    before, after = unix_to_gps_seconds([NEW_YEAR_2017_UNIX - 1.0, NEW_YEAR_2017_UNIX])
    midnight = calendar_to_gps_seconds(2017, 1, 1, 0, 0, 0)
    assert after == midnight + 18.0
    assert before == midnight - 1.0 + 17.0


def test_the_gps_epoch_is_unix_315964800():
    assert unix_to_gps_seconds(315964800.0) == 0.0
    assert np.shape(unix_to_gps_seconds(np.zeros((2, 3)))) == (2, 3)


def test_the_latest_leap_second_count_is_today_s():
    assert GPS_MINUS_UTC_LATEST_S == 18.0
