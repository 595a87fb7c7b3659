"""The low-cost chain ([KZ]) measured against a reference trajectory: heading runs with a
chosen ε0 window, the per-block error of a block-mean bias, the scatter of raw and reconstructed
GPS fixes, and the time offset between fixes and reference.

``truth`` is a reference track with ``t`` (s), ``yaw`` and ``body_yaw`` (rad, CCW from east,
unwrapped), ``lat``/``lon`` (rad) and ``height`` (m); ``fixes`` a GPS fix series with ``t``,
``lat``, ``lon`` and ``as_tuple()``.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.spatial import cKDTree

from vo_doppler.geo import EnuFrame
from vo_doppler.lowcost.gps_reconstruction import reconstruct_track
from vo_doppler.lowcost.pipeline import DeadReckonConfig, Reference, run_deadreckon
from vo_doppler.model.timeseries import cumulative_integral, time_grid


def heading_run(truth, fixes, gyro, can, window_s: float, k: float | None, body: bool = False):
    """The chain with ε0 over the first ``window_s`` seconds of the common span, against the
    reference's course (or its body yaw with ``body``)."""
    start = max(gyro[0][0], can[0][0], fixes.t[0], truth.t[0])
    config = DeadReckonConfig(
        k=k,
        tau_s=window_s,
        standstill_s=(start, start + window_s),
        window_is_standstill=False,
        drift_window_s=0.0,
    )
    if body:
        reference = Reference(truth.t, truth.body_yaw, "global_pose body yaw")
    else:
        reference = Reference(truth.t, truth.yaw, "global_pose course")
    return run_deadreckon(gyro, can, fixes.as_tuple(), config, reference=reference)


def block_rate_errors(t_rate, rate, truth, block_s: float = 5.0) -> np.ndarray:
    """(sensor − truth) heading change per block divided by its length (rad/s): the error of a
    block-mean ε0 taken there."""
    heading = cumulative_integral(t_rate, rate)
    edges = time_grid(max(t_rate[0], truth.t[0]), min(t_rate[-1], truth.t[-1]) - block_s, block_s)
    return np.array(
        [
            (
                np.interp(a + block_s, t_rate, heading)
                - np.interp(a, t_rate, heading)
                - np.interp(a + block_s, truth.t, truth.yaw)
                + np.interp(a, truth.t, truth.yaw)
            )
            / block_s
            for a in edges
        ]
    )


def scatter_metrics(enu_xy: np.ndarray, truth_xy: np.ndarray, tree: cKDTree) -> dict:
    """Errors of points against time-matched truth, and their cross-track distance to the path."""
    error = enu_xy - truth_xy
    cross, _ = tree.query(enu_xy)
    jitter = np.diff(error, n=2, axis=0)
    return {
        "rms_m": float(np.sqrt(np.mean(np.sum(error**2, axis=1)))),
        "std_about_mean_m": float(np.sqrt(np.mean(np.sum((error - error.mean(0)) ** 2, axis=1)))),
        "cross_track_rms_m": float(np.sqrt(np.mean(cross**2))),
        "jitter_rms_m": float(np.sqrt(np.mean(np.sum(jitter**2, axis=1)))),
    }


def gps_scatter(truth, fixes, downsamples, cluster_m):
    """Scatter of the raw fixes and of the fixes reconstructed with each M in ``downsamples``
    against the time-matched reference (ENU at the reference's start)."""
    frame = EnuFrame(float(truth.lat[0]), float(truth.lon[0]), float(truth.height[0]))
    truth_enu = frame.geodetic_to_enu(truth.lat, truth.lon, truth.height)[:, :2]
    inside = (fixes.t >= truth.t[0]) & (fixes.t <= truth.t[-1])
    t = fixes.t[inside]
    at_t = np.column_stack([np.interp(t, truth.t, truth_enu[:, i]) for i in range(2)])
    fine_t = np.linspace(truth.t[0], truth.t[-1], 20 * len(truth.t))
    dense = np.column_stack([np.interp(fine_t, truth.t, truth_enu[:, i]) for i in range(2)])
    tree = cKDTree(dense)
    raw = frame.geodetic_to_enu(fixes.lat[inside], fixes.lon[inside], 0.0)[:, :2]
    results = {"raw": scatter_metrics(raw, at_t, tree)}
    tracks = {}
    for m in downsamples:
        track = reconstruct_track(t, fixes.lat[inside], fixes.lon[inside], m, cluster_m)
        xy = frame.geodetic_to_enu(track.lat, track.lon, 0.0)[:, :2]
        results[f"reconstructed M={m}"] = scatter_metrics(xy, at_t, tree) | {
            "kept": len(track.kept)
        }
        tracks[m] = xy
    return results, (t, at_t), raw, tracks


def fitted_time_offset(truth, fixes) -> float:
    """Time shift (s) added to the fix times that minimises their RMS distance to the truth at
    the shifted times: the offset between the two time bases (an evaluation alignment, like
    associating timestamps)."""
    frame = EnuFrame(float(truth.lat[0]), float(truth.lon[0]), float(truth.height[0]))
    truth_enu = frame.geodetic_to_enu(truth.lat, truth.lon, truth.height)[:, :2]
    inside = (fixes.t >= truth.t[0] + 1.0) & (fixes.t <= truth.t[-1] - 1.0)
    fix_enu = frame.geodetic_to_enu(fixes.lat[inside], fixes.lon[inside], 0.0)[:, :2]

    def rms(shift: float) -> float:
        t = fixes.t[inside] + shift
        at = np.column_stack([np.interp(t, truth.t, truth_enu[:, i]) for i in range(2)])
        return float(np.sqrt(np.mean(np.sum((fix_enu - at) ** 2, axis=1))))

    return float(minimize_scalar(rms, bounds=(-1.0, 1.0), method="bounded").x)
