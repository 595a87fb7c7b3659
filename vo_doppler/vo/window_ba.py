"""Sliding-window bundle adjustment: Levenberg–Marquardt over poses and points (Ceres, pycolmap).

Minimises Σ ρ(‖π(K, T_cw,f · X_p) − u_fp‖²) over the window's camera poses T_cw (world→camera)
and 3-D points X_p, with a robust loss ρ; the oldest ``n_fixed`` poses are held constant, which
fixes the gauge (one pose) and the scale (two poses).
"""

from __future__ import annotations

import signal
import threading
from dataclasses import dataclass

import numpy as np
import pycolmap

from vo_doppler.vo.geometry import project


def _give_sigterm_back_to_python() -> None:
    """Importing pycolmap installs glog's failure-signal handler, SIGTERM included. That handler
    is not async-signal-safe (it formats a backtrace, which allocates), so a process terminated
    while inside malloc, e.g. a batch worker ended by its pool, deadlocks instead of ending.
    Python's own table still holds the handler it had before the import; it is installed again.
    Only the main thread may set handlers, and the VO runs there."""
    handler = signal.getsignal(signal.SIGTERM)
    if handler is not None and threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, handler)


_give_sigterm_back_to_python()


@dataclass
class BundleProblem:
    """Poses (F, 4, 4) world→camera, points (P, 3), observations as parallel index/pixel arrays."""

    poses_cw: np.ndarray
    points: np.ndarray
    obs_frame: np.ndarray
    obs_point: np.ndarray
    obs_uv: np.ndarray
    n_fixed: int = 1


@dataclass
class BundleResult:
    poses_cw: np.ndarray
    points: np.ndarray
    iterations: int
    initial_rms_px: float
    final_rms_px: float
    converged: bool


def reprojection_residuals(K: np.ndarray, problem: BundleProblem, poses_cw, points) -> np.ndarray:
    """Pixel residuals (M, 2) of every observation for the given poses and points."""
    predicted = project(K, poses_cw[problem.obs_frame], points[problem.obs_point])
    return predicted - problem.obs_uv


def _rms(residuals: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.sum(residuals**2, axis=1)))) if len(residuals) else 0.0


def _add_points(
    reconstruction: pycolmap.Reconstruction, problem: BundleProblem, index_in_image: np.ndarray
) -> np.ndarray:
    """Add every point seen at least twice with its track; its point3D id, else −1.

    The per-observation image ids and keypoint indices are listed once, sorted by point, so the
    only Python work per observation is the ``add_element`` call itself.
    """
    order = np.argsort(problem.obs_point, kind="stable")
    counts = np.bincount(problem.obs_point, minlength=len(problem.points))
    ends = np.cumsum(counts).tolist()
    image_ids = (problem.obs_frame[order] + 1).tolist()
    keypoints = index_in_image[order].tolist()
    xyz = problem.points
    point_ids = np.full(len(problem.points), -1, dtype=np.int64)
    for p in np.flatnonzero(counts >= 2).tolist():
        track = pycolmap.Track()
        for k in range(ends[p] - counts[p], ends[p]):
            track.add_element(image_ids[k], keypoints[k])
        point_ids[p] = reconstruction.add_point3D(xyz[p], track)
    return point_ids


def bundle_adjust(
    K: np.ndarray,
    problem: BundleProblem,
    max_iterations: int = 20,
    loss_scale_px: float | None = 1.5,
    width: int = 2000,
    height: int = 2000,
    function_tolerance: float = 1e-10,
    num_threads: int = 1,
) -> BundleResult:
    """Refine the window's poses and points jointly (Levenberg–Marquardt, Ceres via pycolmap).

    ``loss_scale_px`` selects a Cauchy loss of that scale; ``None`` gives plain least squares.
    Iterations stop at ``max_iterations`` or when the relative cost decrease falls below
    ``function_tolerance``.
    """
    n_frames = len(problem.poses_cw)
    reconstruction = pycolmap.Reconstruction()
    camera = pycolmap.Camera(
        model="PINHOLE",
        width=width,
        height=height,
        params=[K[0, 0], K[1, 1], K[0, 2], K[1, 2]],
        camera_id=1,
    )
    reconstruction.add_camera_with_trivial_rig(camera)
    order = np.argsort(problem.obs_frame, kind="stable")
    starts = np.searchsorted(problem.obs_frame[order], np.arange(n_frames + 1))
    index_in_image = np.empty(len(order), dtype=np.int64)
    index_in_image[order] = np.arange(len(order)) - np.repeat(starts[:-1], np.diff(starts))
    for f in range(n_frames):
        image = pycolmap.Image(
            name=str(f),
            keypoints=problem.obs_uv[order[starts[f] : starts[f + 1]]],
            camera_id=1,
            image_id=f + 1,
        )
        reconstruction.add_image_with_trivial_frame(
            image, pycolmap.Rigid3d(problem.poses_cw[f][:3, :4])
        )
    point_ids = _add_points(reconstruction, problem, index_in_image)
    used = point_ids[problem.obs_point] >= 0
    initial_rms = _rms(reprojection_residuals(K, problem, problem.poses_cw, problem.points)[used])
    options = pycolmap.BundleAdjustmentOptions()
    options.print_summary = False
    options.refine_focal_length = False
    options.refine_principal_point = False
    options.refine_extra_params = False
    if loss_scale_px is not None:
        options.ceres.loss_function_type = pycolmap.LossFunctionType.CAUCHY
        options.ceres.loss_function_scale = loss_scale_px
    options.ceres.solver_options.max_num_iterations = max_iterations
    options.ceres.solver_options.num_threads = num_threads
    options.ceres.min_num_residuals_for_cpu_multi_threading = 2000
    options.ceres.solver_options.function_tolerance = function_tolerance
    options.ceres.solver_options.parameter_tolerance = 1e-12
    options.ceres.solver_options.gradient_tolerance = 1e-12
    config = pycolmap.BundleAdjustmentConfig()
    for f in range(n_frames):
        config.add_image(f + 1)
    config.set_constant_cam_intrinsics(1)
    for f in range(min(problem.n_fixed, n_frames)):
        config.set_constant_rig_from_world_pose(f + 1)
    if problem.n_fixed == 1:
        config.fix_gauge(pycolmap.BundleAdjustmentGauge.TWO_CAMS_FROM_WORLD)
    adjuster = pycolmap.create_default_bundle_adjuster(options, config, reconstruction)
    summary = adjuster.solve()
    ceres_summary = summary.ceres_summary
    poses = np.array(
        [
            np.vstack([reconstruction.image(f + 1).cam_from_world().matrix(), [0, 0, 0, 1]])
            for f in range(n_frames)
        ]
    )
    points = problem.points.copy()
    tracked = np.flatnonzero(point_ids >= 0)
    if len(tracked):
        points[tracked] = [reconstruction.point3D(i).xyz for i in point_ids[tracked].tolist()]
    final_rms = _rms(reprojection_residuals(K, problem, poses, points)[used])
    iterations = ceres_summary.num_successful_steps + ceres_summary.num_unsuccessful_steps
    return BundleResult(
        poses, points, int(iterations), initial_rms, final_rms, bool(summary.is_solution_usable())
    )
