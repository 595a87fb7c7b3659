"""Broadcast atmosphere models on hand-worked cases: Saastamoinen's zenith delays of a standard
atmosphere and their 1/cos z mapping, the Klobuchar model's night floor, its cosine at the
afternoon peak and its frequency scaling (tests/gnss/test_spp.py compares both with RTKLIB)."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.geo import SPEED_OF_LIGHT as C
from vo_doppler.gnss.atmosphere import L1_HZ, klobuchar_delay, troposphere_delay

LAT45 = np.radians(45.0)


def test_the_zenith_delay_at_sea_level_is_the_standard_atmospheres():
    # hydrostatic: 2.2768 mm/hPa · 1013.25 hPa (at 45° latitude the gravity term is 1);
    # wet at 15 °C and 70 % humidity: 12.01 hPa of water vapour, 0.1205 m
    zenith = troposphere_delay(LAT45, 0.0, np.array([np.pi / 2]))[0]
    assert zenith == pytest.approx(0.0022768 * 1013.25 + 0.1205, abs=1e-4)


def test_the_slant_delay_maps_with_one_over_cos_z_down_to_3_degrees():
    elevation = np.radians([90.0, 30.0, 10.0, 3.0, 1.0, -5.0])
    delay = troposphere_delay(LAT45, 0.0, elevation)
    np.testing.assert_allclose(delay[1:4] * np.sin(elevation[1:4]), delay[0], rtol=1e-12)
    np.testing.assert_array_equal(delay[4:], delay[3])  # below 3°: as at 3°


def test_less_air_above_a_higher_receiver_and_a_little_more_weight_near_the_poles():
    zenith = np.array([np.pi / 2])
    sea, high = troposphere_delay(LAT45, 0.0, zenith)[0], troposphere_delay(LAT45, 2000.0, zenith)
    # 794.9 hPa, 2 °C and 4.96 hPa of vapour at 2 km: 1.8109 m hydrostatic and 0.0520 m wet
    assert high[0] == pytest.approx(1.8109 + 0.0520, abs=1e-4)
    assert high[0] < sea
    assert troposphere_delay(np.radians(80.0), 0.0, zenith)[0] < sea  # less gravity term
    # heights outside 0-10 km are held at the bound
    assert troposphere_delay(LAT45, -50.0, zenith)[0] == sea


# α0 = 10 ns and a 20-h period, no latitude dependence: the amplitude and period are exact
COEFFICIENTS = np.array([10e-9, 0.0, 0.0, 0.0, 72000.0, 0.0, 0.0, 0.0])
ZENITH_SLANT = 1.0 + 16.0 * (0.53 - 0.5) ** 3
WEEK_START = 2300 * 604800.0


def _zenith_delay(tow: float, coefficients=COEFFICIENTS, frequency=L1_HZ) -> float:
    # at the zenith with azimuth 0 and longitude 0 the pierce point's local time is the TOW
    return klobuchar_delay(
        coefficients, 0.3, 0.0, np.array([np.pi / 2]), np.array([0.0]), WEEK_START + tow, frequency
    )[0]


def test_the_delay_peaks_at_14_h_local_time():
    assert _zenith_delay(50400.0) == pytest.approx(C * ZENITH_SLANT * (5e-9 + 10e-9), rel=1e-12)


def test_the_delay_follows_the_cosines_series_in_the_day():
    x = 1.0  # phase 1 rad from the peak: 72000 / 2π s later
    expected = C * ZENITH_SLANT * (5e-9 + 10e-9 * (1.0 - x**2 / 2.0 + x**4 / 24.0))
    assert _zenith_delay(50400.0 + 72000.0 / (2.0 * np.pi)) == pytest.approx(expected, rel=1e-9)


def test_at_night_only_the_5_ns_floor_remains():
    night = C * ZENITH_SLANT * 5e-9
    assert _zenith_delay(50400.0 + 72000.0 / 4.0 + 1.0) == pytest.approx(night, rel=1e-12)
    assert _zenith_delay(3600.0) == pytest.approx(night, rel=1e-12)
    # a period shorter than 72000 s is raised to it; a negative amplitude is zero
    short = COEFFICIENTS.copy()
    short[4] = 1000.0
    assert _zenith_delay(50400.0, short) == _zenith_delay(50400.0)
    negative = COEFFICIENTS.copy()
    negative[0] = -10e-9
    assert _zenith_delay(50400.0, negative) == pytest.approx(C * ZENITH_SLANT * 5e-9, rel=1e-12)


def test_other_carriers_scale_with_the_inverse_square_of_the_frequency():
    l5 = 1176.45e6
    assert _zenith_delay(50400.0, frequency=l5) == pytest.approx(
        _zenith_delay(50400.0) * (L1_HZ / l5) ** 2, rel=1e-12
    )


def test_low_satellites_see_a_longer_slant():
    low = klobuchar_delay(
        COEFFICIENTS, 0.3, 0.0, np.radians([10.0]), np.array([0.0]), WEEK_START + 3600.0
    )[0]
    e = 10.0 / 180.0  # semicircles
    assert low == pytest.approx(C * (1.0 + 16.0 * (0.53 - e) ** 3) * 5e-9, rel=1e-12)
