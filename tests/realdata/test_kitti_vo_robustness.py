"""VO robustness on the real KITTI clip: damaged sequences finish, stay finite and are flagged."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from tests.conftest import require_shared
from vo_doppler.eval.metrics import evaluate
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.trajectory import read_kitti
from vo_doppler.vo.batch import run_visual_odometry

pytestmark = pytest.mark.slow

N_FRAMES = 24
GLITCH = 10


@pytest.fixture(scope="module")
def kitti():
    folder = require_shared("kitti06_0000_0050")
    files = sorted((folder / "image_0").glob("*.png"))[:N_FRAMES]
    images = [cv2.imread(str(f), cv2.IMREAD_GRAYSCALE) for f in files]
    times = np.loadtxt(folder / "times.txt")[:N_FRAMES]
    truth = read_kitti(folder / "poses.txt")
    camera = read_camera(folder / "calib.txt")
    return images, times, camera, truth.subset(slice(0, N_FRAMES))


def run(images, times, camera):
    return run_visual_odometry(images, times, camera)


def flagged(output) -> dict[int, list[str]]:
    return {f["index"]: f["reasons"] for f in output.stats.flagged_frames}


@pytest.fixture(scope="module")
def clean_run(kitti):
    images, times, camera, _ = kitti
    return run(images, times, camera)


def test_clean_clip_tracks_every_frame_and_follows_truth(kitti, clean_run):
    _, _, _, truth = kitti
    assert flagged(clean_run) == {}
    assert len(clean_run.trajectory) == N_FRAMES
    assert clean_run.stats.reprojection_rms_px < 1.5
    estimate = clean_run.trajectory
    scale = truth.path_length / estimate.path_length
    scaled = estimate.transformed(np.eye(3), np.zeros(3), scale)
    errors = evaluate(scaled, truth, "start", np.array([0.0, -1.0, 0.0]))
    assert errors.final_drift_pct < 2.0
    assert abs(errors.end_yaw_error_deg) < 1.5


def glitch_then_compare(kitti, clean_run, images, times, expected_reason):
    _, _, camera, _ = kitti
    output = run(images, times, camera)
    assert len(output.trajectory) == len(images)
    assert np.all(np.isfinite(output.trajectory.positions))
    assert np.all(np.isfinite(output.trajectory.orientations.as_quat()))
    reasons = flagged(output)
    assert expected_reason in reasons.get(GLITCH, []), reasons
    return output


def direction_of_travel(trajectory):
    step = trajectory.positions[-1] - trajectory.positions[0]
    return step / np.linalg.norm(step)


def test_black_frame(kitti, clean_run):
    images, times, _, _ = kitti
    damaged = list(images)
    damaged[GLITCH] = np.zeros_like(images[GLITCH])
    output = glitch_then_compare(kitti, clean_run, damaged, times, "blank")
    assert list(flagged(output)) == [GLITCH]
    cosine = direction_of_travel(output.trajectory) @ direction_of_travel(clean_run.trajectory)
    assert cosine > np.cos(np.radians(1.0))


def test_unreadable_image(kitti, clean_run):
    images, times, _, _ = kitti
    damaged = list(images)
    damaged[GLITCH] = None
    output = glitch_then_compare(kitti, clean_run, damaged, times, "unreadable")
    assert list(flagged(output)) == [GLITCH]


def test_duplicated_frame(kitti, clean_run):
    images, times, _, _ = kitti
    damaged = list(images)
    damaged[GLITCH] = images[GLITCH - 1]
    output = glitch_then_compare(kitti, clean_run, damaged, times, "duplicate")
    positions = output.trajectory.positions
    np.testing.assert_allclose(positions[GLITCH], positions[GLITCH - 1])


def test_ten_frame_standstill(kitti, clean_run):
    images, _, camera, _ = kitti
    still = images[:GLITCH] + [images[GLITCH]] * 11 + images[GLITCH + 1 :]
    still_times = np.arange(len(still)) * 0.1
    output = run(still, still_times, camera)
    reasons = flagged(output)
    assert sorted(reasons) == list(range(GLITCH + 1, GLITCH + 11))
    positions = output.trajectory.positions
    assert np.ptp(positions[GLITCH : GLITCH + 11], axis=0).max() < 1e-9
    assert np.all(np.isfinite(positions))
    assert np.linalg.norm(positions[-1] - positions[GLITCH]) > 0


def test_sudden_ninety_degree_rotation(kitti, clean_run):
    images, times, _, _ = kitti
    damaged = list(images)
    height, width = images[GLITCH].shape
    rotated = cv2.rotate(images[GLITCH], cv2.ROTATE_90_CLOCKWISE)
    damaged[GLITCH] = cv2.resize(rotated, (width, height))
    output = glitch_then_compare(kitti, clean_run, damaged, times, "tracking-lost")
    cosine = direction_of_travel(output.trajectory) @ direction_of_travel(clean_run.trajectory)
    assert cosine > np.cos(np.radians(1.0))


def test_long_blackout_reinitialises_and_keeps_going(kitti, clean_run):
    images, times, camera, _ = kitti
    damaged = [np.zeros_like(im) if GLITCH <= i < GLITCH + 5 else im for i, im in enumerate(images)]
    output = run(damaged, times, camera)
    reasons = flagged(output)
    assert all("blank" in reasons[i] for i in range(GLITCH, GLITCH + 5))
    assert any("reinitialised" in r for r in reasons.values())
    assert output.stats.initialisations == 2
    assert np.all(np.isfinite(output.trajectory.positions))
    cosine = direction_of_travel(output.trajectory) @ direction_of_travel(clean_run.trajectory)
    assert cosine > np.cos(np.radians(2.0))
