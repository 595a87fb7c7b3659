"""Carrier frequencies by RINEX band: fixed bands, GLONASS FDMA channels, BeiDou's renumbered
B1I and what cannot be known."""

from __future__ import annotations

import pytest

from vo_doppler.model.signals import carrier_frequency


@pytest.mark.parametrize(
    ("system", "code", "hz"),
    [
        ("G", "D1C", 1575.42e6),
        ("G", "D2", 1227.60e6),  # RINEX 2 code: the band is its second character
        ("G", "D5Q", 1176.45e6),
        ("E", "D7Q", 1207.14e6),
        ("E", "D8Q", 1191.795e6),
        ("C", "D2I", 1561.098e6),
        ("C", "D6I", 1268.52e6),
        ("J", "D6Z", 1278.75e6),
        ("I", "D9A", 2492.028e6),
        ("R", "D3Q", 1202.025e6),  # GLONASS CDMA: no channel needed
    ],
)
def test_fixed_bands_have_their_carrier(system, code, hz):
    assert carrier_frequency(system, code) == hz


def test_glonass_fdma_bands_follow_the_frequency_channel():
    assert carrier_frequency("R", "D1C", glonass_channel=-7) == 1602.0e6 - 7 * 0.5625e6
    assert carrier_frequency("R", "D1C", glonass_channel=6) == 1602.0e6 + 6 * 0.5625e6
    assert carrier_frequency("R", "D2P", glonass_channel=0) == 1246.0e6
    assert carrier_frequency("R", "D2P", glonass_channel=-1) == 1246.0e6 - 0.4375e6
    assert carrier_frequency("R", "D1C") is None  # channel unknown


def test_beidou_band_1_is_b1i_before_rinex_3_03_and_b1c_from_it():
    assert carrier_frequency("C", "D1I", rinex_version=3.02) == 1561.098e6
    assert carrier_frequency("C", "D1P", rinex_version=3.03) == 1575.42e6
    assert carrier_frequency("C", "D1P") == 1575.42e6
    assert carrier_frequency("G", "D1C", rinex_version=3.02) == 1575.42e6  # BeiDou only


def test_unknown_systems_and_bands_have_no_frequency():
    assert carrier_frequency("X", "D1C") is None
    assert carrier_frequency("G", "D9X") is None
    assert carrier_frequency("S", "D2C") is None
