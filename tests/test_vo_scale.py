"""Metric scale from a speed signal: exact cases."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.vo.scale import metric_positions, travelled_distance


def poses_along_z(centres: np.ndarray) -> np.ndarray:
    poses = np.tile(np.eye(4), (len(centres), 1, 1))
    poses[:, :3, 3] = centres
    return poses


@settings(max_examples=50, deadline=None)
@given(st.floats(0.1, 40.0), st.floats(0.01, 0.5))
def test_constant_speed_gives_exact_steps(speed, dt):
    t = np.arange(20) * dt
    centres = np.column_stack([np.zeros(20), np.zeros(20), 0.37 * np.arange(20)])
    positions = metric_positions(poses_along_z(centres), t, t, np.full(20, speed))
    np.testing.assert_allclose(np.diff(positions[:, 2]), speed * dt, rtol=1e-12)
    np.testing.assert_allclose(positions[:, :2], 0.0)


def test_trapezoid_distance_and_held_speed_outside_the_record():
    t = np.array([0.0, 1.0, 2.0])
    v = np.array([0.0, 2.0, 2.0])
    np.testing.assert_allclose(
        travelled_distance(t, v, np.array([-1.0, 0.5, 1.0, 2.0, 3.0])),
        [0.0, 0.5, 1.0, 3.0, 5.0],
    )


def test_no_vo_motion_but_moving_follows_the_optical_axis():
    centres = np.array([[0, 0, 0], [0, 0, 1.0], [0, 0, 1.0], [0, 0, 2.0]])
    poses = poses_along_z(centres)
    t = np.arange(4.0)
    positions = metric_positions(poses, t, t, np.full(4, 3.0))
    np.testing.assert_allclose(positions[:, 2], [0.0, 3.0, 6.0, 9.0])
