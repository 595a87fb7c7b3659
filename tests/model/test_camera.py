"""The pinhole camera: its matrix, projection, the forward mounting on the vehicle, distortion
and the image-size check."""

from __future__ import annotations

import numpy as np

from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD, Camera

CAMERA = Camera(fx=700.0, fy=710.0, cx=600.0, cy=180.0, width=1241, height=376)


def test_the_camera_matrix_and_projection():
    np.testing.assert_array_equal(CAMERA.K, [[700, 0, 600], [0, 710, 180], [0, 0, 1]])
    pixels = CAMERA.project(np.array([[0.0, 0.0, 5.0], [1.0, -0.5, 10.0]]))
    np.testing.assert_allclose(pixels, [[600.0, 180.0], [670.0, 144.5]])


def test_the_default_mounting_looks_forward():
    # camera z (optical axis) → vehicle x (forward), x (right) → −y, y (down) → −z
    mount = Camera(1.0, 1.0, 0.0, 0.0).T_vehicle_camera
    np.testing.assert_array_equal(mount[:3, :3] @ [0, 0, 1], [1, 0, 0])
    np.testing.assert_array_equal(mount[:3, :3] @ [1, 0, 0], [0, -1, 0])
    np.testing.assert_array_equal(mount[:3, :3] @ [0, 1, 0], [0, 0, -1])
    assert np.linalg.det(mount[:3, :3]) == 1.0
    mount[0, 3] = 5.0  # each camera has its own copy
    assert CAMERA_TO_VEHICLE_FORWARD[0, 3] == 0.0 and CAMERA.T_vehicle_camera[0, 3] == 0.0


def test_distortion_is_there_when_any_coefficient_is_not_zero():
    assert not CAMERA.has_distortion
    assert Camera(1.0, 1.0, 0.0, 0.0, distortion=np.array([0, 0, 0, 0, 1e-6])).has_distortion


def test_images_of_another_size_than_the_calibrations_are_named():
    assert CAMERA.size_mismatch(1241, 376) is None
    assert Camera(700.0, 700.0, 600.0, 180.0).size_mismatch(640, 480) is None  # no size stated
    message = CAMERA.size_mismatch(1226, 370)
    assert message.startswith(
        "the images are 1226×370 px but the camera calibration is for 1241×376 px"
    )
