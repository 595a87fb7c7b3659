"""Trajectory error per 100 m of path, the figure of the seed's evaluation.

For every window of the path that is 100 m long on the ground truth, the estimate is
translated (not rotated) so that it coincides with the truth at the window's start; the
error is the position difference at the window's end. Mean and maximum over all windows are
reported in metres per 100 m. Paths shorter than the window use the whole path and scale the
error to 100 m; paths shorter than :data:`MIN_PATH_M` give no figure (``None``): dividing by a
near-zero distance turns centimetres of noise into any number. ``horizontal=True`` measures
the error in the x–y plane only (ENU east/north): the figure of a heading method for ground
vehicles, blind to a VO's height drift.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.model.trajectory import Trajectory

MIN_PATH_M = 5.0
"""Shortest ground-truth path (m) on which figures per distance (error per 100 m, KITTI segment
errors, drift in % of the path) are computed: below it a few centimetres of position noise,
divided by the distance, reads as metres per 100 m."""


def too_short_for_distance_figures(path_length_m: float) -> str | None:
    """Why figures per distance are not available on a path of ``path_length_m``, or None."""
    if path_length_m >= MIN_PATH_M:
        return None
    return (
        f"the ground-truth path is {path_length_m:.1f} m long, shorter than the {MIN_PATH_M:.0f} m "
        "that figures per distance (error per 100 m, KITTI segment errors, drift in % of the "
        "path) need: they are not available"
    )


@dataclass
class ErrorPerDistance:
    window_m: float
    mean_m_per_100m: float | None
    """None on a path shorter than :data:`MIN_PATH_M` (no window)."""
    max_m_per_100m: float | None
    n_windows: int
    errors_m: np.ndarray
    """Error at the end of each window (m), in window order."""
    start_distance_m: np.ndarray


def error_per_100m(
    estimate: Trajectory,
    truth: Trajectory,
    window_m: float = 100.0,
    step_m: float = 1.0,
    horizontal: bool = False,
) -> ErrorPerDistance:
    """Error growth over every ``window_m`` stretch, windows starting every ``step_m`` metres.

    ``estimate`` and ``truth`` must have matching rows (associate them by time first).
    """
    if len(estimate) != len(truth):
        raise ValueError(f"estimate has {len(estimate)} poses, ground truth {len(truth)}")
    distance = truth.cumulative_distance()
    total = float(distance[-1]) if len(distance) else 0.0
    if too_short_for_distance_figures(total):
        empty = np.zeros(0)
        return ErrorPerDistance(window_m, None, None, 0, empty, empty)
    scale = 1.0
    if total < window_m:
        scale = window_m / total
        window_m = total
    start_marks = np.arange(0.0, total - window_m + 1e-9, step_m)
    starts = np.searchsorted(distance, start_marks, side="left")
    ends = np.searchsorted(distance, distance[starts] + window_m - 1e-9, side="left")
    keep = ends < len(distance)
    starts, ends = starts[keep], ends[keep]
    est_delta = estimate.positions[ends] - estimate.positions[starts]
    gt_delta = truth.positions[ends] - truth.positions[starts]
    axes = 2 if horizontal else 3
    errors = np.linalg.norm((est_delta - gt_delta)[:, :axes], axis=1) * scale
    return ErrorPerDistance(
        window_m=window_m,
        mean_m_per_100m=float(errors.mean()) if errors.size else None,
        max_m_per_100m=float(errors.max()) if errors.size else None,
        n_windows=int(errors.size),
        errors_m=errors,
        start_distance_m=distance[starts],
    )
