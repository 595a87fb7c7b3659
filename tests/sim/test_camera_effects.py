"""The realistic camera: rolling shutter places each row at its own time, motion blur spreads a
point over its exposure path, everything off gives the pinhole render, frames repeat per seed."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tests.sim.test_lens import _blob_plane, _blob_texture, _centroid
from vo_doppler.model.camera import Camera
from vo_doppler.sim.camera_effects import CameraEffects, EffectsCamera
from vo_doppler.sim.render import Renderer
from vo_doppler.sim.scene import Scene

CAMERA = Camera(200.0, 200.0, 159.5, 89.5, 320, 180)
OFF = CameraEffects(
    distortion=(0.0,) * 5, distortion_error=(0.0,) * 5, readout_s=0.0, exposure_s=0.0, sensor=None
)
SPEED = 10.0
"""m/s along the camera's x axis."""
DEPTH = 5.0
MARKERS = [(-1.0, -1.5), (0.5, -0.5), (-0.5, 0.4), (1.0, 1.6)]
"""Blob centres (x, y) at depth 5 m, rows from top to bottom."""


def _scene() -> Scene:
    """Small blob squares (0.77 m, blob σ 3.6 cm) that do not overlap."""
    planes = [_blob_plane(x, y, DEPTH, texel=0.003) for x, y in MARKERS]
    return Scene(planes, [_blob_texture(sigma=12.0)], sky=0.0)


def _poses(times: np.ndarray) -> np.ndarray:
    """Camera → world poses translating along x at SPEED (times of any shape)."""
    T = np.broadcast_to(np.eye(4), (*times.shape, 4, 4)).copy()
    T[..., 0, 3] = SPEED * times
    return T


def _frame(effects: CameraEffects, seed: int = 0, scene: Scene | None = None) -> np.ndarray:
    camera = EffectsCamera(scene or _scene(), CAMERA, CAMERA, effects, np.zeros(1), seed)
    times = camera.band_times(np.zeros(1))
    return camera.frame(0, _poses(times)[0], times[0])


def _expected(x: float, y: float, t: float) -> np.ndarray:
    return np.array(
        [CAMERA.fx * (x - SPEED * t) / DEPTH + CAMERA.cx, CAMERA.fy * y / DEPTH + CAMERA.cy]
    )


def test_everything_off_is_the_pinhole_render():
    image = _frame(OFF)
    expected = Renderer(_scene(), CAMERA).render(np.eye(4))
    np.testing.assert_array_equal(image, expected)


@pytest.mark.parametrize("band_rows", [180, 60, 7])
def test_rolling_shutter_reads_each_row_at_its_time(band_rows):
    """Row v is read at (v − v_mid)·readout/H: a marker there shows the pose of that time."""
    readout = 0.03
    image = _frame(replace(OFF, readout_s=readout, band_rows=band_rows))
    for x, y in MARKERS:
        row = CAMERA.fy * y / DEPTH + CAMERA.cy
        t = (row - (CAMERA.height - 1) / 2) * readout / CAMERA.height
        expected = _expected(x, y, t)
        assert np.linalg.norm(_centroid(image, expected) - expected) < 0.1
        assert abs(expected[0] - _expected(x, y, 0.0)[0]) > 1.0 or abs(t) < 0.004


def test_motion_blur_spreads_a_point_over_its_path():
    """Variance along the motion grows by L²/12 (L = f·v·τ/Z, box blur; ≤ 3 % less with six
    samples); across it, it stays."""
    exposure = 0.02
    length = CAMERA.fx * SPEED * exposure / DEPTH
    sharp, blurred = _frame(OFF), _frame(replace(OFF, exposure_s=exposure))
    for x, y in MARKERS:
        centre = _expected(x, y, 0.0)
        moments = []
        for image in (sharp, blurred):
            u0, v0 = np.round(centre).astype(int)
            patch = image[v0 - 12 : v0 + 13, u0 - 12 : u0 + 13].astype(float) - 20.0
            weight = np.clip(patch, 0.0, None)
            vv, uu = np.mgrid[-12:13, -12:13] + np.array([v0, u0])[:, None, None]
            mean_u = (weight * uu).sum() / weight.sum()
            mean_v = (weight * vv).sum() / weight.sum()
            moments.append(
                (
                    mean_u,
                    (weight * (uu - mean_u) ** 2).sum() / weight.sum(),
                    (weight * (vv - mean_v) ** 2).sum() / weight.sum(),
                )
            )
        (u_sharp, var_u_sharp, var_v_sharp), (u_blur, var_u_blur, var_v_blur) = moments
        assert u_blur == pytest.approx(u_sharp, abs=0.05)
        assert var_u_blur - var_u_sharp == pytest.approx(length**2 / 12, rel=0.05)
        assert var_v_blur == pytest.approx(var_v_sharp, rel=0.05)


def test_frames_are_deterministic_per_seed():
    effects = replace(
        OFF, distortion=(-0.3, 0.1, 0, 0, 0), readout_s=0.02, sensor=CameraEffects().sensor
    )
    a, b, c = _frame(effects, 5), _frame(effects, 5), _frame(effects, 6)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
