"""GLONASS navigation in ROS bags: gnss_comm ``GnssGloEphemMsg`` records come back from the
imported sequence's ``gnss/brdc.nav`` field by field (RINEX 3.04 precision, epoch in UTC);
u-blox ``RxmSFRBX`` GLONASS strings come back the same way, at the values the strings carry."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers.glonass_strings import (
    encode_strings,
    example_at,
    quantised,
    sfrbx_words,
    tb_quarter_hour,
)
from tests.helpers.rosbag_writer import SmallBag, bag_path, ros_ns, ublox_rawx, ublox_sfrbx
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.rinex_write import gps_calendar, rounded_nav_value
from vo_doppler.io.rosbag_gnss import satellite_number
from vo_doppler.io.rosbag_import import RosbagOptions, import_rosbag
from vo_doppler.model.gpstime import SECONDS_PER_WEEK

ORIGIN = (22.3, 114.17, 10.0)
WEEK = 2300
TOE_TOW = 3 * 86400.0 + 10 * 3600.0 + 45 * 60.0  # tb on a quarter hour (GPS time)
T0 = WEEK * SECONDS_PER_WEEK + TOE_TOW + 12.0
CHANNEL = -3
EPHEMERIDES = {  # slot → (position m, velocity m/s, acceleration m/s², tau_n s, gamma, age)
    5: (
        (12_345_678.125, -15_432_109.875, 16_001_234.5),
        (1500.3217, 2100.7654, -1800.2231),
        (1.8626451e-06, -9.3132257e-07, 2.7939677e-06),
        1.2345678e-05,
        9.094947e-13,
        2,
    ),
    12: (
        (-20_100_200.5, 5_300_400.25, 14_200_300.0),
        (-900.125, -2800.5, 1200.75),
        (0.0, 1.8626451e-06, -1.8626451e-06),
        -3.4567e-05,
        -1.818989e-12,
        0,
    ),
}


RAWX_MEAS = "prMes cpMes doMes gnssId svId sigId freqId locktime cno prStdev cpStdev doStdev"
RAWX_MEAS += " trkStat reserved3"
RAWX_MEAS_VALUES = (2.1e7, 0.0, -1000.5, 6, 5, 0, 7 + CHANNEL, 1000, 40, 3, 0, 4, 1, 0)
"""An R05 measurement on channel −3 (ublox_msgs' ROS 1 field names)."""


def _named(names: str, values) -> dict:
    return dict(zip(names.split(), values, strict=True))


def _time(bag: SmallBag, t: float):
    week = int(t // SECONDS_PER_WEEK)
    return bag.types["gnss_comm/msg/GnssTimeMsg"](week=week, tow=t - week * SECONDS_PER_WEEK)


def write_glonass_bag(path, flavour: str):
    """IMU, speed, 5 gnss_comm epochs of G07 and R05 (channel −3) and two GLONASS ephemerides
    on their own topic (GVINS publishes them apart from the Keplerian ones)."""
    with SmallBag(path, flavour) as bag:
        times = T0 + np.arange(0.0, 5.0, 0.1)
        bag.imu(times, 0.1)
        bag.twist(times, 5.0)
        types = bag.types
        for t in T0 + np.arange(5.0):
            meas = []
            for sat, freq in ((7, 1575.42e6), (satellite_number("R", 5), 1602e6 - 3 * 0.5625e6)):
                one = np.ones(1)
                meas.append(
                    types["gnss_comm/msg/GnssObsMsg"](
                        time=_time(bag, t),
                        sat=sat,
                        freqs=np.array([freq]),
                        CN0=40.0 * one,
                        LLI=np.zeros(1, np.uint8),
                        code=np.ones(1, np.uint8),
                        psr=(2.1e7 + sat) * one,
                        psr_std=one,
                        cp=np.zeros(1),
                        cp_std=np.zeros(1),
                        dopp=(-1000.5 + sat) * one,
                        dopp_std=np.zeros(1),
                        status=np.ones(1, np.uint8),
                    )
                )
            message = types["gnss_comm/msg/GnssMeasMsg"](meas=meas)
            bag.write("/gnss/meas", "gnss_comm/msg/GnssMeasMsg", ros_ns(t), message)
        toe = WEEK * SECONDS_PER_WEEK + TOE_TOW
        for slot, (pos, vel, acc, tau_n, gamma, age) in EPHEMERIDES.items():
            fields = {
                "sat": satellite_number("R", slot),
                "ttr": _time(bag, toe - 30.0),
                "toe": _time(bag, toe),
                "freqo": CHANNEL if slot == 5 else 4,
                "iode": 33,
                "health": 0,
                "age": age,
                "ura": 2.5,
                "tau_n": tau_n,
                "gamma": gamma,
                "delta_tau_n": 2.8e-09,
            }
            for axis, p, v, a in zip("xyz", pos, vel, acc, strict=True):
                fields |= {f"pos_{axis}": p, f"vel_{axis}": v, f"acc_{axis}": a}
            message = types["gnss_comm/msg/GnssGloEphemMsg"](**fields)
            bag.write("/gnss/glo_ephem", "gnss_comm/msg/GnssGloEphemMsg", ros_ns(T0), message)
    return path


@pytest.mark.parametrize("flavour", ["ros1", "mcap"])
def test_glonass_ephemerides_come_back_from_the_navigation_file(tmp_path, flavour):
    bag = write_glonass_bag(bag_path(tmp_path, flavour, "glo"), flavour)
    summary = import_rosbag(bag, tmp_path / "seq", RosbagOptions(origin=ORIGIN))
    assert summary.ephemerides == 2 and summary.gnss_epochs == 5
    assert summary.topics["ephemeris"] == "['/gnss/glo_ephem']"
    nav = read_nav(tmp_path / "seq" / "gnss" / "brdc.nav")
    glonass = nav.glonass
    assert len(nav.kepler) == 0 and glonass.prn.tolist() == [5, 12]
    toe = WEEK * SECONDS_PER_WEEK + TOE_TOW
    np.testing.assert_array_equal(glonass.toc, [toe, toe])
    leap = 18.0
    for k, (pos, vel, acc, tau_n, gamma, age) in enumerate(EPHEMERIDES.values()):
        for names, values in (("x y z", pos), ("vx vy vz", vel), ("ax ay az", acc)):
            for name, value in zip(names.split(), values, strict=True):
                assert glonass[name][k] == rounded_nav_value(value / 1000.0) * 1000.0, name
        assert glonass["minus_tau_n"][k] == rounded_nav_value(-tau_n)
        assert glonass["gamma_n"][k] == rounded_nav_value(gamma)
        assert glonass["frame_time"][k] == (toe - 30.0 - leap) % SECONDS_PER_WEEK
        assert glonass["age"][k] == age and glonass["health"][k] == 0
    assert glonass["channel"].tolist() == [CHANNEL, 4]
    year, month, day, hour, minute, second = gps_calendar(toe - leap)  # tb on UTC
    text = (tmp_path / "seq" / "gnss" / "brdc.nav").read_text()
    assert f"R05 {year} {month:02d} {day:02d} {hour:02d} {minute:02d} {round(second):02d}" in text
    assert read_obs(tmp_path / "seq" / "gnss" / "rover.obs").header.glonass_channels == {5: CHANNEL}


@pytest.mark.parametrize("flavour", ["ros1", "mcap"])
def test_glonass_strings_of_ublox_come_back_from_the_navigation_file(tmp_path, flavour):
    """RxmSFRBX GLONASS strings 1–4 of R05 (channel −3) and R12 (channel 4), encoded from the
    records above (tb on a quarter hour of UTC, the frame 15 min before): the navigation file
    holds them at the values the strings carry, to its D19.12 digits; a Galileo message that is
    no I/NAV page is refused, counted and named by its message index in a warning."""
    toc = tb_quarter_hour(T0)
    channels = {5: CHANNEL, 12: 4}
    sent = {}
    path = bag_path(tmp_path, flavour, "ublox")
    with SmallBag(path, flavour) as bag:
        times = T0 + np.arange(0.0, 3.0, 0.1)
        bag.imu(times, 0.1)
        bag.twist(times, 5.0)
        for t in T0 + np.arange(3.0):
            ublox_rawx(bag, t, [_named(RAWX_MEAS, RAWX_MEAS_VALUES)])
            ublox_sfrbx(bag, t, 2, 11, 0, np.arange(8))
        for slot, (pos, vel, acc, tau_n, gamma, age) in EPHEMERIDES.items():
            params = example_at(toc) | {"minus_tau_n": -tau_n, "gamma_n": gamma, "age": age}
            params |= dict(zip(("x", "y", "z", "vx", "vy", "vz"), (*pos, *vel), strict=True))
            params |= dict(zip(("ax", "ay", "az"), acc, strict=True))
            params["channel"] = channels[slot]
            sent[slot] = quantised(params)
            for n, string in enumerate(encode_strings(slot, toc, params)):
                words = sfrbx_words(string)
                ublox_sfrbx(bag, T0 + 0.5 + n, 6, slot, channels[slot] + 7, words)
    summary = import_rosbag(path, tmp_path / "seq", RosbagOptions(origin=ORIGIN))
    assert summary.ephemerides == 2
    glonass = read_nav(tmp_path / "seq" / "gnss" / "brdc.nav").glonass
    assert glonass.prn.tolist() == [5, 12] and glonass.toc.tolist() == [toc, toc]
    for k, slot in enumerate((5, 12)):
        for name in ("x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"):
            assert glonass[name][k] == rounded_nav_value(sent[slot][name] / 1000.0) * 1000.0
        for name in ("minus_tau_n", "gamma_n", "frame_time", "health", "channel", "age"):
            assert glonass[name][k] == rounded_nav_value(sent[slot][name]), name
    assert glonass["frame_time"][0] == (toc - 18.0 - 900.0) % SECONDS_PER_WEEK
    assert (
        "/ublox/rxmsfrb, message 0: 3 Galileo pages or ephemerides refused (the first: E11, page "
        "parts not even then odd)" in summary.warnings
    )
    assert read_obs(tmp_path / "seq" / "gnss" / "rover.obs").header.glonass_channels == {5: CHANNEL}
