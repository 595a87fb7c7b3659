"""Renderer geometry: markers land on their projections, occlusion, determinism, texture scale."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.path import Path

from vo_doppler.model.camera import Camera
from vo_doppler.sim.render import Renderer, look_at, project_points
from vo_doppler.sim.scene import Plane, Scene, city_scene

CAMERA = Camera(300.0, 300.0, 159.5, 119.5, 320, 240)
MARKER_TEXELS = [(64.0, 64.0), (192.0, 64.0), (128.0, 128.0), (64.0, 192.0), (192.0, 200.0)]


def _marker_texture(size: int = 256, sigma: float = 3.0) -> np.ndarray:
    """Dark tile with bright Gaussian blobs centred exactly on the texel coordinates above."""
    grid = np.arange(size, dtype=float)
    image = np.full((size, size), 20.0)
    for s, t in MARKER_TEXELS:
        image += 220.0 * np.exp(
            -((grid[None, :] - s) ** 2 + (grid[:, None] - t) ** 2) / (2 * sigma**2)
        )
    return np.clip(image, 0, 255).round().astype(np.uint8)


def _facing_plane(texture: int = 0, offset=(0.0, 0.0), texel: float = 0.02) -> Plane:
    """A 5.12 m square in the plane y = 0 facing −y (normal u × v = x × z = −y); texture s runs
    along +x and t along +z."""
    return Plane(
        origin=np.array([-2.56, 0.0, -2.56]),
        u_axis=np.array([1.0, 0.0, 0.0]),
        v_axis=np.array([0.0, 0.0, 1.0]),
        width=5.12,
        height=5.12,
        texture=texture,
        texel_size=texel,
        offset=offset,
    )


def _centroid(image: np.ndarray, centre: np.ndarray, radius: int, background: float) -> np.ndarray:
    u0, v0 = np.round(centre).astype(int)
    patch = image[v0 - radius : v0 + radius + 1, u0 - radius : u0 + radius + 1].astype(float)
    weight = np.clip(patch - background, 0.0, None)
    vv, uu = np.mgrid[v0 - radius : v0 + radius + 1, u0 - radius : u0 + radius + 1]
    return np.array([(weight * uu).sum(), (weight * vv).sum()]) / weight.sum()


@pytest.mark.parametrize(
    ("eye", "target"),
    [
        ((0.0, -4.0, 0.0), (0.0, 0.0, 0.0)),  # head-on, magnified texture
        ((1.5, -3.5, 0.4), (0.2, 0.0, -0.1)),  # oblique
        ((3.5, -2.0, -1.0), (0.0, 0.0, 0.0)),  # strongly oblique (anisotropic levels)
        ((0.5, -9.0, 0.3), (0.0, 0.0, 0.0)),  # distant: mip levels 1–2
        ((-4.0, -6.0, 2.0), (0.3, 0.0, 0.3)),  # distant and oblique
    ],
)
def test_markers_land_on_their_projections(eye, target):
    plane = _facing_plane(offset=(7.0, 3.0))
    scene = Scene([plane], [_marker_texture()], sky=0.0)
    T = look_at(eye, target)
    image = Renderer(scene, CAMERA).render(T)
    points = np.array([plane.texel_to_point(s, t) for s, t in MARKER_TEXELS])
    expected = project_points(CAMERA, T, points)
    inside = np.all((expected > 15) & (expected < (CAMERA.width - 16, CAMERA.height - 16)), axis=1)
    assert inside.sum() >= 3
    for pixel in expected[inside]:
        found = _centroid(image, pixel, radius=12, background=30.0)
        # Acceptance is 0.5 px; the renderer does ≤ 0.1 px here, so a half-texel slip would show.
        assert np.linalg.norm(found - pixel) < 0.2, (found, pixel)


def test_nearest_plane_wins_regardless_of_order():
    far = Plane(
        np.array([-3.0, 6.0, -3.0]), np.array([1.0, 0, 0]), np.array([0, 0, 1.0]), 6.0, 6.0, 0, 0.05
    )
    near = Plane(
        np.array([0.0, 3.0, -1.0]), np.array([1.0, 0, 0]), np.array([0, 0, 1.0]), 2.0, 2.0, 1, 0.05
    )
    textures = [np.full((64, 64), 80, np.uint8), np.full((64, 64), 200, np.uint8)]
    T = look_at((0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    a = Renderer(Scene([far, near], textures, sky=0.0), CAMERA).render_full(T)
    b = Renderer(Scene([near, far], textures, sky=0.0), CAMERA).render_full(T)
    np.testing.assert_array_equal(a.image, b.image)
    # The near square spans x ∈ [0, 2], z ∈ [−1, 1] at y = 3: right of the view centre.
    centre_near = project_points(CAMERA, T, [[1.0, 3.0, 0.0]])[0].round().astype(int)
    centre_far = project_points(CAMERA, T, [[-1.5, 6.0, 0.0]])[0].round().astype(int)
    assert a.image[centre_near[1], centre_near[0]] == 200
    assert a.plane_index[centre_near[1], centre_near[0]] == 1
    assert a.depth[centre_near[1], centre_near[0]] == pytest.approx(3.0, rel=1e-5)
    assert a.image[centre_far[1], centre_far[0]] == 80
    assert a.depth[centre_far[1], centre_far[0]] == pytest.approx(6.0, rel=1e-5)
    assert a.image[5, 5] == 0  # above the far plane's top edge (z = 3 at y = 6): sky
    assert np.isinf(a.depth[5, 5]) and a.plane_index[5, 5] == -1


def test_back_face_is_culled_unless_two_sided():
    plane = _facing_plane()
    textures = [np.full((32, 32), 150, np.uint8)]
    behind = look_at((0.0, 3.0, 0.0), (0.0, 0.0, 0.0))
    one_sided = Renderer(Scene([plane], textures, sky=0.0), CAMERA).render(behind)
    assert one_sided.max() == 0
    two = Plane(**{**plane.__dict__, "two_sided": True})
    two_sided = Renderer(Scene([two], textures, sky=0.0), CAMERA).render(behind)
    assert two_sided[CAMERA.height // 2, CAMERA.width // 2] == 150


@pytest.fixture(scope="module")
def small_city():
    return city_scene(seed=5, blocks_x=2, blocks_y=2, tile_size=256, n_facade_textures=2)


def test_city_is_deterministic_per_seed(small_city):
    again = city_scene(seed=5, blocks_x=2, blocks_y=2, tile_size=256, n_facade_textures=2)
    other = city_scene(seed=6, blocks_x=2, blocks_y=2, tile_size=256, n_facade_textures=2)
    for a, b in zip(small_city.textures, again.textures, strict=True):
        np.testing.assert_array_equal(a, b)
    assert len(small_city.planes) == len(again.planes)
    T = look_at((30.0, -4.0, 1.5), (60.0, -3.0, 1.5))
    image = Renderer(small_city, CAMERA).render(T)
    np.testing.assert_array_equal(image, Renderer(again, CAMERA).render(T))
    assert not np.array_equal(image, Renderer(other, CAMERA).render(T))


def test_city_street_view_is_corner_rich(small_city):
    pitch_x, _ = small_city.layout.pitch
    T = look_at((0.5 * pitch_x, 4.0, 1.5), (pitch_x, 4.0, 1.5))  # along the street y = 0
    result = Renderer(small_city, CAMERA).render_full(T)
    below_horizon = result.plane_index[CAMERA.height // 2 + 5 :, :]
    assert np.all(below_horizon >= 0)  # ground everywhere below the horizon
    corners = cv2.goodFeaturesToTrack(result.image, 1000, 0.01, 5)
    assert len(corners) >= 300


def test_project_points_marks_points_behind_camera():
    T = look_at((0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    pixels = project_points(CAMERA, T, [[0.0, 5.0, 0.0], [0.0, -5.0, 0.0]])
    np.testing.assert_allclose(pixels[0], (CAMERA.cx, CAMERA.cy))
    assert np.all(np.isnan(pixels[1]))


@settings(max_examples=25, deadline=None)
@given(
    distance=st.floats(0.3, 60.0),
    azimuth=st.floats(-1.2, 1.2),
    elevation=st.floats(-1.2, 1.2),
    roll=st.floats(-np.pi, np.pi),
)
def test_any_pose_facing_a_plane_sees_it(distance, azimuth, elevation, roll):
    texture = (np.random.default_rng(0).random((128, 128)) * 255).astype(np.uint8)
    plane = Plane(
        origin=np.array([-200.0, 0.0, -200.0]),
        u_axis=np.array([1.0, 0.0, 0.0]),
        v_axis=np.array([0.0, 0.0, 1.0]),
        width=400.0,
        height=400.0,
        texture=0,
        texel_size=0.03,
    )
    renderer = Renderer(Scene([plane], [texture], sky=0.0), CAMERA)
    eye = distance * np.array(
        [
            np.sin(azimuth) * np.cos(elevation),
            -np.cos(azimuth) * np.cos(elevation),
            np.sin(elevation),
        ]
    )
    T = look_at(eye, (0.0, 0.0, 0.0))
    spin = np.eye(4)
    spin[:2, :2] = [[np.cos(roll), -np.sin(roll)], [np.sin(roll), np.cos(roll)]]
    T = T @ spin
    result = renderer.render_full(T)
    assert result.image.dtype == np.uint8
    centre = (CAMERA.height // 2, CAMERA.width // 2)
    assert result.plane_index[centre] == 0
    hit = renderer.backproject(T, [[CAMERA.cx, CAMERA.cy]], result.plane_index)[0]
    np.testing.assert_allclose(hit, 0.0, atol=1e-6 * max(distance, 1.0))
    pixel = [[float(centre[1]), float(centre[0])]]
    hit_z = (renderer.backproject(T, pixel, result.plane_index)[0] - T[:3, 3]) @ T[:3, 2]
    assert result.depth[centre] == pytest.approx(hit_z, rel=1e-4)
    seen = result.plane_index >= 0
    assert np.all(np.isfinite(result.depth[seen]))
    assert result.image[seen].min() >= 0 and result.image[seen].max() <= 255


@settings(max_examples=10, deadline=None)
@given(
    pixels_per_texel=st.floats(1.5, 4.0),
    offset_s=st.floats(0.0, 64.0),
    offset_t=st.floats(0.0, 64.0),
)
def test_head_on_plane_shows_texture_at_the_right_scale(pixels_per_texel, offset_s, offset_t):
    """Magnified head-on view = the texture under the affine map texel → pixel (bilinear)."""
    texture = cv2.GaussianBlur(
        (np.random.default_rng(1).random((128, 128)) * 255).astype(np.uint8), (0, 0), 1.0
    )
    texel = 0.02
    plane = _facing_plane(offset=(offset_s, offset_t), texel=texel)
    distance = CAMERA.fx * texel / pixels_per_texel
    T = look_at((0.0, -distance, 0.0), (0.0, 0.0, 0.0))
    image = Renderer(Scene([plane], [texture], sky=0.0), CAMERA).render(T)
    # Texel (s, t) sits at x = (s − offset_s)·m − 2.56, z = (t − offset_t)·m − 2.56; image v ∝ −z.
    k = pixels_per_texel
    affine = np.array(
        [
            [k, 0.0, CAMERA.cx + k * (-2.56 / texel - offset_s)],
            [0.0, -k, CAMERA.cy - k * (-2.56 / texel - offset_t)],
        ]
    )
    expected = cv2.warpAffine(
        texture,
        affine,
        (CAMERA.width, CAMERA.height),
        flags=cv2.INTER_LINEAR,
        borderMode=cv2.BORDER_WRAP,
    )
    inner = (slice(20, -20), slice(20, -20))
    difference = np.abs(image[inner].astype(float) - expected[inner])
    assert difference.mean() < 0.6
    assert difference.max() <= 3


def test_geometric_edges_are_area_averaged():
    """Pixels cut by a slanted plane edge show about their covered fraction (4 sub-samples),
    where centre-point sampling would give only 0 or 200; the plane index is exact at centres."""
    plane = _facing_plane()
    scene = Scene([plane], [np.full((64, 64), 200, np.uint8)], sky=0.0)
    T = look_at((2.3, -6.0, 1.1), (2.56, 0.0, 1.5), up=(0.35, 0.0, 1.0))  # tilted edge x = 2.56
    result = Renderer(scene, CAMERA).render_full(T)
    image = result.image.astype(float)
    polygon = Path(project_points(CAMERA, T, plane.corners))
    vv, uu = np.mgrid[0 : CAMERA.height, 0 : CAMERA.width]
    centre_inside = polygon.contains_points(np.column_stack([uu.ravel(), vv.ravel()]))
    np.testing.assert_array_equal(result.plane_index.ravel() == 0, centre_inside)
    changes = np.zeros(image.shape, dtype=bool)
    changes[:, 1:] |= image[:, 1:] != image[:, :-1]
    changes[1:, :] |= image[1:, :] != image[:-1, :]
    rows, cols = np.nonzero(cv2.dilate(changes.astype(np.uint8), np.ones((3, 3), np.uint8)))
    fine = (np.arange(16) + 0.5) / 16 - 0.5
    du, dv = np.meshgrid(fine, fine)
    coverage = np.array(
        [
            polygon.contains_points(np.column_stack([c + du.ravel(), r + dv.ravel()])).mean()
            for r, c in zip(rows, cols, strict=True)
        ]
    )
    cut = (coverage > 0.05) & (coverage < 0.95)
    assert cut.sum() > 100
    rows, cols, coverage = rows[cut], cols[cut], coverage[cut]
    error = np.abs(image[rows, cols] / 200.0 - coverage)
    assert error.mean() < 0.12  # centre-point sampling: min(coverage, 1 − coverage) ≈ 0.25
    assert error.max() < 0.35
