"""Side-by-side evaluation of the pipelines' vehicle trajectories against ground truth:
error per 100 m, KITTI segment errors, heading RMSE and heading availability."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from vo_doppler.eval.metrics import evaluate
from vo_doppler.eval.per_distance import ErrorPerDistance, error_per_100m
from vo_doppler.geo import wrap_angle, yaw_of
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.trajectory import Trajectory

PIPELINE_LABELS = {
    "vo": "VO alone",
    "vo_gps_conv": "VO + GPS (conventional)",
    "vo_gps_tc": "VO + GPS (tightly coupled)",
    "dr": "wheel + gyro DR alone",
    "dr_gps_conv": "wheel + gyro DR + GPS (conventional)",
    "dr_gps_tc": "wheel + gyro DR + GPS (tightly coupled)",
}
UNCORRECTED = ("vo", "dr")
"""Pipelines without an absolute heading: evaluated from the truth's initial heading."""


@dataclass
class PipelineErrors:
    """``error_per_100m_*`` are horizontal (east/north); ``error_per_100m_3d_m`` adds height."""

    error_per_100m_m: float
    error_per_100m_max_m: float
    error_per_100m_3d_m: float
    kitti_translation_pct: float
    kitti_rotation_deg_per_100m: float
    heading_rmse_deg: float
    heading_availability: float
    final_position_error_m: float
    path_length_m: float

    def to_dict(self) -> dict:
        return asdict(self)


def truth_at(truth: Trajectory, t: np.ndarray) -> tuple[Trajectory, np.ndarray]:
    """Ground truth interpolated at times ``t`` (linear positions, slerp rotations) and the mask
    of the times inside the ground truth's span."""
    inside = (t >= truth.t[0]) & (t <= truth.t[-1])
    tq = t[inside]
    positions = np.column_stack([np.interp(tq, truth.t, truth.positions[:, k]) for k in range(3)])
    rotations = Slerp(truth.t, truth.orientations)(tq)
    return Trajectory(tq, positions, rotations), inside


def heading_rmse_deg(estimate: Trajectory, truth: Trajectory) -> float:
    """RMS of the yaw difference (deg) between matched vehicle poses."""
    diff = wrap_angle(
        yaw_of(estimate.orientations.as_matrix()) - yaw_of(truth.orientations.as_matrix())
    )
    return float(np.degrees(np.sqrt(np.mean(diff**2))))


def evaluate_trajectory(
    estimate: Trajectory, truth: Trajectory, availability: float
) -> tuple[PipelineErrors, ErrorPerDistance]:
    matched_truth, inside = truth_at(truth, estimate.t)
    matched = estimate.subset(np.flatnonzero(inside))
    per_100m = error_per_100m(matched, matched_truth, horizontal=True)
    per_100m_3d = error_per_100m(matched, matched_truth)
    kitti = evaluate(matched, matched_truth, "start")
    errors = PipelineErrors(
        error_per_100m_m=per_100m.mean_m_per_100m,
        error_per_100m_max_m=per_100m.max_m_per_100m,
        error_per_100m_3d_m=per_100m_3d.mean_m_per_100m,
        kitti_translation_pct=kitti.mean_translation_pct,
        kitti_rotation_deg_per_100m=kitti.mean_rotation_deg_per_100m,
        heading_rmse_deg=heading_rmse_deg(matched, matched_truth),
        heading_availability=availability,
        final_position_error_m=float(
            np.linalg.norm(matched.positions[-1, :2] - matched_truth.positions[-1, :2])
        ),
        path_length_m=matched_truth.path_length,
    )
    return errors, per_100m


def align_start_to_truth(estimate: Trajectory, truth: Trajectory) -> Trajectory:
    """Translate the estimate so that its first position is the truth's at that time."""
    start, _ = truth_at(truth, estimate.t[:1])
    return estimate.transformed(np.eye(3), start.positions[0] - estimate.positions[0])


def with_initial_heading(estimate: Trajectory, truth: Trajectory) -> Trajectory:
    """Rotate the estimate about its start so its first yaw equals the truth's there."""
    start, _ = truth_at(truth, estimate.t[:1])
    turn = float(
        wrap_angle(
            yaw_of(start.orientations.as_matrix())[0]
            - yaw_of(estimate.orientations[:1].as_matrix())[0]
        )
    )
    rotation = Rotation.from_euler("z", turn).as_matrix()
    origin = estimate.positions[0]
    return estimate.transformed(rotation, origin - rotation @ origin)


def heading_availability(table: HeadingTable, tc_usable: np.ndarray) -> dict[str, float]:
    """Fraction of GNSS epochs whose absolute heading each pipeline could use."""
    tc = float(np.mean(tc_usable))
    conventional = float(np.mean(table.published_conventional[0]))
    return {
        "vo": 0.0,
        "vo_gps_conv": conventional,
        "vo_gps_tc": tc,
        "dr": 0.0,
        "dr_gps_conv": conventional,
        "dr_gps_tc": tc,
    }


def evaluate_pipelines(
    trajectories: dict[str, Trajectory],
    table: HeadingTable,
    tc_usable: np.ndarray,
    truth: Trajectory,
) -> tuple[dict[str, PipelineErrors], dict[str, ErrorPerDistance], dict[str, Trajectory]]:
    """Errors of every pipeline, its per-window errors, and the trajectories as evaluated:
    translated to the truth's start, the uncorrected ones also turned to the truth's initial
    heading."""
    availability = heading_availability(table, tc_usable)
    errors, per_100m, shown = {}, {}, {}
    for name, trajectory in trajectories.items():
        estimate = with_initial_heading(trajectory, truth) if name in UNCORRECTED else trajectory
        shown[name] = align_start_to_truth(estimate, truth)
        errors[name], per_100m[name] = evaluate_trajectory(
            shown[name], truth, availability.get(name, float("nan"))
        )
    return errors, per_100m, shown
