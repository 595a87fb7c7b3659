"""A comma2k19 ``video.hevc`` decoded into a sequence's camera (frames, times, calibration).

OpenCV's pip wheels can decode HEVC but not encode it, so the test videos are Motion-JPEG in
an AVI container under the segment's file name: the decoder probes the content, not the name.
"""

from __future__ import annotations

import logging

import cv2
import numpy as np
import pytest
import yaml

from tests.conftest import require_shared
from vo_doppler.errors import InputError
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.comma2k19 import DeviceMount
from vo_doppler.io.comma2k19_import import import_comma2k19
from vo_doppler.io.comma2k19_video import decode_video, eon_camera
from vo_doppler.io.sequence import read_sequence


def write_video(path, frames: int, width: int = 116, height: int = 88) -> None:
    avi = path.with_suffix(".avi")
    writer = cv2.VideoWriter(str(avi), cv2.VideoWriter_fourcc(*"MJPG"), 20, (width, height))
    assert writer.isOpened()
    for k in range(frames):
        writer.write(np.full((height, width, 3), (7 * k) % 250, dtype=np.uint8))
    writer.release()
    avi.rename(path)


LEVEL = DeviceMount(0.0, 0.0, 0.0)


def test_eon_camera_scales_with_the_frame_and_turns_by_the_mounting():
    full = eon_camera(1164, 874, LEVEL)
    assert (full.fx, full.fy, full.cx, full.cy) == (910.0, 910.0, 582.0, 437.0)
    half = eon_camera(582, 437, LEVEL)
    assert (half.fx, half.cy) == pytest.approx((455.0, 218.5))
    yaw, pitch = np.radians(2.0), np.radians(3.8)
    optical_axis = eon_camera(1164, 874, DeviceMount(yaw, 0.0, 0.0)).T_vehicle_camera[:3, 2]
    np.testing.assert_allclose(optical_axis, [np.cos(-yaw), np.sin(-yaw), 0.0], atol=1e-12)
    down = eon_camera(1164, 874, DeviceMount(yaw, 0.0, 0.0)).T_vehicle_camera[:3, 1]
    np.testing.assert_allclose(down, [0.0, 0.0, -1.0], atol=1e-12)
    # the travel 3.8° above the device's forward axis: the camera looks 3.8° below the vehicle's
    pitched = eon_camera(1164, 874, DeviceMount(0.0, pitch, 0.0)).T_vehicle_camera[:3, 2]
    np.testing.assert_allclose(pitched, [np.cos(pitch), 0.0, -np.sin(pitch)], atol=1e-12)
    # rolled: the image's right (camera x) is the device's, tilted about the forward axis
    roll = np.radians(1.2)
    right = eon_camera(1164, 874, DeviceMount(0.0, 0.0, roll)).T_vehicle_camera[:3, 0]
    np.testing.assert_allclose(right, [0.0, -np.cos(roll), np.sin(roll)], atol=1e-12)


def test_frames_times_and_calibration_are_written(tmp_path, caplog):
    video = tmp_path / "video.hevc"
    write_video(video, frames=6)
    times = 100.0 + 0.05 * np.arange(5)
    with caplog.at_level(logging.WARNING):
        decoded = decode_video(video, times, tmp_path / "seq", LEVEL)
    assert (decoded.frames, decoded.width, decoded.height) == (5, 116, 88)
    assert "more frames in the video for 5 frame times" in caplog.text
    images = sorted((tmp_path / "seq" / "image_0").glob("*.jpg"))
    assert [p.name for p in images] == [f"{k:06d}.jpg" for k in range(5)]
    grey = cv2.imread(str(images[3]), cv2.IMREAD_UNCHANGED)
    assert grey.ndim == 2 and abs(float(grey.mean()) - 21.0) < 3.0
    np.testing.assert_allclose(np.loadtxt(tmp_path / "seq" / "times.txt"), times, atol=1e-6)
    camera = read_camera(tmp_path / "seq" / "calib.yaml")
    assert camera.fx == pytest.approx(910.0 * 116 / 1164)


def test_a_short_video_keeps_its_frames_and_says_so(tmp_path, caplog):
    video = tmp_path / "video.hevc"
    write_video(video, frames=3)
    with caplog.at_level(logging.WARNING):
        decoded = decode_video(video, np.arange(10.0), tmp_path / "seq", LEVEL)
    assert decoded.frames == 3
    assert "3 frames in the video for 10 frame times; the first 3 are used" in caplog.text
    assert np.loadtxt(tmp_path / "seq" / "times.txt").shape == (3,)


def test_an_undecodable_video_is_named(tmp_path):
    video = tmp_path / "video.hevc"
    video.write_bytes(b"\x00\x00\x01 not a video" * 50)
    with pytest.raises(InputError, match=r"video\.hevc") as caught:
        decode_video(video, np.arange(3.0), tmp_path / "seq", LEVEL)
    assert "decode" in str(caught.value) or "open" in str(caught.value)


@pytest.mark.slow
@pytest.mark.shared_data
def test_imported_segment_with_a_video_has_a_camera_on_gps_time(tmp_path):
    source = require_shared("comma2k19_example1")
    segment = tmp_path / "segment"
    segment.mkdir()
    for entry in source.iterdir():
        (segment / entry.name).symlink_to(entry)
    write_video(segment / "video.hevc", frames=1200)
    folder = tmp_path / "seq"
    summary = import_comma2k19(segment, folder, source / "Sta20124_1400_1845.sp3")
    assert summary.has_video
    manifest = yaml.safe_load((folder / "sequence.yaml").read_text())
    assert manifest["camera"]["time_offset_s"] == manifest["clock_offsets"]["log_to_gps_s"]
    sequence = read_sequence(folder)
    assert sequence.image_times.shape == (1200,)
    np.testing.assert_allclose(sequence.image_times, sequence.truth.t, atol=1e-5)
    assert sequence.camera.width == 116
