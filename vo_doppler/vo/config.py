"""Settings of the monocular visual odometry, with defaults tuned on KITTI and the simulator."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class VoConfig:
    """Front-end, geometry and bundle-adjustment settings.

    Pixel thresholds are for images of roughly 1000 px width; they are used as given.
    """

    window_size: int = 20
    """Frames kept in the sliding bundle-adjustment window. 20 rather than 30: about a third
    fewer residuals per solve, and a VO that drifts less on the simulator's drives. Shorter
    windows drift less still with the VO alone, but the VO with the tightly coupled heading and
    the KITTI clip's final error then get worse, so 20 is kept
    (docs/benchmarks.md, "VO on KITTI", "The VO's settings")."""
    max_features: int = 600
    """Corners kept tracked; fewer made the sample's VO alone drift far more
    (docs/benchmarks.md, "VO on KITTI", "The VO's settings")."""
    grid_rows: int = 4
    grid_cols: int = 8
    min_corner_distance_px: int = 12
    corner_quality: float = 0.005
    replenish_below: float = 0.8
    """Detect new corners when fewer than this fraction of ``max_features`` are tracked."""
    klt_window_px: int = 15
    """KLT window (px); the KLT's cost goes with its area. A smaller window was worse on the KITTI
    clip and, with the tightly coupled heading, on most simulator drives
    (docs/benchmarks.md, "VO on KITTI", "The VO's settings")."""
    klt_levels: int = 3
    klt_epsilon_px: float = 0.01
    """KLT stop (px); a coarser stop made the sample's VO alone drift more
    (docs/benchmarks.md, "VO on KITTI", "The VO's settings")."""
    forward_backward_max_px: float = 0.7
    """Largest forward–backward distance of a kept track. The backward pass repeats the forward
    one in full (half of the KLT's CPU): each cheaper backward pass tried (a smaller window, one
    pyramid level fewer, starting at the original points with ``OPTFLOW_USE_INITIAL_FLOW``)
    made the sample's VO alone drift more
    (docs/benchmarks.md, "VO on KITTI", "The VO's settings")."""
    ransac_threshold_px: float = 1.0
    init_min_parallax_rad: float = np.radians(1.0)
    """Median parallax (rad) the two-view initialisation needs."""
    init_min_points: int = 60
    triangulation_min_parallax_rad: float = np.radians(1.0)
    """Parallax (rad) a new point needs to be triangulated."""
    max_reprojection_px: float = 2.0
    pnp_min_inliers: int = 25
    standstill_flow_px: float = 0.3
    """Median feature motion below this (px) means the camera did not move."""
    keyframe_flow_px: float = 25.0
    """A frame becomes a keyframe when the median flow since the last keyframe exceeds this."""
    keyframe_max_gap: int = 5
    """Frames after which a keyframe is made anyway; a longer gap made the sample's VO alone
    drift more (docs/benchmarks.md, "VO on KITTI", "The VO's settings")."""
    ba_every_keyframes: int = 2
    """The window is adjusted at every this many keyframes (a fixed lag), not at every one: each
    frame is adjusted about ``window_size`` / (this × the mean keyframe spacing) times. Every
    second keyframe halves the solves at the same accuracy as every one; every third drifted
    more, so 2 is kept (docs/benchmarks.md, "VO on KITTI", "The VO's settings")."""
    ba_max_iterations: int = 4
    """Levenberg–Marquardt iterations per window solve; fewer made the VO alone drift more on
    the sample and the simulator's seeds
    (docs/benchmarks.md, "VO on KITTI", "The VO's settings")."""
    ba_function_tolerance: float = 1e-5
    ba_threads: int = 1
    ba_loss_scale_px: float = 1.5
    ba_fixed_oldest: int = 2
    """Oldest window poses held constant: the gauge (and, with two, the scale) of the window."""
    min_texture_std_grey: float = 3.0
    """Images whose grey-level standard deviation is below this are treated as blank."""
