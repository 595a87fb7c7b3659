"""Lens distortion and rectification maps: the model round-trips, matches OpenCV, and a marker
seen through a miscalibrated lens lands where the calibration chain predicts."""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.model.camera import Camera
from vo_doppler.sim.camera_effects import CameraEffects, EffectsCamera
from vo_doppler.sim.lens import LensMaps, distort, project_distorted, undistort
from vo_doppler.sim.scene import Plane, Scene

LENS = (-0.30, 0.10, 0.001, -0.0005, 0.0)
PINHOLE = Camera(200.0, 200.0, 159.5, 89.5, 320, 180)


@settings(max_examples=60, deadline=None)
@given(
    x=st.floats(-0.8, 0.8),
    y=st.floats(-0.45, 0.45),
    k1=st.floats(-0.35, 0.0),
    k2=st.floats(0.0, 0.12),
)
def test_undistort_inverts_distort(x, y, k1, k2):
    lens = (k1, k2, 0.001, -0.0005, 0.0)
    point = np.array([[x, y]])
    np.testing.assert_allclose(undistort(distort(point, lens), lens), point, atol=1e-10)


def test_distort_is_opencv_projection():
    rng = np.random.default_rng(1)
    points = np.column_stack([rng.uniform(-3, 3, (50, 2)), rng.uniform(4, 20, 50)])
    camera = replace(PINHOLE, distortion=np.array(LENS))
    expected, _ = cv2.projectPoints(points, np.zeros(3), np.zeros(3), camera.K, camera.distortion)
    np.testing.assert_allclose(project_distorted(camera, points), expected[:, 0], atol=1e-9)


def test_maps_follow_the_true_lens_and_the_calibration():
    true = replace(PINHOLE, distortion=np.array(LENS))
    calibration = replace(PINHOLE, fx=199.0, cx=161.0, distortion=np.add(LENS, (0.006, 0, 0, 0, 0)))
    maps = LensMaps.build(true, calibration)
    render = maps.render_camera
    # Every raw pixel reads the render where the true lens sends its ray.
    map_x, map_y = maps.raw_from_render
    rays = np.column_stack(
        [(map_x.ravel() - render.cx) / render.fx, (map_y.ravel() - render.cy) / render.fy]
    )
    raw = distort(rays, true.distortion) * (true.fx, true.fy) + (true.cx, true.cy)
    u, v = np.meshgrid(np.arange(true.width), np.arange(true.height))
    np.testing.assert_allclose(raw, np.column_stack([u.ravel(), v.ravel()]), atol=2e-4)
    # The render covers every raw pixel with a margin.
    assert map_x.min() >= 3 - 1e-4 and map_x.max() <= render.width - 4 + 1e-4
    assert map_y.min() >= 3 - 1e-4 and map_y.max() <= render.height - 4 + 1e-4
    # Every rectified pixel reads the raw frame where the calibrated lens sends its ray.
    rect_x, rect_y = maps.rectified_from_raw
    expected = project_distorted(
        calibration,
        np.column_stack([(u.ravel() - 161.0) / 199.0, (v.ravel() - 89.5) / 200.0, np.ones(u.size)]),
    )
    np.testing.assert_allclose(
        np.column_stack([rect_x.ravel(), rect_y.ravel()]), expected, atol=2e-4
    )


def _blob_texture(size: int = 256, sigma: float = 4.0) -> np.ndarray:
    grid = np.arange(size) - size / 2
    blob = np.exp(-(grid[None, :] ** 2 + grid[:, None] ** 2) / (2 * sigma**2))
    return np.round(20 + 220 * blob).astype(np.uint8)


def _blob_plane(x: float, y: float, z: float, texel: float = 0.01) -> Plane:
    """A square of 256 texels facing the camera (−z), its blob centred at (x, y, z) in camera
    axes."""
    half = 128 * texel
    return Plane(
        origin=np.array([x - half, y + half, z]),
        u_axis=np.array([1.0, 0.0, 0.0]),
        v_axis=np.array([0.0, -1.0, 0.0]),
        width=2 * half,
        height=2 * half,
        texture=0,
        texel_size=texel,
    )


def _centroid(image: np.ndarray, near: np.ndarray, radius: int = 9) -> np.ndarray:
    u0, v0 = np.round(near).astype(int)
    patch = image[v0 - radius : v0 + radius + 1, u0 - radius : u0 + radius + 1].astype(float)
    weight = np.clip(patch - 20.0, 0.0, None) ** 2
    vv, uu = np.mgrid[v0 - radius : v0 + radius + 1, u0 - radius : u0 + radius + 1]
    return np.array([(weight * uu).sum(), (weight * vv).sum()]) / weight.sum()


STILL = CameraEffects(readout_s=0.0, exposure_s=0.0, sensor=None)


@pytest.mark.parametrize("where", [(0.0, 0.0), (-3.2, -1.4), (3.0, 1.5)])
def test_marker_lands_where_the_calibration_chain_predicts(where):
    """Raw pixel q = K·d_true(X/Z); the rectified image shows it at K_cal·d_cal⁻¹(K_cal⁻¹ q)."""
    centre = np.array([*where, 6.0])
    scene = Scene([_blob_plane(*centre)], [_blob_texture()], sky=0.0)
    calibration = replace(PINHOLE, fx=198.0, fy=198.0, cx=161.0, cy=88.5)
    camera = EffectsCamera(scene, PINHOLE, calibration, STILL, np.zeros(1), seed=0)
    T = np.eye(4)
    image = camera.frame(0, np.stack([T, T, T])[None], np.zeros((1, 3)))
    true = replace(PINHOLE, distortion=np.array(STILL.distortion))
    raw = project_distorted(true, centre[None])[0]
    calibrated = np.asarray(STILL.distortion) + STILL.distortion_error
    ray = undistort((raw - (161.0, 88.5)) / 198.0, calibrated)[0]
    expected = ray * 198.0 + (161.0, 88.5)
    assert np.linalg.norm(_centroid(image, expected) - expected) < 0.1
    # A pinhole reading of the same calibration misses it by pixels away from the centre.
    pinhole_guess = centre[:2] / centre[2] * 198.0 + (161.0, 88.5)
    assert np.linalg.norm(pinhole_guess - expected) > (0.5 if any(where) else 0.0)
