"""Fixed-lag window adjustment: solved at every n-th keyframe, as accurate on a rendered drive."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.eval.metrics import evaluate
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.sim.vo_sequence import simulate_vo
from vo_doppler.vo.batch import run_visual_odometry
from vo_doppler.vo.config import VoConfig

CAMERA_UP = np.array([0.0, -1.0, 0.0])


@pytest.fixture(scope="module")
def drive():
    return simulate_vo(duration_s=9.0, fps=10.0, seed=5)


@pytest.mark.parametrize("every", [1, 3])
def test_window_is_adjusted_at_every_nth_keyframe(drive, every):
    plan = drive.plan
    truth = Trajectory.from_matrices(plan.times, plan.T_first_camera)
    steps = np.linalg.norm(np.diff(truth.positions, axis=0), axis=1) / np.diff(plan.times)
    speed = (plan.times, np.r_[steps[0], steps])
    config = VoConfig(ba_every_keyframes=every)
    output = run_visual_odometry(list(drive.images), plan.times, plan.camera, config, speed)
    stats = output.stats
    # The first solve needs three measured frames; after it, one per ``every`` keyframes.
    assert stats.keyframes > 10
    assert stats.keyframes // every - 1 <= stats.ba_runs <= stats.keyframes // every
    assert stats.reprojection_rms_px < 1.0
    errors = evaluate(output.trajectory, truth, "start", CAMERA_UP)
    assert errors.final_drift_pct < 1.0
    assert abs(errors.end_yaw_error_deg) < 0.5
