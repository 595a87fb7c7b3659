"""Batch helper: run the streaming VO over a whole image sequence and make it metric."""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np

from vo_doppler.model.camera import Camera
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.model.visual_odometry import VoOutput
from vo_doppler.vo.config import VoConfig
from vo_doppler.vo.odometry import VisualOdometry
from vo_doppler.vo.scale import metric_positions

MIN_VO_FRAMES = 2
"""Fewest decoded images a VO trajectory needs: a motion takes two views."""


def run_visual_odometry(
    images: Iterable[np.ndarray | None],
    times: np.ndarray,
    camera: Camera,
    config: VoConfig | None = None,
    speed: tuple[np.ndarray, np.ndarray] | None = None,
    on_frame: Callable[[int], None] | None = None,
) -> VoOutput:
    """Process every image (``None`` = unreadable) and return one pose per image.

    ``speed`` is ``(t, speed_mps)`` on the same clock as ``times``; with it the trajectory is
    metric (step lengths from travelled distance), without it the scale is arbitrary.
    """
    odometry = VisualOdometry(camera, config)
    for index, (image, t) in enumerate(zip(images, times, strict=True)):
        odometry.process(image, float(t))
        if on_frame is not None:
            on_frame(index)
    result = odometry.finish()
    poses = result.poses_wc.copy()
    if speed is not None:
        poses[:, :3, 3] = metric_positions(poses, result.t, speed[0], speed[1])
    return VoOutput(Trajectory.from_matrices(result.t, poses), result.stats, speed is not None)
