"""Carrier wavelengths per signal and GPS time conversions."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.gnss.gpstime import (
    calendar_to_gps_seconds,
    gps_minus_utc,
    time_of_week,
    utc_to_gps_seconds,
)
from vo_doppler.gnss.signals import carrier_frequency, strength_code, wavelengths


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
