"""A Trajectory owns its times and positions: the caller's later edits do not reach it."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.model.trajectory import Trajectory


def test_the_trajectory_keeps_its_own_times_and_positions():
    t, positions = np.array([0.0, 1.0]), np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    trajectory = Trajectory(t, positions, Rotation.identity(2))
    t[1], positions[1, 0] = 7.0, 5.0
    np.testing.assert_array_equal(trajectory.t, [0.0, 1.0])
    assert trajectory.path_length == 1.0
    moved = trajectory.transformed(np.eye(3), np.zeros(3))
    moved.positions[0, 2] = 3.0
    assert trajectory.positions[0, 2] == 0.0
    np.testing.assert_array_equal(Rotation.from_euler("z", 0.1).apply(trajectory.positions)[0], 0.0)
