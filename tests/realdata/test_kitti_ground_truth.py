"""The KITTI 06 clip's ground-truth attitude: interpolated over frames 0–11, measured after.

This is why ``benchmarks/vo_kitti.py`` also reports its figures from frame 12 on."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.conftest import require_shared
from vo_doppler.eval.metrics import attitude_roughness_deg
from vo_doppler.io.trajectory import read_kitti
from vo_doppler.model.trajectory import Trajectory


def test_constant_rate_rotation_has_zero_roughness_and_a_kick_is_found():
    n = 20
    rotvec = np.outer(np.arange(n), [0.001, -0.004, 0.0005])
    rotvec[12] += [0.0, 0.002, 0.0]
    truth = Trajectory(np.arange(n) * 0.1, np.zeros((n, 3)), Rotation.from_rotvec(rotvec))
    roughness = attitude_roughness_deg(truth)
    assert roughness.shape == (n - 2,)
    kicked = {10, 11, 12}  # second differences touching frame 12 (index = frame − 1)
    for i, value in enumerate(roughness):
        if i in kicked:
            assert value > 0.05
        else:
            assert value == pytest.approx(0.0, abs=1e-9)


def test_kitti06_attitude_is_smooth_until_frame_11():
    truth = read_kitti(require_shared("kitti06_0000_0050/poses.txt"))
    roughness = attitude_roughness_deg(truth)
    interpolated, measured = roughness[:10], roughness[11:]  # frames 1–10 and 12–49
    assert interpolated.max() < 1e-3
    assert np.median(measured) > 1e-2
    assert np.sqrt(np.mean(measured**2)) > 30 * np.sqrt(np.mean(interpolated**2))
