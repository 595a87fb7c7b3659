"""Window bundle adjustment on exact synthetic scenes."""

from __future__ import annotations

import signal
import subprocess
import sys

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from vo_doppler.vo.geometry import camera_center, invert_pose, make_pose, project
from vo_doppler.vo.window_ba import BundleProblem, bundle_adjust

K = np.array([[500.0, 0.0, 320.0], [0.0, 500.0, 240.0], [0.0, 0.0, 1.0]])


def synthetic_problem(seed: int, n_frames: int = 30, n_points: int = 300, noise_px: float = 0.0):
    rng = np.random.default_rng(seed)
    poses_wc = []
    for f in range(n_frames):
        R = Rotation.from_euler("y", 0.02 * f).as_matrix()
        poses_wc.append(make_pose(R, [0.3 * np.sin(0.2 * f), 0.05 * f, 0.8 * f]))
    poses_cw = invert_pose(np.array(poses_wc))
    points = np.column_stack(
        [rng.uniform(-15, 15, n_points), rng.uniform(-4, 3, n_points), rng.uniform(8, 60, n_points)]
    )
    obs_f, obs_p, obs_uv = [], [], []
    for f in range(n_frames):
        uv = project(K, poses_cw[f], points)
        depth = (poses_cw[f][:3, :3] @ points.T).T[:, 2] + poses_cw[f][2, 3]
        seen = (depth > 1) & (uv[:, 0] > 0) & (uv[:, 0] < 640) & (uv[:, 1] > 0) & (uv[:, 1] < 480)
        obs_f.append(np.full(seen.sum(), f))
        obs_p.append(np.flatnonzero(seen))
        obs_uv.append(uv[seen] + rng.normal(0, noise_px, (seen.sum(), 2)))
    problem = BundleProblem(
        poses_cw, points, np.concatenate(obs_f), np.concatenate(obs_p), np.concatenate(obs_uv), 2
    )
    return problem


def perturbed(problem: BundleProblem, seed: int) -> BundleProblem:
    rng = np.random.default_rng(seed)
    poses = problem.poses_cw.copy()
    for f in range(problem.n_fixed, len(poses)):
        delta = make_pose(
            Rotation.from_rotvec(rng.normal(0, 0.002, 3)).as_matrix(), rng.normal(0, 0.05, 3)
        )
        poses[f] = delta @ poses[f]
    points = problem.points + rng.normal(0, 0.1, problem.points.shape)
    return BundleProblem(
        poses, points, problem.obs_frame, problem.obs_point, problem.obs_uv, problem.n_fixed
    )


@pytest.mark.parametrize("seed", [0, 1])
def test_noise_free_window_recovers_poses(seed):
    truth = synthetic_problem(seed)
    start = perturbed(truth, seed + 10)
    result = bundle_adjust(K, start, max_iterations=100, loss_scale_px=None)
    assert result.converged and result.iterations > 0
    assert result.initial_rms_px > 1.0
    assert result.final_rms_px < 1e-6
    centres = camera_center(result.poses_cw)[..., 0]
    true_centres = camera_center(truth.poses_cw)[..., 0]
    span = np.linalg.norm(true_centres[-1] - true_centres[0])
    assert np.max(np.linalg.norm(centres - true_centres, axis=1)) / span < 1e-6
    np.testing.assert_allclose(result.poses_cw[:, :3, :3], truth.poses_cw[:, :3, :3], atol=1e-7)


def test_noisy_window_residual_matches_injected_noise():
    sigma = 0.5
    truth = synthetic_problem(3, noise_px=sigma)
    result = bundle_adjust(K, perturbed(truth, 4), max_iterations=100, loss_scale_px=None)
    n_obs = len(truth.obs_uv)
    n_params = 6 * (len(truth.poses_cw) - 2) + 3 * len(truth.points)
    expected_rms = sigma * np.sqrt(2.0 * (1.0 - n_params / (2.0 * n_obs)))
    assert result.final_rms_px == pytest.approx(expected_rms, rel=0.05)


def test_importing_the_bundle_adjustment_leaves_sigterm_to_python():
    """pycolmap's glog handler on SIGTERM deadlocks a process terminated inside malloc: after the
    import the default action (end the process, status -SIGTERM) is back."""
    code = (
        "import os, signal\n"
        "import vo_doppler.vo.window_ba\n"
        "status = open('/proc/self/status').read().split('SigCgt:')[1]\n"
        "caught = int(status.split()[0], 16)\n"
        "print(bool(caught & (1 << (signal.SIGTERM - 1))))\n"
        "os.kill(os.getpid(), signal.SIGTERM)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.stdout.split() == ["False"]
    assert done.returncode == -signal.SIGTERM
