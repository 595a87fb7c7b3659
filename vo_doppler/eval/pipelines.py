"""Side-by-side evaluation of the pipelines' vehicle trajectories against ground truth:
error per 100 m, KITTI segment errors, heading RMSE and heading availability, over the time the
ground truth covers (a reference system often starts late or stops early)."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from vo_doppler.eval.metrics import Coverage, evaluate, time_coverage
from vo_doppler.eval.per_distance import (
    ErrorPerDistance,
    error_per_100m,
    too_short_for_distance_figures,
)
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
    """``error_per_100m_*`` are horizontal (east/north); ``error_per_100m_3d_m`` adds height.
    A figure per distance is ``None`` on a path too short for it
    (:func:`vo_doppler.eval.per_distance.too_short_for_distance_figures`)."""

    error_per_100m_m: float | None
    error_per_100m_max_m: float | None
    error_per_100m_3d_m: float | None
    kitti_translation_pct: float | None
    kitti_rotation_deg_per_100m: float | None
    heading_rmse_deg: float
    heading_availability: float
    final_position_error_m: float
    path_length_m: float
    coverage: Coverage | None = None
    """The part of the trajectory's time span inside the ground truth's (the part evaluated)."""

    def to_dict(self) -> dict:
        return asdict(self)


def truth_at(truth: Trajectory, t: np.ndarray) -> tuple[Trajectory, np.ndarray]:
    """Ground truth interpolated at times ``t`` (linear positions, slerp rotations)
    and the mask of the times inside the ground truth's span."""
    inside = (t >= truth.t[0]) & (t <= truth.t[-1])
    tq = t[inside]
    positions = np.column_stack([np.interp(tq, truth.t, truth.positions[:, k]) for k in range(3)])
    return Trajectory(tq, positions, _slerp_in_blocks(truth, tq)), inside


SLERP_BLOCK = 8192
"""Times interpolated by one :class:`~scipy.spatial.transform.Slerp`, built on the truth rows
around them only: one built on the whole truth holds a rotation vector and copies of the times
for each of its rows (a 30-min ground truth at 100 Hz has 180,000), once per pipeline
evaluated."""


def _slerp_in_blocks(truth: Trajectory, tq: np.ndarray) -> Rotation:
    """``Slerp(truth.t, truth.orientations)(tq)`` (``tq`` inside the truth's span)
    computed :data:`SLERP_BLOCK` times at a time on the truth rows from the one before each
    block's first time to the one after its last, which give every time the interval and
    fraction the whole truth gives it: the same rotations."""
    if tq.size == 0:
        return Rotation.from_quat(np.zeros((0, 4)))
    parts = []
    for k in range(0, tq.size, SLERP_BLOCK):
        block = tq[k : k + SLERP_BLOCK]
        first = max(int(np.searchsorted(truth.t, block.min())) - 1, 0)
        end = min(max(int(np.searchsorted(truth.t, block.max())) + 1, first + 2), len(truth))
        parts.append(Slerp(truth.t[first:end], truth.orientations[first:end])(block))
    return Rotation.concatenate(parts)


def heading_rmse_deg(estimate: Trajectory, truth: Trajectory) -> float:
    """RMS of the yaw difference (deg) between matched vehicle poses."""
    diff = wrap_angle(
        yaw_of(estimate.orientations.as_matrix()) - yaw_of(truth.orientations.as_matrix())
    )
    return float(np.degrees(np.sqrt(np.mean(diff**2))))


def evaluate_trajectory(
    estimate: Trajectory, truth: Trajectory, availability: float
) -> tuple[PipelineErrors, ErrorPerDistance]:
    """The errors of ``estimate`` over the times inside the ground truth's span (at least two
    of its poses must be: see :func:`overlap`)."""
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
        coverage=time_coverage(estimate.t, matched.t),
    )
    return errors, per_100m


