"""The starting heading: the circular median of the first seconds' absolute headings, compared
like with like (the heading table's headings, the vehicle origin's course, with the trajectory's
course, as the correction does, not with its yaw). The placement: the vehicle, not its antenna,
where the fixes carried back along the trajectory put it, heights only from good fixes."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.helpers.heading_table import plain_heading_table
from vo_doppler.fusion.antenna_track import PLACEMENT_VERTICAL_SIGMA_M, AntennaTrack
from vo_doppler.fusion.placement import initial_yaw_offset, level_with_yaw, turned_about_start
from vo_doppler.geo import wrap_angle
from vo_doppler.model.heading import HeadingTable
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


def _heading_table(t, yaw_tc, tc_usable, yaw_conv=None, conv_valid=None) -> HeadingTable:
    n = len(t)
    return plain_heading_table(
        t,
        yaw_tc=np.asarray(yaw_tc, dtype=float),
        tc_reliable=np.asarray(tc_usable, dtype=bool),
        n_obs_window=np.full(n, 8),
        n_sat_epoch=np.full(n, 6),
        yaw_conv=np.full(n, np.nan) if yaw_conv is None else np.asarray(yaw_conv, dtype=float),
        conv_valid=np.zeros(n, dtype=bool) if conv_valid is None else np.asarray(conv_valid),
    )


def _turning_trajectory(t: np.ndarray, yaw0: float, rate: float) -> Trajectory:
    yaw = yaw0 + rate * (t - t[0])
    return Trajectory(t, np.zeros((len(t), 3)), Rotation.from_euler("z", yaw[:, None]))


def test_the_initial_heading_is_the_median_of_the_first_seconds_not_the_first_heading():
    t = np.arange(0.0, 20.0, 0.5)
    trajectory = _turning_trajectory(t, yaw0=0.3, rate=0.02)
    truth_offset = np.radians(100.0)
    yaw_tc = 0.3 + 0.02 * t + truth_offset
    yaw_tc[2] += np.radians(40.0)  # the first usable heading is off (a reflected satellite)
    usable = t >= 1.0
    yaw_tc[~usable] = np.nan
    offset = initial_yaw_offset(_heading_table(t, yaw_tc, usable), usable, trajectory)
    assert offset == pytest.approx(truth_offset, abs=1e-12)


def test_the_initial_heading_median_is_circular():
    t = np.arange(5.0)
    trajectory = _turning_trajectory(t, yaw0=0.0, rate=0.0)
    yaw_tc = np.radians([-179.5, 179.0, 179.0, -178.0, 179.0])  # π + (0.5, -1, -1, 2, -1)°
    usable = np.ones(len(t), dtype=bool)
    offset = initial_yaw_offset(_heading_table(t, yaw_tc, usable), usable, trajectory)
    assert np.degrees(wrap_angle(offset - np.pi)) == pytest.approx(-1.0, abs=1e-9)


def test_the_initial_heading_takes_the_first_span_inside_the_trajectory():
    t = np.arange(0.0, 30.0, 1.0)
    trajectory = _turning_trajectory(t[10:], yaw0=0.5, rate=0.0)
    yaw_tc = np.where(t < 10.0, 2.0, 1.5)
    yaw_tc[t >= 16.0] = 2.5  # beyond 5 s from the first heading inside: not used
    usable = np.ones(len(t), dtype=bool)
    offset = initial_yaw_offset(_heading_table(t, yaw_tc, usable), usable, trajectory)
    assert offset == pytest.approx(1.0, abs=1e-12)


def test_without_tight_headings_the_conventional_ones_start_the_trajectory(caplog):
    t = np.arange(0.0, 10.0, 1.0)
    trajectory = _turning_trajectory(t, yaw0=0.25, rate=0.0)
    none = np.zeros(len(t), dtype=bool)
    table = _heading_table(t, np.full(len(t), np.nan), none, np.full(len(t), 1.25), ~none)
    assert initial_yaw_offset(table, none, trajectory) == pytest.approx(1.0, abs=1e-12)
    table = _heading_table(t, np.full(len(t), np.nan), none, np.full(len(t), np.nan), none)
    with caplog.at_level("WARNING"):
        assert initial_yaw_offset(table, none, trajectory) == pytest.approx(-0.25, abs=1e-12)
    assert "starts facing east" in caplog.text


def test_reliable_tight_headings_too_vague_to_correct_still_start_the_trajectory():
    """A canyon from the start: no conventional heading, tight headings reliable but at σ 3.4°
    (not usable); before the unreliable ones, after the conventional ones."""
    t = np.arange(0.0, 10.0, 1.0)
    trajectory = _turning_trajectory(t, yaw0=0.25, rate=0.0)
    none = np.zeros(len(t), dtype=bool)
    yaw_tc = np.where(t < 3.0, 2.0, 0.75)
    table = _heading_table(t, yaw_tc, t >= 3.0)
    table.sigma_tc[:] = np.radians(3.4)
    assert initial_yaw_offset(table, none, trajectory) == pytest.approx(0.5, abs=1e-12)
    with_conventional = _heading_table(t, yaw_tc, t >= 3.0, np.full(len(t), 1.25), ~none)
    assert initial_yaw_offset(with_conventional, none, trajectory) == pytest.approx(1.0, abs=1e-12)


LEVER = (1.5, -0.3, 1.6)


def _placed_straight_drive(t_dr, t_gnss, heading):
    """A straight drive at 15 m/s along ``heading``: dead reckoning from its own origin facing
    x, placed by the exact antenna track; returns the placed trajectory and the truth."""
    direction = np.array([np.cos(heading), np.sin(heading), 0.0])

    def vehicle(t):
        return np.array([100.0, -50.0, 2.0]) + 15.0 * (t - 0.4)[:, None] * direction

    own = Trajectory(
        t_dr, 15.0 * (t_dr - t_dr[0])[:, None] * [1.0, 0.0, 0.0], Rotation.identity(t_dr.size)
    )
    antenna = vehicle(t_gnss) + Rotation.from_euler("z", heading).apply(LEVER)
    placed = level_with_yaw(own, heading, AntennaTrack(t_gnss, antenna), LEVER)
    return placed, vehicle(t_dr)


def test_a_trajectory_is_placed_where_the_vehicle_was_at_its_first_gnss_epoch():
    """The vehicle, not the antenna 1.5 m ahead, 0.3 m right and 1.6 m up, is on the truth at
    every pose: whether the trajectory starts between GNSS epochs or 0.5 s before the first
    (the dead reckoning carries it back), to rounding."""
    t_dr = 0.43 + np.arange(100) * 0.05
    for t_gnss in (np.arange(0.0, 6.0, 0.1), np.arange(0.93, 6.0, 1.0)):
        placed, truth = _placed_straight_drive(t_dr, t_gnss, np.radians(30.0))
        np.testing.assert_allclose(placed.positions, truth, atol=1e-9)
        assert np.degrees(placed.yaw()[0]) == pytest.approx(30.0, abs=1e-9)


def test_fixes_only_seconds_later_are_carried_back_along_the_trajectory():
    """A street canyon: the first valid fixes 20 s after the start (σ 1 m, one of the first
    eleven 100 m off) and a turning drive. The median of the eleven fixes carried back along
    the trajectory: 1.25 σ/√10 = 0.4 m per axis for the ten good ones, the bad one shifting it
    by at most half a gap between them; 1.5 m bounds it. (A track carried back along Doppler
    velocities there drifted by 37 m in the simulated canyon of ``tests/test_run.py``.)"""
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 30.0, 0.05)
    yaw = 0.4 + 0.03 * t
    truth = np.column_stack([np.cumsum(10.0 * np.cos(yaw)), np.cumsum(10.0 * np.sin(yaw))])
    truth = np.column_stack([truth * 0.05 + [200.0, -80.0], np.full(t.size, 3.0)])
    turn = Rotation.from_euler("z", (yaw - 0.4)[:, None])
    own = Trajectory(t, (truth - truth[0]) @ Rotation.from_euler("z", -0.4).as_matrix().T, turn)
    fixes = np.flatnonzero(t >= 20.0)[::10]
    antenna = truth[fixes] + Rotation.from_euler("z", yaw[fixes, None]).apply(LEVER)
    antenna += rng.normal(size=antenna.shape)
    antenna[3] += [100.0, -60.0, 20.0]
    placed = level_with_yaw(own, 0.4, AntennaTrack(t[fixes], antenna), LEVER)
    assert np.all(np.abs(placed.positions[0] - truth[0]) < 1.5)
    np.testing.assert_allclose(placed.positions - placed.positions[0], truth - truth[0], atol=1e-9)


def _canyon_heights(height_sigma):
    """A straight drive 3 m above the origin, placed by fixes exact horizontally whose heights
    are 46 m too high (σ_u 12 m, the sample's street canyon) except the ones of ``height_sigma``
    at most 5 m, which are right."""
    t = np.arange(0.0, 20.0, 0.1)
    truth = np.column_stack([12.0 * t, np.zeros(t.size), np.full(t.size, 3.0)])
    own = Trajectory(t, truth - truth[0], Rotation.identity(t.size))
    fixes = np.arange(0, t.size, 10)
    antenna = truth[fixes] + np.array(LEVER)
    antenna[:, 2] += np.where(height_sigma <= PLACEMENT_VERTICAL_SIGMA_M, 0.0, 46.0)
    track = AntennaTrack(t[fixes], antenna, height_sigma, "test")
    return level_with_yaw(own, 0.0, track, LEVER), truth


def test_heights_come_from_the_fixes_with_a_small_vertical_sigma_or_the_origin():
    """Before: every trajectory 46 m above the road, the height of the canyon's fixes."""
    sigma = np.full(20, 12.0)
    placed, truth = _canyon_heights(sigma)
    np.testing.assert_allclose(placed.positions[:, :2], truth[:, :2], atol=1e-9)
    np.testing.assert_allclose(placed.positions[:, 2], 0.0, atol=1e-9)  # the origin's height
    sigma[[3, 8, 15]] = [2.0, 4.0, 1.5]  # three good heights (beyond the first 5 s: carried)
    placed, truth = _canyon_heights(sigma)
    np.testing.assert_allclose(placed.positions, truth, atol=1e-9)


def test_a_trajectory_without_a_gnss_epoch_is_placed_by_the_nearest_one_with_a_warning(caplog):
    t_dr = np.arange(100) * 0.05
    with caplog.at_level("WARNING"):
        placed, truth = _placed_straight_drive(t_dr, np.array([-3.0, 7.0]), 0.0)
    # the epoch 2.05 s after the end places the end: 30.75 m ahead, driven meanwhile
    np.testing.assert_allclose(placed.positions - truth, np.tile([30.75, 0, 0], (100, 1)))
    assert "antenna position 2.0 s outside it" in caplog.text
    untimed = AntennaTrack(np.zeros(0), np.array([[1.0, 2.0, 3.0]]))
    own = Trajectory(t_dr, np.zeros((100, 3)), Rotation.identity(100))
    np.testing.assert_allclose(level_with_yaw(own, 0.0, untimed).positions[0], [1.0, 2.0, 3.0])
