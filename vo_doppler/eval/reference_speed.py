"""A speed signal from a ground-truth trajectory (e.g. KITTI poses with their times.txt): the
stand-in for wheel speed that gives a monocular VO its metric scale when a recording has no
wheel speed."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory


def speed_from_poses(truth: Trajectory, source: str | Path | None = None) -> SensorSeries:
    """Speed (m/s) at every pose whose trapezoidal integral between consecutive poses is the
    true step length: v₀ = s₀/Δt₀, vᵢ = 2 sᵢ₋₁/Δtᵢ₋₁ − vᵢ₋₁ (what the VO's scale integrates,
    :mod:`vo_doppler.vo.scale`). Where that recursion would turn negative, the plain step rate
    sᵢ/Δtᵢ is used instead (first sample repeated). Fewer than two poses, or times that do
    not increase, are an :class:`InputError` naming ``source`` (the poses' file) and the pose."""
    if len(truth) < 2:
        raise InputError(f"need at least two poses for a speed, got {len(truth)}", source)
    dt = np.diff(truth.t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0)) + 1
        raise InputError(
            f"pose times must increase, but pose {i} (t = {truth.t[i]:.6f} s) follows "
            f"t = {truth.t[i - 1]:.6f} s",
            source,
        )
    steps = np.linalg.norm(np.diff(truth.positions, axis=0), axis=1)
    speed = np.empty(len(truth))
    speed[0] = steps[0] / dt[0]
    for i in range(1, len(truth)):
        speed[i] = 2.0 * steps[i - 1] / dt[i - 1] - speed[i - 1]
    if np.any(speed < 0):
        speed = np.r_[steps[0] / dt[0], steps / dt]
    return SensorSeries(truth.t.copy(), speed, "speed", "m/s")
