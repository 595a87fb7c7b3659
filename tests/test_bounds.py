"""The bounds of what a road vehicle's sensors can report and of its antenna lever arm."""

from __future__ import annotations

import numpy as np

from vo_doppler.bounds import (
    SPEED,
    YAW_RATE,
    lever_arm_problem,
    too_many_out_of_range,
)


def test_the_bounds_are_closed_and_nan_is_outside():
    values = np.array([-10.0, -10.001, 150.0, 150.001, np.nan, 0.0])
    np.testing.assert_array_equal(SPEED.outside(values), [0, 1, 0, 1, 1, 0])
    np.testing.assert_array_equal(YAW_RATE.outside([-5.0, 5.0, 5.1]), [0, 0, 1])
    assert str(SPEED) == "[-10, 150] m/s"


def test_isolated_means_one_percent_at_most():
    assert not too_many_out_of_range(1, 100)
    assert too_many_out_of_range(2, 100)
    assert too_many_out_of_range(1, 99)
    assert not too_many_out_of_range(0, 0)


def test_a_lever_arm_longer_than_a_vehicle_is_named():
    assert lever_arm_problem((1.2, -0.3, 1.5)) is None
    assert lever_arm_problem((12.0, 16.0)) is None  # exactly 20 m
    problem = lever_arm_problem((1000.0, 0.0, 0.0))
    assert problem is not None and problem.startswith("the lever arm is 1000 m long")


def test_the_gnss_bounds_follow_from_each_other():
    """The Doppler bound is the range-rate bound at the highest GNSS carrier; the travel time
    bound covers every pseudorange bound; the clock-offset bound covers every GPS time."""
    from vo_doppler.bounds import (
        DOPPLER,
        GPS_TIME,
        PSEUDORANGE,
        RANGE_RATE,
        SIGNAL_TRAVEL_TIME,
        TIME_OFFSET,
    )
    from vo_doppler.geo import SPEED_OF_LIGHT

    assert DOPPLER.high == RANGE_RATE.high * 1.61e9 / SPEED_OF_LIGHT
    assert 53_000 < DOPPLER.high < 54_000
    assert SIGNAL_TRAVEL_TIME.low * SPEED_OF_LIGHT <= PSEUDORANGE.low
    assert SIGNAL_TRAVEL_TIME.high * SPEED_OF_LIGHT >= PSEUDORANGE.high
    assert TIME_OFFSET.high == GPS_TIME.high


def test_the_receiver_radius_is_written_only_in_the_bounds_module():
    """ "A position on Earth" is one bound: no other module writes its radii as numbers."""
    import re
    from pathlib import Path

    import vo_doppler
    from vo_doppler.bounds import RECEIVER_RADIUS

    package = Path(vo_doppler.__file__).parent
    radius = re.compile(r"(?<![\w.])[67](?:\.0)?e6(?![\w.])")
    found = [
        f"{path.relative_to(package)}:{number}"
        for path in sorted(package.rglob("*.py"))
        if path.name != "bounds.py"
        for number, line in enumerate(path.read_text().splitlines(), 1)
        if radius.search(line)
    ]
    assert found == []
    assert (RECEIVER_RADIUS.low, RECEIVER_RADIUS.high) == (6.0e6, 7.0e6)
