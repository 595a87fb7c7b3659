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
    """Frames kept in the sliding bundle-adjustment window. 20 rather than 30: 32 % fewer
    residuals per solve (8,014 against 11,796 on the sample; 69 against 114 ms of CPU per solve
    under load) and a VO that drifts less on the simulator's drives. VO alone, m per 100 m
    (``benchmarks/error_per_100m.py``), windows of 30/25/20/15 frames: sample 0.76/0.71/0.63/0.47,
    seed 0 1.54/1.30/1.04/0.89; 30/20 on seeds 1 and 2: 1.81/1.54 and 0.74/0.68 (VO + TC
    0.299/0.299, 0.185/0.183, 0.227/0.220, 0.141/0.139 on the sample and seeds 0-2; at 15 the
    sample's VO + TC was 0.313). KITTI 06 clip final error 0.484/0.485/0.483/0.489 m (ratio to
    the baseline 0.546/0.547/0.545/0.552, over the issue's 0.55 at 15). 17 frames: VO alone
    0.58/1.03/1.50/0.63 on the sample and seeds 0–2, but VO + TC 0.308/0.186/0.218/0.140, worse on
    the sample and seed 0 (KITTI 0.483 m, ratio 0.545): not taken."""
    max_features: int = 600
    """Corners kept tracked; 500 took the sample's VO alone (30-frame window) from 0.76 to 2.23 m
    per 100 m."""
    grid_rows: int = 4
    grid_cols: int = 8
    min_corner_distance_px: int = 12
    corner_quality: float = 0.005
    replenish_below: float = 0.8
    """Detect new corners when fewer than this fraction of ``max_features`` are tracked."""
    klt_window_px: int = 15
    """KLT window (px); the KLT's cost goes with its area. 13 with the 20-frame window: VO alone
    0.72/0.92/1.28/1.49 against 0.63/1.04/1.54/0.68 m per 100 m on the sample and seeds 0–2, VO + TC
    0.320/0.206/0.214/0.161 against 0.299/0.183/0.220/0.139, KITTI final-error ratio 0.58."""
    klt_levels: int = 3
    klt_epsilon_px: float = 0.01
    """KLT stop (px); 0.03 took the sample's VO alone from 0.76 to 0.96 m per 100 m."""
    forward_backward_max_px: float = 0.7
    """Largest forward–backward distance of a kept track. The backward pass repeats the forward
    one in full (half of the KLT's CPU); each cheaper backward pass tried took the sample's VO
    alone (30-frame window) from 0.76 m per 100 m to 1.0–1.1 m: a 9-px window 1.03, one pyramid
    level fewer 1.02, starting at the original points (``OPTFLOW_USE_INITIAL_FLOW``) with two
    levels 1.10."""
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
    """Frames after which a keyframe is made anyway; 6 took the sample's VO alone (30-frame
    window) from 0.76 to 0.82 m per 100 m."""
    ba_every_keyframes: int = 2
    """The window is adjusted at every this many keyframes (a fixed lag), not at every one: each
    frame is adjusted about ``window_size`` / (this × the mean keyframe spacing) times. Measured
    with 1/2/3: simulator drive 0.204/0.202/0.202 m per 100 m, KITTI 06 clip final error
    0.485/0.484/0.490 m, at 167/84/56 solves on the simulator drive. Re-measured with 3 on
    ``benchmarks/error_per_100m.py`` (VO alone, m per 100 m): window 30, sample 0.82 against 0.76;
    window 20, sample/seeds 0–2 0.69/1.09/1.76/0.68 against 0.63/1.04/1.54/0.68 (VO + TC
    0.314/0.186/0.223/0.149 against 0.299/0.183/0.220/0.139): kept at 2."""
    ba_max_iterations: int = 4
    """Levenberg–Marquardt iterations per window solve. 3 with the 20-frame window: VO alone
    0.67/1.07/1.76/0.79 against 0.63/1.04/1.54/0.68 m per 100 m on the sample and seeds 0–2."""
    ba_function_tolerance: float = 1e-5
    ba_threads: int = 1
    ba_loss_scale_px: float = 1.5
    ba_fixed_oldest: int = 2
    """Oldest window poses held constant: the gauge (and, with two, the scale) of the window."""
    min_texture_std_grey: float = 3.0
    """Images whose grey-level standard deviation is below this are treated as blank."""
