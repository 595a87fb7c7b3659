"""A Trajectory owns its times and positions: the caller's later edits do not reach it; its
similarity transform, pose matrices, distances and yaw on exact hand-worked cases."""

from __future__ import annotations

import numpy as np
import pytest
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


def test_transformed_applies_scale_rotation_then_translation_to_positions_and_orientations():
    # 90° counter-clockwise about z maps x to y; scale 2; then the translation (10, 20, 30)
    trajectory = Trajectory(
        [0.0, 1.0],
        [[1.0, 0.0, 0.0], [0.0, 3.0, 1.0]],
        Rotation.from_euler("z", [[0.0], [0.25]]),
    )
    quarter = Rotation.from_euler("z", np.pi / 2).as_matrix()
    moved = trajectory.transformed(quarter, [10.0, 20.0, 30.0], scale=2.0)
    np.testing.assert_allclose(moved.positions, [[10.0, 22.0, 30.0], [4.0, 20.0, 32.0]], atol=1e-12)
    np.testing.assert_allclose(moved.yaw(), [np.pi / 2, np.pi / 2 + 0.25], atol=1e-12)
    # a pose's body x axis is turned with it: the first pose now looks along world y
    np.testing.assert_allclose(moved.orientations[0].apply([1.0, 0.0, 0.0]), [0, 1, 0], atol=1e-12)
    np.testing.assert_array_equal(moved.t, trajectory.t)


def test_pose_matrices_hold_rotation_and_translation_and_come_back_unchanged():
    rotations = Rotation.from_euler("ZYX", [[0.3, 0.1, -0.2], [-1.2, 0.0, 0.4]])
    trajectory = Trajectory([5.0, 6.0], [[1.0, 2.0, 3.0], [-4.0, 5.0, -6.0]], rotations)
    matrices = trajectory.matrices
    assert matrices.shape == (2, 4, 4)
    np.testing.assert_allclose(matrices[:, :3, :3], rotations.as_matrix(), atol=1e-15)
    np.testing.assert_array_equal(matrices[:, :3, 3], trajectory.positions)
    np.testing.assert_array_equal(matrices[:, 3], [[0, 0, 0, 1], [0, 0, 0, 1]])
    back = Trajectory.from_matrices(trajectory.t, matrices[:, :3, :])
    np.testing.assert_array_equal(back.positions, trajectory.positions)
    np.testing.assert_allclose(back.orientations.as_matrix(), rotations.as_matrix(), atol=1e-15)


def test_distances_sum_the_steps_between_poses():
    # steps of 5 m (a 3-4-5 triangle), 0 m (standing) and 2 m (straight up)
    positions = [[0.0, 0.0, 0.0], [3.0, 4.0, 0.0], [3.0, 4.0, 0.0], [3.0, 4.0, 2.0]]
    trajectory = Trajectory(np.arange(4.0), positions, Rotation.identity(4))
    np.testing.assert_allclose(trajectory.cumulative_distance(), [0.0, 5.0, 5.0, 7.0])
    assert trajectory.path_length == pytest.approx(7.0, abs=1e-12)


def test_yaw_is_unwrapped_and_interpolated_inside_the_times_only():
    # yaw 170°, -170° (= 190°), -150° (= 210°): unwrapped across ±180°
    yaw = np.radians([170.0, -170.0, -150.0])
    trajectory = Trajectory(
        [0.0, 1.0, 2.0], np.zeros((3, 3)), Rotation.from_euler("z", yaw[:, None])
    )
    np.testing.assert_allclose(np.degrees(trajectory.yaw()), [170.0, 190.0, 210.0], atol=1e-9)
    at = trajectory.yaw_at([0.5, 1.75, -0.1, 2.1])
    np.testing.assert_allclose(np.degrees(at[:2]), [180.0, 205.0], atol=1e-9)
    assert np.isnan(at[2:]).all()


def test_yaw_ignores_pitch_and_roll():
    tilted = Rotation.from_euler("ZYX", [[0.7, 0.2, -0.3]])  # intrinsic: yaw, pitch, roll
    assert Trajectory([0.0], [[0.0, 0.0, 0.0]], tilted).yaw()[0] == pytest.approx(0.7, abs=1e-12)


def test_subset_keeps_the_chosen_poses_and_an_empty_trajectory_has_no_yaw():
    trajectory = Trajectory(
        [0.0, 1.0, 2.0],
        [[0, 0, 0], [1, 0, 0], [2, 0, 0]],
        Rotation.from_euler("z", [[0.0], [1.0], [2.0]]),
    )
    part = trajectory.subset(np.array([True, False, True]))
    np.testing.assert_array_equal(part.t, [0.0, 2.0])
    np.testing.assert_allclose(part.yaw(), [0.0, 2.0], atol=1e-12)
    empty = trajectory.subset(np.zeros(3, dtype=bool))
    assert len(empty) == 0 and empty.yaw().shape == (0,) and empty.matrices.shape == (0, 4, 4)


def test_arrays_of_different_lengths_are_refused_with_their_counts():
    with pytest.raises(ValueError, match="2 times, 3 positions, 2 orientations"):
        Trajectory([0.0, 1.0], np.zeros((3, 3)), Rotation.identity(2))


def test_yaw_in_chunks_is_the_yaw_of_every_matrix_at_once(monkeypatch):
    """Issue 30: the yaw of a 30-min ground truth (180,000 poses) took 12 MiB of matrices at
    once, each time a figure or table compared headings with it; in chunks the values are the
    same to the bit, across chunk edges and wraps, in bounded memory."""
    import tracemalloc

    import vo_doppler.model.trajectory as trajectory_module
    from vo_doppler.geo import yaw_of

    rng = np.random.default_rng(9)
    n = 50_000
    angles = np.column_stack([np.cumsum(rng.normal(0, 0.05, n)), rng.normal(0, 0.02, (n, 2))])
    track = Trajectory(np.arange(n) * 0.01, np.zeros((n, 3)), Rotation.from_euler("zyx", angles))
    whole = np.unwrap(yaw_of(track.orientations.as_matrix()))
    monkeypatch.setattr(trajectory_module, "YAW_CHUNK", 777)
    np.testing.assert_array_equal(track.yaw(), whole)
    assert np.ptp(whole) > 4 * np.pi  # turns past ±π, unwrapped across the chunks
    monkeypatch.setattr(trajectory_module, "YAW_CHUNK", 8192)
    tracemalloc.start()
    try:
        track.yaw()
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 2.5 * 2**20  # 3.4 MiB of matrices alone at once
