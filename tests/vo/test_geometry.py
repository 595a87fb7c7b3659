"""VO geometry on exact synthetic views: rigid inverses and camera centres, projection,
parallax, DLT triangulation and its validity checks, the essential-matrix two-view start and
PnP with outliers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from vo_doppler.vo.geometry import (
    camera_center,
    depths,
    invert_pose,
    make_pose,
    parallax,
    project,
    solve_pnp,
    transform_points,
    triangulate,
    two_view_geometry,
)

K = np.array([[400.0, 0.0, 320.0], [0.0, 400.0, 240.0], [0.0, 0.0, 1.0]])
R_BA = Rotation.from_euler("xyz", [0.02, -0.05, 0.01]).as_matrix()
T_B = make_pose(R_BA, [-1.0, 0.05, 0.1])  # world (= camera a) → camera b


def _scene(n: int = 120, seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(-6, 6, n), rng.uniform(-3, 3, n), rng.uniform(8, 30, n)])


def test_inverse_poses_and_camera_centres():
    poses = np.stack([T_B, make_pose(Rotation.from_euler("z", 1.0).as_matrix(), [3, 4, 5])])
    np.testing.assert_allclose(
        invert_pose(poses) @ poses, np.tile(np.eye(4), (2, 1, 1)), atol=1e-14
    )
    # the camera centre is where the camera frame's origin lies in the world
    centre = camera_center(T_B).ravel()
    np.testing.assert_allclose(transform_points(T_B, centre[None]), [[0, 0, 0]], atol=1e-14)
    np.testing.assert_allclose(centre, invert_pose(T_B)[:3, 3], atol=1e-14)


def test_projection_and_depth_of_a_point():
    points = np.array([[0.0, 0.0, 10.0], [2.0, -1.0, 5.0]])
    np.testing.assert_allclose(project(K, np.eye(4), points), [[320, 240], [480, 160]])
    shifted = make_pose(np.eye(3), [0.0, 0.0, -5.0])  # the camera 5 m further forward
    np.testing.assert_allclose(depths(shifted, points), [5.0, 0.0])


def test_parallax_is_the_angle_between_the_two_rays():
    points = np.array([[1.0, 0.0, 1.0], [0.0, 0.0, 1000.0]])
    angles = parallax(np.zeros(3), np.array([2.0, 0.0, 0.0]), points)
    assert angles[0] == pytest.approx(np.pi / 2, abs=1e-12)
    assert angles[1] == pytest.approx(np.arctan(2.0 / 1000.0), rel=1e-6)


def test_triangulation_recovers_points_and_flags_the_unusable():
    points = _scene(20)
    points[0] = [0.0, 0.0, -10.0]  # behind both cameras
    uv_a, uv_b = project(K, np.eye(4), points), project(K, T_B, points)
    uv_b[1] += [0.0, 8.0]  # 8 px off the epipolar line (the baseline is along x)
    tri = triangulate(K, np.eye(4), T_B, uv_a, uv_b, max_reprojection_px=2.0, min_parallax=0.0)
    np.testing.assert_allclose(tri.points[2:], points[2:], rtol=1e-6)
    np.testing.assert_array_equal(tri.valid, [False, False] + [True] * 18)
    # asking for more parallax than the far points have drops them
    angles = parallax(np.zeros(3), camera_center(T_B).ravel(), points)
    strict = triangulate(K, np.eye(4), T_B, uv_a, uv_b, 2.0, min_parallax=np.median(angles[2:]))
    np.testing.assert_array_equal(strict.valid[2:], angles[2:] >= np.median(angles[2:]))
    empty = triangulate(K, np.eye(4), T_B, np.zeros((0, 2)), np.zeros((0, 2)), 2.0, 0.0)
    assert empty.points.shape == (0, 3) and empty.valid.shape == (0,)


def test_two_views_give_the_relative_pose_up_to_scale_and_the_points():
    points = _scene()
    uv_a, uv_b = project(K, np.eye(4), points), project(K, T_B, points)
    result = two_view_geometry(K, uv_a, uv_b, 1.0, 2.0, min_parallax=0.0)
    np.testing.assert_allclose(result.T_ba[:3, :3], R_BA, atol=1e-6)
    direction = T_B[:3, 3] / np.linalg.norm(T_B[:3, 3])
    np.testing.assert_allclose(result.T_ba[:3, 3], direction, atol=1e-6)
    assert result.valid.all()
    np.testing.assert_allclose(result.points_a, points / np.linalg.norm(T_B[:3, 3]), rtol=1e-5)
    angles = parallax(np.zeros(3), camera_center(T_B).ravel(), points)
    assert result.median_parallax == pytest.approx(np.median(angles), rel=1e-5)
    assert two_view_geometry(K, uv_a[:7], uv_b[:7], 1.0, 2.0, 0.0) is None


def test_pnp_finds_the_pose_through_outliers():
    points = _scene()
    uv = project(K, T_B, points)
    uv[:10] += np.random.default_rng(5).uniform(30.0, 60.0, (10, 2))  # 10 gross outliers
    result = solve_pnp(K, points, uv, None, threshold_px=2.0, min_inliers=20)
    np.testing.assert_allclose(result.T_cw, T_B, atol=1e-6)
    np.testing.assert_array_equal(result.inliers, np.arange(len(points)) >= 10)
    guessed = solve_pnp(K, points, uv, make_pose(np.eye(3), [-0.9, 0, 0]), 2.0, 20)
    np.testing.assert_allclose(guessed.T_cw, T_B, atol=1e-6)
    assert solve_pnp(K, points[:5], uv[:5], None, 2.0, 3) is None  # fewer than six points
    assert solve_pnp(K, points, uv, None, 2.0, min_inliers=115) is None
