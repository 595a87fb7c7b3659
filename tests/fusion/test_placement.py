"""The starting heading compares like with like: the heading table's headings (the vehicle
origin's course) with the trajectory's course, as the correction does, not with its yaw."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.helpers.heading_table import plain_heading_table
from vo_doppler.fusion.placement import initial_yaw_offset, turned_about_start
from vo_doppler.geo import wrap_angle
from vo_doppler.model.trajectory import Trajectory

SPEED_MPS = 5.0
YAW_RATE = 0.5
AHEAD_M = 1.35
"""The vehicle origin under the camera, 1.35 m ahead of the rear axle: in a turn at 0.5 rad/s
and 5 m/s it slips sideways by atan(ω·d / v) = 7.7° (issue 30's sharp turn)."""


def _sharp_turn(t0: float = 0.0):
    """20-Hz poses of an origin ahead of the rear axle on a 10-m circle, their true course
    (1 Hz, what the heading stage gives) and the same trajectory in the VO's own frame
    (turned by −1 rad about its start)."""
    t = t0 + np.arange(0.0, 8.0, 0.05)
    yaw = 0.3 + YAW_RATE * (t - t0)
    radius = SPEED_MPS / YAW_RATE
    axle = radius * np.column_stack([np.sin(yaw), -np.cos(yaw), np.zeros(t.size)])
    origin = axle + AHEAD_M * np.column_stack([np.cos(yaw), np.sin(yaw), np.zeros(t.size)])
    truth = Trajectory(t, origin, Rotation.from_euler("z", yaw[:, None]))
    slip = np.arctan2(YAW_RATE * AHEAD_M, SPEED_MPS)
    t_gnss = t0 + np.arange(0.5, 7.6, 1.0)
    course = 0.3 + YAW_RATE * (t_gnss - t0) + slip
    own = turned_about_start(truth, -1.0)
    return own, t_gnss, course, slip


@pytest.mark.parametrize("t0", [0.0, 1.0e9])
def test_the_start_compares_the_course_with_the_trajectory_course(t0):
    own, t_gnss, course, slip = _sharp_turn(t0)
    assert np.degrees(slip) == pytest.approx(7.7, abs=0.05)
    usable = np.ones(t_gnss.size, dtype=bool)
    table = plain_heading_table(t_gnss, yaw_tc=course, yaw_conv=course)
    offset = initial_yaw_offset(table, usable, own)
    # chords of 0.5 m on a circle: the course at their middle is exact; the headings are
    # interpolated linearly between 1-Hz epochs along the turn, also exact here
    assert np.degrees(wrap_angle(offset - 1.0)) == pytest.approx(0.0, abs=0.05)
    # before: the yaw, 7.7° off in the turn
    yaw_start = initial_yaw_offset(table, usable, own, reference="orientation")
    assert np.degrees(wrap_angle(yaw_start - 1.0 - slip)) == pytest.approx(0.0, abs=0.05)


def test_a_trajectory_that_does_not_move_starts_from_its_yaw():
    t = np.arange(0.0, 5.0, 0.1)
    still = Trajectory(
        t, np.zeros((t.size, 3)), Rotation.from_euler("z", np.full((t.size, 1), 0.2))
    )
    table = plain_heading_table(np.arange(0.0, 5.0), yaw_tc=np.full(5, 1.2))
    offset = initial_yaw_offset(table, np.ones(5, dtype=bool), still)
    assert offset == pytest.approx(1.0, abs=1e-12)
