"""GLONASS navigation in ROS bags: gnss_comm ``GnssGloEphemMsg`` records come back from the
imported sequence's ``gnss/brdc.nav`` field by field (RINEX 3.04 precision, epoch in UTC);
u-blox ``RxmSFRBX`` GLONASS strings, which the import does not decode, are named in a warning
instead of being dropped silently."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers.rosbag_writer import SmallBag, bag_path, ros_ns
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
RAWX = "rcvTOW week leapS numMeas recStat version reserved1 meas"
SFRBX = "gnssId svId reserved0 freqId numWords chn version reserved1 dwrd"


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


def test_glonass_navigation_strings_of_ublox_are_named_not_dropped(tmp_path):
    """RxmSFRBX carries GLONASS strings (gnssId 6) the import does not decode: the warning says
    so, with the count, and what to give instead."""
    with SmallBag(tmp_path / "ublox.bag", "ros1") as bag:
        times = T0 + np.arange(0.0, 3.0, 0.1)
        bag.imu(times, 0.1)
        bag.twist(times, 5.0)
        types = bag.types
        meas = types["ublox_msgs/msg/RxmRAWX_Meas"](**_named(RAWX_MEAS, RAWX_MEAS_VALUES))
        for t in T0 + np.arange(3.0):
            values = (t - WEEK * SECONDS_PER_WEEK, WEEK, 18, 1, 1, 1, np.zeros(2, np.uint8), [meas])
            rawx = types["ublox_msgs/msg/RxmRAWX"](**_named(RAWX, values))
            bag.write("/ublox/rxmraw", "ublox_msgs/msg/RxmRAWX", ros_ns(t), rawx)
            for gnss_id in (6, 6, 6, 2):  # three GLONASS strings, one Galileo page
                values = (gnss_id, 5, 0, 7 + CHANNEL, 4, 1, 2, 0, np.arange(4, dtype=np.uint32))
                sfrbx = types["ublox_msgs/msg/RxmSFRBX"](**_named(SFRBX, values))
                bag.write("/ublox/rxmsfrb", "ublox_msgs/msg/RxmSFRBX", ros_ns(t), sfrbx)
    summary = import_rosbag(tmp_path / "ublox.bag", tmp_path / "seq", RosbagOptions(origin=ORIGIN))
    assert summary.ephemerides == 0
    assert (
        "/ublox/rxmsfrb: navigation data of other systems not decoded (3 Galileo, 9 GLONASS "
        "messages; only GPS LNAV is): those satellites have no ephemeris in the sequence, so "
        "their measurements are not used; add a RINEX navigation file of the day to gnss.nav "
        "for them" in summary.warnings
    )
    assert any("no ephemeris in the bag" in text for text in summary.warnings)
    assert (tmp_path / "seq" / "gnss" / "rover.obs").is_file()
