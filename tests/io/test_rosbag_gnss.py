"""The GNSS of ROS bags, its pure parts: gnss_comm's (RTKLIB's) satellite numbers both ways,
bands and GLONASS channels from carrier frequencies and back (the bag readers end to end are in
tests/io/test_rosbag_import.py and test_rosbag_glonass.py)."""

from __future__ import annotations

import math

import pytest

from vo_doppler.io.rosbag_gnss import band_of, carrier_hz, satellite, satellite_number


@pytest.mark.parametrize(
    ("number", "system", "prn"),
    [
        (1, "G", 1),
        (32, "G", 32),
        (33, "R", 1),
        (59, "R", 27),
        (60, "E", 1),
        (97, "E", 38),
        (98, "C", 1),
        (160, "C", 63),
    ],
)
def test_rtklib_satellite_numbers_both_ways(number, system, prn):
    assert satellite(number) == (system, prn)
    assert satellite_number(system, prn) == number


def test_numbers_outside_every_system():
    assert satellite(0) is None and satellite(161) is None
    with pytest.raises(ValueError, match="G33 has no gnss_comm satellite number"):
        satellite_number("G", 33)
    with pytest.raises(ValueError, match="J01 has no gnss_comm satellite number"):
        satellite_number("J", 1)


def test_bands_from_carrier_frequencies():
    assert band_of("G", 1575.42e6) == ("1", None)
    assert band_of("G", 1575.42e6 + 5e4) == ("1", None)  # within 100 kHz
    assert band_of("G", 1575.42e6 + 2e5) is None
    assert band_of("E", 1176.45e6) == ("5", None)
    assert band_of("C", 1561.098e6) == ("2", None)
    assert band_of("X", 1575.42e6) is None


def test_glonass_channels_from_frequencies_and_back():
    for channel in (-7, 0, 6):
        g1 = carrier_hz("R", "1", channel)
        assert g1 == 1602.0e6 + channel * 0.5625e6
        assert band_of("R", g1) == ("1", channel)
        assert band_of("R", carrier_hz("R", "2", channel)) == ("2", channel)
    assert band_of("R", 1602.0e6 + 7 * 0.5625e6) is None  # channel 7 is none
    assert band_of("R", 1602.0e6 + 0.3e6) is None  # between two channels
    assert math.isnan(carrier_hz("R", "1")) and math.isnan(carrier_hz("R", "3", 0))
    assert carrier_hz("G", "2") == 1227.60e6 and math.isnan(carrier_hz("G", "7"))
