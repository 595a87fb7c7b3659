"""The VO on rendered synthetic drives (no real data needed): metric accuracy through a turn."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.eval.metrics import evaluate
from vo_doppler.model.camera import Camera
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.sim.vo_sequence import simulate_vo
from vo_doppler.vo.baseline import FrameToFrameVO
from vo_doppler.vo.batch import run_visual_odometry
from vo_doppler.vo.config import VoConfig
from vo_doppler.vo.odometry import RECENT_FRAMES, VisualOdometry, _FinishedFrames, _Frame
from vo_doppler.vo.scale import metric_positions
from vo_doppler.vo.tracker import TrackedFeatures

CAMERA_UP = np.array([0.0, -1.0, 0.0])


@pytest.fixture(scope="module")
def drive():
    return simulate_vo(duration_s=14.0, fps=10.0, seed=3)


@pytest.mark.slow
def test_metric_vo_follows_a_rendered_drive(drive):
    plan = drive.plan
    truth = Trajectory.from_matrices(plan.times, plan.T_first_camera)
    steps = np.linalg.norm(np.diff(truth.positions, axis=0), axis=1) / np.diff(plan.times)
    speed = (plan.times, np.r_[steps[0], steps])
    output = run_visual_odometry(list(drive.images), plan.times, plan.camera, speed=speed)
    assert output.metric
    assert output.stats.flagged_frames == []
    assert output.stats.reprojection_rms_px < 1.0
    errors = evaluate(output.trajectory, truth, "start", CAMERA_UP)
    assert truth.path_length > 60.0
    assert errors.final_drift_pct < 1.0
    assert abs(errors.end_yaw_error_deg) < 0.5


@pytest.mark.slow
def test_unscaled_vo_is_declared_and_similar_up_to_scale(drive):
    plan = drive.plan
    truth = Trajectory.from_matrices(plan.times, plan.T_first_camera)
    output = run_visual_odometry(list(drive.images)[:40], plan.times[:40], plan.camera)
    assert not output.metric
    aligned = evaluate(output.trajectory, truth.subset(slice(0, 40)), "sim3", CAMERA_UP)
    assert aligned.ate_rmse_m < 0.01 * truth.subset(slice(0, 40)).path_length


@pytest.mark.slow
def test_streaming_rejects_times_that_do_not_increase(drive):
    vo = VisualOdometry(drive.plan.camera)
    vo.process(drive.images[0], 1.0)
    with pytest.raises(InputError, match=r"frame 1: time 1.0 is not after"):
        vo.process(drive.images[1], 1.0)
    with pytest.raises(InputError, match="frame 1: time nan"):
        vo.process(drive.images[1], float("nan"))
    assert vo.process(drive.images[1], 1.1).index == 1


def test_a_frame_of_another_size_than_the_calibration_is_an_error():
    """The VO checks every frame's size against the calibration's (issue 30: 1241×376 images
    with a 1226×370 calibration passed silently)."""
    odometry = VisualOdometry(Camera(707.0, 707.0, 601.9, 183.1, 1226, 370))
    image = np.zeros((376, 1241), np.uint8)
    with pytest.raises(InputError, match=r"frame 0: the images are 1241×376 px but the camera"):
        odometry.process(image, 0.0)


@pytest.mark.slow
def test_frame_to_frame_baseline_follows_a_straight_stretch(drive):
    plan = drive.plan
    truth = Trajectory.from_matrices(plan.times, plan.T_first_camera).subset(slice(0, 30))
    baseline = FrameToFrameVO(plan.camera.K)
    poses = np.array([baseline.process(image) for image in list(drive.images)[:30]])
    steps = np.linalg.norm(np.diff(truth.positions, axis=0), axis=1) / np.diff(truth.t)
    poses[:, :3, 3] = metric_positions(poses, truth.t, truth.t, np.r_[steps[0], steps])
    errors = evaluate(Trajectory.from_matrices(truth.t, poses), truth, "start", CAMERA_UP)
    assert errors.final_drift_pct < 3.0


@pytest.fixture(scope="module")
def short_drive():
    return simulate_vo(duration_s=9.0, fps=10.0, seed=5)


@pytest.mark.slow
@pytest.mark.parametrize("every", [1, 3])
def test_window_is_adjusted_at_every_nth_keyframe(short_drive, every):
    plan = short_drive.plan
    truth = Trajectory.from_matrices(plan.times, plan.T_first_camera)
    steps = np.linalg.norm(np.diff(truth.positions, axis=0), axis=1) / np.diff(plan.times)
    speed = (plan.times, np.r_[steps[0], steps])
    config = VoConfig(ba_every_keyframes=every)
    output = run_visual_odometry(list(short_drive.images), plan.times, plan.camera, config, speed)
    stats = output.stats
    # The first solve needs three measured frames; after it, one per ``every`` keyframes.
    assert stats.keyframes > 10
    assert stats.keyframes // every - 1 <= stats.ba_runs <= stats.keyframes // every
    assert stats.reprojection_rms_px < 1.0
    errors = evaluate(output.trajectory, truth, "start", CAMERA_UP)
    assert errors.final_drift_pct < 1.0
    assert abs(errors.end_yaw_error_deg) < 0.5


def test_finished_frames_keep_their_final_poses_in_a_few_bytes_each():
    """30 minutes at 15 frames per second: the frames that left the window take about 4 MiB
    (their time, pose and flags), where the frame objects took 22 MiB; a frame that stood still
    takes the final pose of the frame it stood still at, one without a measured pose and
    without a reason is flagged 'no-geometry', and the last few stay whole."""
    finished = _FinishedFrames()
    n = 27_000
    tracemalloc.start()
    try:
        for k in range(n):
            pose = np.eye(4)
            pose[0, 3] = k
            frame = _Frame(k, 0.1 * k, pose, TrackedFeatures.empty(), measured=k % 7 != 3)
            if k % 11 == 5:
                frame.flags.append("standstill")
                frame.still_of = finished.recent[-1]
            finished.add(frame)
        held = tracemalloc.get_traced_memory()[0]
    finally:
        tracemalloc.stop()
    assert held < 6 * 2**20
    assert finished.count == n and len(finished.recent) == RECENT_FRAMES
    np.testing.assert_array_equal(finished.t[:n], 0.1 * np.arange(n))
    expected = np.arange(n, dtype=float)
    expected[np.arange(n) % 11 == 5] -= 1.0
    np.testing.assert_array_equal(finished.T_cw[:n, 0, 3], expected)
    assert finished.flags[3] == ["no-geometry"] and finished.flags[5] == ["standstill"]
    assert finished.flags.keys() == {k for k in range(n) if k % 7 == 3 or k % 11 == 5}