def overlap(estimate: Trajectory, truth: Trajectory) -> np.ndarray:
    """Indices of the estimate's poses inside the ground truth's time span."""
    return np.flatnonzero((estimate.t >= truth.t[0]) & (estimate.t <= truth.t[-1]))


def align_start_to_truth(estimate: Trajectory, truth: Trajectory, first: int = 0) -> Trajectory:
    """Translate the estimate so that its position at pose ``first`` (the first inside the
    ground truth's span) is the truth's at that time."""
    start, _ = truth_at(truth, estimate.t[first : first + 1])
    return estimate.transformed(np.eye(3), start.positions[0] - estimate.positions[first])


def with_initial_heading(estimate: Trajectory, truth: Trajectory, first: int = 0) -> Trajectory:
    """Rotate the estimate about its pose ``first`` (the first inside the ground truth's span)
    so that its yaw there equals the truth's."""
    start, _ = truth_at(truth, estimate.t[first : first + 1])
    turn = float(
        wrap_angle(
            yaw_of(start.orientations.as_matrix())[0]
            - yaw_of(estimate.orientations[first : first + 1].as_matrix())[0]
        )
    )
    rotation = Rotation.from_euler("z", turn).as_matrix()
    origin = estimate.positions[first]
    return estimate.transformed(rotation, origin - rotation @ origin)


def epochs_within(t: np.ndarray, *spans: tuple[float, float] | None) -> np.ndarray:
    """Mask of the times ``t`` inside every one of ``spans`` ((first, last) s; None: no
    bound)."""
    inside = np.ones(len(t), dtype=bool)
    for span in spans:
        if span is not None:
            inside &= (t >= span[0]) & (t <= span[1])
    return inside


def heading_availability(
    table: HeadingTable | None,
    tc_usable: np.ndarray,
    trajectories: dict[str, Trajectory] | None = None,
    vehicle_span: tuple[float, float] | None = None,
) -> dict[str, float]:
    """Per pipeline, the share of the GNSS epochs where its absolute heading could be used that
    it did use: those inside its trajectory's time span (of ``trajectories``, when given) and
    inside ``vehicle_span`` (the vehicle signals' span, when given; the tightly coupled heading
    and the dead reckoning need them). NaN where no epoch could be; ``table`` None: a recording
    without GNSS, whose VO and dead reckoning use none."""
    if table is None:
        return {"vo": 0.0, "dr": 0.0}
    used = {
        "tc": np.asarray(tc_usable, dtype=bool),
        "conv": np.asarray(table.published_conventional[0], dtype=bool),
    }
    shares = {"vo": 0.0, "dr": 0.0}
    for base in ("vo", "dr"):
        for source in ("conv", "tc"):
            name = f"{base}_gps_{source}"
            track = (trajectories or {}).get(name)
            span = None if track is None or not len(track) else (track.t[0], track.t[-1])
            could = epochs_within(table.t, span, vehicle_span)
            shares[name] = float(np.mean(used[source][could])) if could.any() else float("nan")
    return shares


def evaluate_pipelines(
    trajectories: dict[str, Trajectory],
    table: HeadingTable | None,
    tc_usable: np.ndarray,
    truth: Trajectory,
    vehicle_span: tuple[float, float] | None = None,
) -> tuple[dict[str, PipelineErrors], dict[str, ErrorPerDistance], dict[str, Trajectory]]:
    """Errors of every pipeline, its per-window errors, and the trajectories as evaluated:
    translated to the truth at their first pose inside the truth's time span, the uncorrected
    ones also turned to the truth's heading there.

    Only the time the ground truth covers is evaluated (``PipelineErrors.coverage`` says how
    much); a trajectory with fewer than two poses in it is left out of all three dictionaries
    (:func:`evaluation_warnings` says so). The heading availability counts the GNSS epochs
    inside each trajectory's span and ``vehicle_span`` (:func:`heading_availability`)."""
    availability = heading_availability(table, tc_usable, trajectories, vehicle_span)
    errors, per_100m, shown = {}, {}, {}
    for name, trajectory in trajectories.items():
        inside = overlap(trajectory, truth)
        if inside.size < 2:
            continue
        first = int(inside[0])
        estimate = trajectory
        if name in UNCORRECTED:
            estimate = with_initial_heading(trajectory, truth, first)
        shown[name] = align_start_to_truth(estimate, truth, first)
        errors[name], per_100m[name] = evaluate_trajectory(
            shown[name], truth, availability.get(name, float("nan"))
        )
    return errors, per_100m, shown


