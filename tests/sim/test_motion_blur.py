"""Motion blur and rolling shutter on exact cases: the image motion of a sideways step and of a
turn, the shift a later-read row sees, and a step edge spread over the exposure's path."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from vo_doppler.model.camera import Camera
from vo_doppler.sim.motion_blur import expose, image_motion

CAMERA = Camera(fx=200.0, fy=200.0, cx=40.0, cy=30.0)
H, W = 60, 80


def _pose(x: float = 0.0, yaw: float = 0.0) -> np.ndarray:
    """Camera → world, the camera moved ``x`` m along its own x axis (right) and turned ``yaw``
    rad about its y axis (down)."""
    pose = np.eye(4)
    pose[:3, :3] = Rotation.from_euler("y", yaw).as_matrix()
    pose[0, 3] = x
    return pose


def test_a_sideways_step_moves_points_by_f_b_over_z_and_leaves_the_sky():
    depth = np.full((H, W), 10.0)
    depth[:10] = np.inf  # sky in the top rows
    motion = image_motion(depth, CAMERA, _pose(), _pose(x=0.5))
    # the camera moves 0.5 m right: points at 10 m move 200 · 0.5 / 10 = 10 px left
    np.testing.assert_allclose(motion[10:, :, 0], -10.0, atol=1e-4)
    np.testing.assert_allclose(motion[10:, :, 1], 0.0, atol=1e-4)
    np.testing.assert_allclose(motion[:10], 0.0, atol=1e-4)  # float32 arithmetic


def test_a_turn_moves_near_and_far_points_alike():
    near, far = np.full((H, W), 2.0), np.full((H, W), np.inf)
    turn = _pose(yaw=np.radians(0.5))
    moved_near = image_motion(near, CAMERA, _pose(), turn)
    np.testing.assert_allclose(moved_near, image_motion(far, CAMERA, _pose(), turn), atol=1e-3)
    # at the principal point: u' = cx − fx·tan(0.5°) (a turn to the right moves the scene left)
    centre = moved_near[int(CAMERA.cy), int(CAMERA.cx), 0]
    assert centre == pytest.approx(-200.0 * np.tan(np.radians(0.5)), abs=1e-3)


def _sideways(speed_px_per_s: float, half_span_s: float = 0.01):
    """Poses 2·half_span apart moving right at constant speed, depth 10 m: the scene moves
    ``speed_px_per_s`` px/s to the left."""
    b = speed_px_per_s * half_span_s * 10.0 / CAMERA.fx
    return np.stack([_pose(-b), _pose(), _pose(b)]), np.full((H, W), 10.0), half_span_s


def test_an_instant_exposure_at_the_render_time_is_the_image():
    poses, depth, half = _sideways(1000.0)
    image = np.random.default_rng(1).uniform(0, 255, (H, W)).astype(np.float32)
    out = expose(image, depth, CAMERA, poses, half, np.zeros((H, W)), exposure_s=0.0)
    assert out.dtype == np.float32
    np.testing.assert_allclose(out, image, atol=1e-3)


def test_a_row_read_later_sees_the_scene_moved_on():
    # 1000 px/s to the left, the rows read 3 ms after the render: the image 3 px to the left
    poses, depth, half = _sideways(1000.0)
    ramp = np.tile(np.arange(W, dtype=np.float32) * 2.0, (H, 1))  # bilinear reads are exact
    out = expose(ramp, depth, CAMERA, poses, half, np.full((H, W), 0.003), exposure_s=0.0)
    np.testing.assert_allclose(out[:, 5:-5], ramp[:, 5:-5] + 2.0 * 3.0, atol=1e-3)
    earlier = expose(ramp, depth, CAMERA, poses, half, np.full((H, W), -0.003), exposure_s=0.0)
    np.testing.assert_allclose(earlier[:, 5:-5], ramp[:, 5:-5] - 2.0 * 3.0, atol=1e-3)


def test_an_exposure_spreads_a_step_edge_over_the_path_it_lasts():
    # 1000 px/s for 4 ms: a 4-px path, sampled 5 times (one per pixel of path, plus one)
    poses, depth, half = _sideways(1000.0)
    step = np.zeros((H, W), dtype=np.float32)
    step[:, 40:] = 1.0
    out = expose(step, depth, CAMERA, poses, half, np.zeros((H, W)), exposure_s=0.004)
    row = out[H // 2]
    np.testing.assert_array_equal(row[:37], 0.0)
    np.testing.assert_array_equal(row[43:], 1.0)
    # column 38 reads 36.4, 37.2, 38, 38.8 and 39.6, of which the edge (bilinear from 39 to
    # 40) gives 0.6 to the last only: 0.12; and so on
    np.testing.assert_allclose(row[37:43], [0.0, 0.12, 0.36, 0.64, 0.88, 1.0], atol=1e-5)
    # symmetric about the edge: the blur neither moves nor darkens the image
    assert row.sum() == pytest.approx(step[H // 2].sum(), abs=1e-4)
    np.testing.assert_allclose(out, np.tile(row, (H, 1)), atol=1e-6)
