"""City scene options of the realistic simulator: repetitive window facades, asphalt ground; the
default city is unchanged by them."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.sim.scene import city_scene, window_facade_texture

SMALL = {"blocks_x": 2, "blocks_y": 2, "tile_size": 256}


def _correlation(tile: np.ndarray, shift: int) -> float:
    a = tile.astype(float) - tile.mean()
    return float((a * np.roll(a, shift, axis=1)).mean() / a.var())


def test_window_facade_repeats_every_bay():
    tile = window_facade_texture(1024, np.random.default_rng(3), columns=16, storeys=12)
    bay = 1024 // 16
    one = _correlation(tile, bay)
    assert one > 0.45
    assert _correlation(tile, 3 * bay) == pytest.approx(one, abs=0.03)
    assert _correlation(tile, bay // 2) < one - 0.4
    rows = tile.astype(float) - tile.mean()
    storey = round(1024 / 12)
    assert float((rows * np.roll(rows, storey, axis=0)).mean() / rows.var()) > 0.4


def test_options_leave_the_city_geometry_alone():
    plain = city_scene(4, **SMALL)
    varied = city_scene(4, window_facades=3, ground_contrast=0.35, **SMALL)
    assert len(varied.planes) == len(plain.planes)
    for a, b in zip(plain.planes, varied.planes, strict=True):
        np.testing.assert_array_equal(a.corners, b.corners)
    assert plain.buildings == varied.buildings
    assert len(varied.textures) == len(plain.textures) + 3
    windows = {p.texture for p in varied.planes} - {p.texture for p in plain.planes}
    assert windows and min(windows) > len(plain.textures) - 1
    for k, texture in enumerate(plain.textures[1:], start=1):
        np.testing.assert_array_equal(texture, varied.textures[k])


def test_asphalt_scales_the_ground_contrast():
    plain = city_scene(4, **SMALL).textures[0].astype(float)
    asphalt = city_scene(4, ground_contrast=0.35, **SMALL).textures[0].astype(float)
    assert asphalt.mean() == pytest.approx(plain.mean(), abs=0.5)
    assert asphalt.std() == pytest.approx(0.35 * plain.std(), rel=0.01)


def test_an_untextured_city_has_the_textured_citys_geometry():
    """A simulation without images skips painting the textures (85 % of its time) but draws
    their random numbers: every plane (corners, texture index, offset, gain) and building is
    that of the textured city, with window facades too."""
    for options in ({}, {"window_facades": 2}):
        textured = city_scene(7, **SMALL, **options)
        bare = city_scene(7, textured=False, **SMALL, **options)
        assert bare.textures == [] and textured.textures
        assert bare.buildings == textured.buildings and bare.layout == textured.layout
        assert len(bare.planes) == len(textured.planes)
        for a, b in zip(textured.planes, bare.planes, strict=True):
            np.testing.assert_array_equal(a.corners, b.corners)
            assert (a.texture, a.offset, a.gain, a.bias) == (b.texture, b.offset, b.gain, b.bias)
