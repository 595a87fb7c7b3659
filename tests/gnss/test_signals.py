"""Carrier wavelengths and BeiDou signals per code, and GPS time conversions."""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.gnss.signals import carrier_frequency, strength_code, wavelengths
from vo_doppler.model.gpstime import (
    calendar_to_gps_seconds,
    gps_minus_utc,
    time_of_week,
    utc_to_gps_seconds,
)
from vo_doppler.model.signals import beidou_signal


def test_glonass_fdma_wavelengths_use_the_channel():
    system = np.array(["R", "R", "G", "E", "C"])
    prn = np.array([1, 2, 5, 4, 23])
    lam = wavelengths(system, prn, "D1C", {1: 1, 2: -4})
    expected = [1602.5625e6, 1599.75e6, 1575.42e6, 1575.42e6, 1575.42e6]
    np.testing.assert_allclose(lam, SPEED_OF_LIGHT / np.array(expected), rtol=1e-15)
    assert np.isnan(wavelengths(np.array(["R"]), np.array([9]), "D1C", {1: 1})[0])
    assert carrier_frequency("R", "D2C", 5) == pytest.approx(1246e6 + 5 * 0.4375e6)


def test_beidou_b1i_band_number_depends_on_version():
    assert carrier_frequency("C", "D1I", rinex_version=3.02) == pytest.approx(1561.098e6)
    assert carrier_frequency("C", "D1P", rinex_version=3.04) == pytest.approx(1575.42e6)
    assert carrier_frequency("C", "D2I", rinex_version=3.04) == pytest.approx(1561.098e6)
    assert carrier_frequency("E", "D7Q") == pytest.approx(1207.14e6)
    assert carrier_frequency("G", "D9X") is None
    assert strength_code("D5Q") == "S5Q"
    assert strength_code("D1") == "S1"


@pytest.mark.parametrize(
    ("code", "version", "signal"),
    [
        ("C1I", 3.02, "B1I"),
        ("D1X", 3.02, "B1I"),
        ("C2I", 3.01, "B1I"),
        ("C2I", 3.03, "B1I"),
        ("C2X", 3.04, "B1I"),
        ("C1P", 3.04, "B1C"),
        ("C1X", 3.04, "B1C"),
        ("C1Z", 3.05, "B1A"),
        ("C5P", 3.04, "B2a"),
        ("C7I", 3.02, "B2I"),
        ("C7Z", 3.04, "B2b"),
        ("C8X", 3.04, "B2a+b"),
        ("C6I", 3.02, "B3I"),
        ("C6D", 3.05, "B3A"),
        ("C9X", 3.04, None),
    ],
)
def test_beidou_signal_of_a_code_in_its_rinex_version(code, version, signal):
    assert beidou_signal(code, version) == signal


def test_gps_time_epochs_and_leap_seconds():
    assert calendar_to_gps_seconds(1980, 1, 6, 0, 0, 0) == 0.0
    week, tow = time_of_week(calendar_to_gps_seconds(2024, 6, 24, 8, 20, 0.0))
    assert (int(week), float(tow)) == (2320, 116400.0)
    assert gps_minus_utc(calendar_to_gps_seconds(2010, 1, 6, 0, 0, 0)) == 15.0
    assert gps_minus_utc(calendar_to_gps_seconds(2024, 6, 24, 0, 0, 0)) == 18.0
    # the 2017-01-01 leap second: UTC midnight is GPS 00:00:18
    t = calendar_to_gps_seconds(2017, 1, 1, 0, 0, 0)
    assert utc_to_gps_seconds(t) == t + 18.0


@given(
    st.dates(
        min_value=np.datetime64("1980-01-06").item(), max_value=np.datetime64("2100-01-01").item()
    )
)
def test_calendar_days_match_numpy(day):
    expected = (np.datetime64(day) - np.datetime64("1980-01-06")).astype(int) * 86400.0
    assert calendar_to_gps_seconds(day.year, day.month, day.day, 0, 0, 0) == expected


# GPS − UTC from each UTC instant on (IERS Bulletin C; IS-GPS-200 sec. 20.3.3.5.2.4 ΔtLS).
GPS_MINUS_UTC_FROM = (
    ("1981-07-01", 1),
    ("1982-07-01", 2),
    ("1983-07-01", 3),
    ("1985-07-01", 4),
    ("1988-01-01", 5),
    ("1990-01-01", 6),
    ("1991-01-01", 7),
    ("1992-07-01", 8),
    ("1993-07-01", 9),
    ("1994-07-01", 10),
    ("1996-01-01", 11),
    ("1997-07-01", 12),
    ("1999-01-01", 13),
    ("2006-01-01", 14),
    ("2009-01-01", 15),
    ("2012-07-01", 16),
    ("2015-07-01", 17),
    ("2017-01-01", 18),
)
GPS_EPOCH = np.datetime64("1980-01-06T00:00:00", "us")


