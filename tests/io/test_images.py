"""Image folders and their timestamps."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import REPO_ROOT
from vo_doppler.errors import InputError
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.images import (
    check_image_size,
    list_images,
    prefetch_images,
    read_image,
    read_times,
    times_from_fps,
)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(0.001, 100.0), min_size=1, max_size=30), st.booleans())
def test_times_round_trip(tmp_path_factory, steps, as_csv):
    times = np.cumsum(steps) + 1000.0
    path = tmp_path_factory.mktemp("t") / ("times.csv" if as_csv else "times.txt")
    if as_csv:
        path.write_text("frame,t\n" + "".join(f"{i},{float(t)!r}\n" for i, t in enumerate(times)))
    else:
        path.write_text("".join(f"{float(t)!r}\n" for t in times))
    np.testing.assert_array_equal(read_times(path, len(times)), times)


def test_non_monotonic_times_name_the_line(tmp_path):
    path = tmp_path / "times.txt"
    path.write_text("0.0\n0.1\n0.1\n0.3\n")
    with pytest.raises(InputError, match=r"times.txt:3: timestamps must increase"):
        read_times(path, 4)
    path.write_text("0.0\nabc\n")
    with pytest.raises(InputError, match=r"times.txt:2: timestamp is not a number"):
        read_times(path, 2)


def test_fps_times():
    np.testing.assert_allclose(times_from_fps(10.0, 3), [0.0, 0.1, 0.2])
    with pytest.raises(InputError, match="positive"):
        times_from_fps(0.0, 3)


def test_folder_listing_and_unreadable_images(tmp_path):
    for name in ("b.png", "a.png"):
        cv2.imwrite(str(tmp_path / name), np.full((8, 8), 100, np.uint8))
    (tmp_path / "c.jpg").write_bytes(b"not a jpeg")
    (tmp_path / "notes.txt").write_text("ignored")
    files = list_images(tmp_path)
    assert [f.name for f in files] == ["a.png", "b.png", "c.jpg"]
    assert read_image(files[0]).shape == (8, 8)
    assert read_image(files[2]) is None


@pytest.mark.parametrize("depth", [1, 3, 50])
def test_prefetched_images_equal_direct_reads_in_order(tmp_path, depth):
    rng = np.random.default_rng(depth)
    for k in range(7):
        cv2.imwrite(str(tmp_path / f"{k:02d}.png"), rng.integers(0, 256, (6, 9), dtype=np.uint8))
    (tmp_path / "03.png").write_bytes(b"broken")
    files = list_images(tmp_path)
    prefetched = list(prefetch_images(files, depth))
    assert len(prefetched) == len(files)
    for path, image in zip(files, prefetched, strict=True):
        direct = read_image(path)
        if direct is None:
            assert image is None
        else:
            np.testing.assert_array_equal(image, direct)
    assert prefetched[3] is None and prefetched[2] is not None


def test_prefetch_stops_when_the_consumer_does(tmp_path):
    for k in range(20):
        cv2.imwrite(str(tmp_path / f"{k:02d}.png"), np.full((4, 4), k, np.uint8))
    images = prefetch_images(list_images(tmp_path), depth=2)
    assert [int(next(images)[0, 0]) for _ in range(3)] == [0, 1, 2]
    images.close()
    with pytest.raises(StopIteration):
        next(images)
    with pytest.raises(ValueError, match="depth"):
        next(prefetch_images(list_images(tmp_path), depth=0))


def test_a_calibration_for_another_image_size_is_an_error_naming_both(tmp_path):
    """Issue 30: the calibration of KITTI's 1226×370 sequences on 1241×376 images passed
    silently (its principal point and focal lengths are wrong there)."""
    calib = REPO_ROOT / "calib" / "kitti_odometry_04-12.yaml"
    camera = read_camera(calib)
    (tmp_path / "000000.png").write_bytes(b"not a png")  # skipped: the next one decodes
    cv2.imwrite(str(tmp_path / "000001.png"), np.zeros((376, 1241), np.uint8))
    images = list_images(tmp_path)
    with pytest.raises(InputError) as found:
        check_image_size(camera, images, calib)
    message = str(found.value)
    assert "the images are 1241×376 px but the camera calibration is for 1226×370 px" in message
    assert "kitti_odometry_04-12.yaml" in message and "000001.png" in message
    check_image_size(read_camera(REPO_ROOT / "calib" / "kitti_odometry_00-02.yaml"), images, "c")
    camera.width = camera.height = 0  # a calibration without a size (KITTI calib.txt)
    check_image_size(camera, images, calib)
    assert camera.size_mismatch(1241, 376) is None