def evaluation_warnings(
    trajectories: dict[str, Trajectory], errors: dict[str, PipelineErrors], truth: Trajectory
) -> list[str]:
    """What the evaluation of :func:`evaluate_pipelines` could not do, in sentences: the
    trajectories the ground truth does not cover, the part of the others it covers when that
    is not all of them, and the figures a too short path leaves out."""
    found = []
    missing = [name for name in trajectories if name not in errors]
    if missing:
        names = ", ".join(PIPELINE_LABELS.get(name, name) for name in missing)
        spans = [trajectories[name].t for name in missing]
        first, last = min(t[0] for t in spans), max(t[-1] for t in spans)
        found.append(
            f"not evaluated: {names}: the ground truth (GPS time {truth.t[0]:.2f} to "
            f"{truth.t[-1]:.2f} s) covers fewer than two of their poses "
            f"({first:.2f} to {last:.2f} s)"
        )
    partial: dict[str, list[str]] = {}
    for name, error in errors.items():
        if error.coverage is not None and error.coverage.note() is not None:
            partial.setdefault(error.coverage.note(), []).append(name)
    for names in partial.values():
        what = "the trajectory" if len(names) == 1 else "each trajectory"
        found.append(
            f"{', '.join(PIPELINE_LABELS.get(name, name) for name in names)}: "
            f"{errors[names[0]].coverage.note(what)} (moved to the truth's position at the "
            "first pose evaluated)"
        )
    lengths = {error.path_length_m for error in errors.values()}
    short = {too_short_for_distance_figures(length) for length in lengths} - {None}
    found += sorted(short)
    return found


@dataclass
class AbsolutePositionErrors:
    """Where a trajectory is, as written (georeferenced as the run placed it), against the
    ground truth at the same times: horizontal distances and absolute height differences (m)
    at its first and last pose inside the truth's time span, and their medians over every pose
    inside it. The evaluation of :func:`evaluate_pipelines` moves each trajectory onto the
    truth at its start and so cannot see this offset."""

    start_horizontal_m: float
    start_vertical_m: float
    end_horizontal_m: float
    end_vertical_m: float
    median_horizontal_m: float
    median_vertical_m: float
    poses: int
    """Poses inside the ground truth's time span (the ones compared)."""

    def to_dict(self) -> dict:
        return asdict(self)


def absolute_position_errors(
    estimate: Trajectory, truth: Trajectory
) -> AbsolutePositionErrors | None:
    """The position errors of ``estimate`` as it is (not moved to the truth) at its poses
    inside the ground truth's time span, the truth's positions interpolated linearly; ``None``
    when no pose is inside."""
    reference, inside = truth_at(truth, estimate.t)
    if not inside.any():
        return None
    difference = estimate.positions[inside] - reference.positions
    horizontal = np.hypot(difference[:, 0], difference[:, 1])
    vertical = np.abs(difference[:, 2])
    return AbsolutePositionErrors(
        start_horizontal_m=float(horizontal[0]),
        start_vertical_m=float(vertical[0]),
        end_horizontal_m=float(horizontal[-1]),
        end_vertical_m=float(vertical[-1]),
        median_horizontal_m=float(np.median(horizontal)),
        median_vertical_m=float(np.median(vertical)),
        poses=int(np.count_nonzero(inside)),
    )