def _utc_as_gps(moment: str | dt.datetime) -> float:
    """UTC calendar time counted as if it had no leap seconds (numpy, not gpstime)."""
    return float((np.datetime64(moment, "us") - GPS_EPOCH) / np.timedelta64(1, "s"))


@pytest.mark.parametrize(("day", "offset"), GPS_MINUS_UTC_FROM)
@pytest.mark.parametrize("seconds_after", [-1.0, -0.001, 0.0, 0.5, 1.0, 10.0, 17.0, 18.5, 86400.0])
def test_utc_to_gps_at_each_leap_second(day, offset, seconds_after):
    """Before the leap the old offset holds, from UTC midnight on the new one, including the
    first ΔtLS seconds after it (looking the UTC time up among GPS-time boundaries got those
    one second short)."""
    u = _utc_as_gps(day) + seconds_after
    expected = offset - 1 if seconds_after < 0 else offset
    g = utc_to_gps_seconds(u)
    assert g - u == expected
    assert gps_minus_utc(g) == expected


@pytest.mark.parametrize(("day", "offset"), GPS_MINUS_UTC_FROM)
def test_gps_minus_utc_across_the_inserted_second(day, offset):
    """GPS side: UTC 23:59:59 is GPS midnight + offset − 1 − 1; the inserted 23:59:60 spans
    GPS [midnight + offset − 1, midnight + offset) and still has the old offset."""
    midnight = _utc_as_gps(day)
    assert gps_minus_utc(midnight + offset - 2.0) == offset - 1  # 23:59:59 UTC
    assert gps_minus_utc(midnight + offset - 1.0) == offset - 1  # 23:59:60 UTC
    assert gps_minus_utc(midnight + offset - 1e-6) == offset - 1
    assert gps_minus_utc(midnight + offset) == offset  # 00:00:00 UTC
    # The two UTC seconds around midnight are two GPS seconds apart: 23:59:60 lies between.
    assert utc_to_gps_seconds(midnight) - utc_to_gps_seconds(midnight - 1.0) == 2.0


def test_2016_leap_second_known_values():
    """GPS week 1930 began on Sunday 2017-01-01 00:00:00 GPS, which was 2016-12-31 23:59:43 UTC
    (GPS − UTC = 17 s): 23:59:59 UTC is 16 s into the week and UTC midnight, after the
    inserted 23:59:60, 18 s into it."""
    before = utc_to_gps_seconds(_utc_as_gps("2016-12-31T23:59:59"))
    after = utc_to_gps_seconds(_utc_as_gps("2017-01-01T00:00:00"))
    week, tow = time_of_week(np.array([before, after]))
    assert week.tolist() == [1930, 1930]
    assert tow.tolist() == [16.0, 18.0]
    assert utc_to_gps_seconds(_utc_as_gps("2016-12-31T23:59:43")) == 1930 * 604800.0


def test_leap_second_table_matches_the_system_leap_seconds_list():
    """Cross-check with the IERS/NIST leap-seconds.list shipped by tzdata (TAI − UTC from NTP
    seconds since 1900); GPS − UTC = TAI − UTC − 19 s."""
    path = Path("/usr/share/zoneinfo/leap-seconds.list")
    if not path.is_file():
        pytest.skip("no tzdata leap-seconds.list on this machine")
    ntp_epoch = np.datetime64("1900-01-01T00:00:00", "us")
    entries = []
    for line in path.read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            ntp, tai_minus_utc = line.split()[:2]
            entries.append((ntp_epoch + np.timedelta64(int(ntp), "s"), int(tai_minus_utc) - 19))
    after_gps_epoch = [(day, offset) for day, offset in entries if day > GPS_EPOCH]
    assert len(after_gps_epoch) >= 18
    for day, offset in after_gps_epoch:
        u = _utc_as_gps(day)
        assert utc_to_gps_seconds(u) - u == offset
        assert utc_to_gps_seconds(u - 1.0) - (u - 1.0) == offset - 1


@given(
    st.datetimes(min_value=dt.datetime(1980, 1, 6), max_value=dt.datetime(2030, 12, 31, 23, 59, 59))
)
def test_utc_gps_round_trip(moment):
    """Any UTC time (a calendar UTC time never names the inserted 23:59:60) converts to GPS
    with the offset the table gives, and back."""
    u = _utc_as_gps(moment)
    offset = sum(moment >= dt.datetime.fromisoformat(day) for day, _ in GPS_MINUS_UTC_FROM)
    fields = (moment.year, moment.month, moment.day, moment.hour, moment.minute)
    assert calendar_to_gps_seconds(*fields, moment.second + moment.microsecond * 1e-6) == (
        pytest.approx(u, abs=1e-6)
    )
    g = utc_to_gps_seconds(u)
    assert g - u == pytest.approx(offset, abs=1e-6)
    assert gps_minus_utc(g) == offset
    assert g - gps_minus_utc(g) == pytest.approx(u, abs=1e-6)
