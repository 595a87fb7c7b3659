"""Trajectory error metrics: KITTI-devkit segment errors, final drift, end yaw error, ATE RMSE.

Segment errors follow the KITTI odometry devkit: for every start frame and segment length L,
the end frame is the first whose ground-truth path distance from the start is ≥ L; the error is
the relative pose ``inv(ΔT_gt) · ΔT_est``, translation in % of L and rotation in degrees per 100 m.
On a path shorter than :data:`vo_doppler.eval.per_distance.MIN_PATH_M` no figure per distance
is computed (``None``, with the reason in ``notes``).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.choices import checked
from vo_doppler.errors import InputError
from vo_doppler.eval.alignment import Alignment, align
from vo_doppler.eval.per_distance import too_short_for_distance_figures
from vo_doppler.model.trajectory import Trajectory

KITTI_SEGMENT_LENGTHS_M = (100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0, 800.0)
SHORT_SEGMENT_LENGTHS_M = (10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0)
MATCH_MAX_DT_S = 0.02
"""Largest time difference (s) between an estimated pose and the ground-truth pose it is
matched with."""
COVERAGE_TOLERANCE_S = 0.25
"""Time of an estimate left out of its evaluation (s) that goes unmentioned: a ground truth
sampled at 10-20 Hz commonly ends a sample before the estimate."""


@dataclass
class Coverage:
    """The part of an estimate's time span that was evaluated (it has ground truth)."""

    estimate_s: float
    """The estimate's time span (s)."""
    evaluated_s: float
    """The evaluated poses' time span (s)."""
    fraction: float
    """``evaluated_s / estimate_s`` (1 for an estimate of one instant)."""
    starts_after_s: float
    """Time from the estimate's first pose to the first evaluated one (s)."""
    ends_before_s: float
    """Time from the last evaluated pose to the estimate's last one (s)."""

    def note(self, what: str = "the estimate") -> str | None:
        """A sentence saying how much of ``what`` was evaluated, when more than
        :data:`COVERAGE_TOLERANCE_S` was left out; else None."""
        if self.starts_after_s + self.ends_before_s <= COVERAGE_TOLERANCE_S:
            return None
        return (
            f"only {self.evaluated_s:.1f} s of the {self.estimate_s:.1f} s of {what} "
            f"({self.fraction:.0%}) were evaluated, from {self.starts_after_s:.2f} s after its "
            f"first pose to {self.ends_before_s:.2f} s before its last: the ground truth covers "
            "no more of it in time"
        )


def time_coverage(estimate_t: np.ndarray, evaluated_t: np.ndarray) -> Coverage:
    """How much of the span of ``estimate_t`` the (non-empty, sorted) ``evaluated_t`` cover."""
    total = float(estimate_t[-1] - estimate_t[0])
    evaluated = float(evaluated_t[-1] - evaluated_t[0])
    return Coverage(
        estimate_s=total,
        evaluated_s=evaluated,
        fraction=evaluated / total if total > 0 else 1.0,
        starts_after_s=float(evaluated_t[0] - estimate_t[0]),
        ends_before_s=float(estimate_t[-1] - evaluated_t[-1]),
    )


@dataclass
class SegmentError:
    length_m: float
    translation_pct: float
    rotation_deg_per_100m: float
    count: int


@dataclass
class TrajectoryErrors:
    """The figures of :func:`evaluate`; ``None`` where a figure is not available (``notes``
    says why), never a number that means nothing."""

    path_length_m: float
    alignment: str
    segments: list[SegmentError] = field(default_factory=list)
    mean_translation_pct: float | None = None
    mean_rotation_deg_per_100m: float | None = None
    final_position_error_m: float | None = None
    final_drift_pct: float | None = None
    end_yaw_error_deg: float | None = None
    ate_rmse_m: float | None = None
    coverage: Coverage | None = None
    """The share of the estimate evaluated, when rows were matched by time."""
    notes: list[str] = field(default_factory=list)
    """Why figures are missing or cover only part of the estimate."""

    def to_dict(self) -> dict:
        return asdict(self)


def segment_lengths_that_fit(path_length: float) -> tuple[float, ...]:
    """KITTI's 100…800 m lengths that fit the path; on short paths 10…80 m; else half the path;
    none on a path too short for figures per distance."""
    if too_short_for_distance_figures(path_length):
        return ()
    for lengths in (KITTI_SEGMENT_LENGTHS_M, SHORT_SEGMENT_LENGTHS_M):
        fit = tuple(length for length in lengths if length < path_length)
        if fit:
            return fit
    return (path_length / 2.0,) if path_length > 0 else ()


def segment_lengths_note(lengths: tuple[float, ...], path_length: float) -> str:
    """Which segment lengths the errors use, in words (KITTI's or shorter ones, and why)."""
    if not lengths:
        return too_short_for_distance_figures(path_length) or (
            f"no segment fits the {path_length:.0f} m path"
        )
    listed = ", ".join(f"{length:.0f}" for length in lengths)
    if lengths[0] >= KITTI_SEGMENT_LENGTHS_M[0]:
        return f"KITTI segments of {listed} m (those of KITTI's 100-800 m that fit the path)"
    return (
        f"segments of {listed} m, shorter than KITTI's 100-800 m: the {path_length:.0f} m "
        "path is too short for them"
    )


def yaw_about(rotation: Rotation, up: np.ndarray) -> np.ndarray:
    """Signed angle (rad) about ``up`` of each rotation, from a horizontal reference axis."""
    up = np.asarray(up, dtype=float) / np.linalg.norm(up)
    reference = np.eye(3)[int(np.argmin(np.abs(up)))]
    reference = reference - (reference @ up) * up
    reference /= np.linalg.norm(reference)
    rotated = rotation.apply(reference)
    rotated = rotated - np.outer(rotated @ up, up)
    sin = np.cross(np.broadcast_to(reference, rotated.shape), rotated) @ up
    return np.arctan2(sin, rotated @ reference)


SEGMENT_CHUNK = 4096
"""Start frames whose relative poses :func:`segment_errors` computes at once: each start's
error depends on its two poses alone, so the chunks give the same figures as one pass, in
about 4 MiB per chunk instead of 0.9 kB per pose (35 MiB for 40,000 poses)."""


def segment_errors(estimate: Trajectory, truth: Trajectory, lengths) -> list[SegmentError]:
    """KITTI-devkit relative errors for each segment length (every start frame used)."""
    distance = truth.cumulative_distance()
    results = []
    for length in lengths:
        ends = np.searchsorted(distance, distance + length, side="left")
        starts = np.flatnonzero(ends < len(distance))
        if starts.size == 0:
            continue
        t_err, r_err = np.empty(starts.size), np.empty(starts.size)
        for k in range(0, starts.size, SEGMENT_CHUNK):
            part = slice(k, k + SEGMENT_CHUNK)
            first, last = starts[part], ends[starts[part]]
            delta_gt = np.linalg.inv(truth.subset(first).matrices) @ truth.subset(last).matrices
            delta_est = (
                np.linalg.inv(estimate.subset(first).matrices) @ estimate.subset(last).matrices
            )
            error = np.linalg.inv(delta_gt) @ delta_est
            t_err[part] = np.linalg.norm(error[:, :3, 3], axis=1) / length
            r_err[part] = Rotation.from_matrix(error[:, :3, :3]).magnitude() / length
        results.append(
            SegmentError(
                length_m=float(length),
                translation_pct=float(100.0 * t_err.mean()),
                rotation_deg_per_100m=float(np.degrees(r_err.mean()) * 100.0),
                count=int(starts.size),
            )
        )
    return results


def evaluate(
    estimate: Trajectory,
    truth: Trajectory,
    alignment: Alignment = Alignment.START,
    up: np.ndarray | None = None,
) -> TrajectoryErrors:
    """All error figures of ``estimate`` against ``truth`` (rows must already correspond).

    An :class:`InputError` names the argument when the two differ in length, hold fewer than
    two poses, a non-finite position or orientation (it would turn every figure into NaN or
    stop the alignment's SVD), or ``alignment`` is not one of
    :class:`~vo_doppler.eval.alignment.Alignment`."""
    if len(estimate) != len(truth):
        raise InputError(
            f"estimate has {len(estimate)} poses, truth {len(truth)}: the rows must correspond "
            "(evaluate_by_time matches them by time)"
        )
    if len(truth) < 2:
        raise InputError(f"need at least two poses to evaluate, got {len(truth)}")
    _check_finite(estimate, "estimate")
    _check_finite(truth, "truth")
    up = np.array([0.0, 0.0, 1.0]) if up is None else np.asarray(up, dtype=float)
    aligned = align(estimate, truth, alignment, up)
    path_length = truth.path_length
    segments = segment_errors(aligned, truth, segment_lengths_that_fit(path_length))
    result = TrajectoryErrors(path_length_m=path_length, alignment=alignment, segments=segments)
    if segments:
        weights = np.array([s.count for s in segments], dtype=float)
        result.mean_translation_pct = float(
            np.average([s.translation_pct for s in segments], weights=weights)
        )
        result.mean_rotation_deg_per_100m = float(
            np.average([s.rotation_deg_per_100m for s in segments], weights=weights)
        )
    else:
        result.notes.append(segment_lengths_note((), path_length))
    final_error = float(np.linalg.norm(aligned.positions[-1] - truth.positions[-1]))
    result.final_position_error_m = final_error
    if not too_short_for_distance_figures(path_length):
        result.final_drift_pct = 100.0 * final_error / path_length
    yaw_est = yaw_about(aligned.orientations[-1:], up)[0]
    yaw_gt = yaw_about(truth.orientations[-1:], up)[0]
    result.end_yaw_error_deg = float(np.degrees(np.angle(np.exp(1j * (yaw_est - yaw_gt)))))
    residual = aligned.positions - truth.positions
    result.ate_rmse_m = float(np.sqrt(np.mean(np.sum(residual**2, axis=1))))
    return result


def _check_finite(trajectory: Trajectory, name: str) -> None:
    """An :class:`InputError` naming ``name`` and the first pose with a non-finite position or
    orientation."""
    finite = np.isfinite(trajectory.positions).all(axis=1)
    if len(trajectory):
        finite &= np.isfinite(trajectory.orientations.as_quat()).all(axis=1)
    bad = np.flatnonzero(~finite)
    if bad.size:
        k = int(bad[0])
        raise InputError(
            f"{name}: pose {k} (t = {trajectory.t[k]:.6f} s) has a non-finite position or "
            f"orientation ({bad.size} such poses)"
        )


def _check_time_order(trajectory: Trajectory, name: str) -> None:
    """An :class:`InputError` naming ``name`` unless its times are finite and sorted: matching
    by time searches them."""
    bad = np.flatnonzero(~np.isfinite(trajectory.t))
    if bad.size:
        raise InputError(f"{name}: t[{bad[0]}] is {trajectory.t[bad[0]]}")
    back = np.flatnonzero(np.diff(trajectory.t) < 0)
    if back.size:
        k = int(back[0]) + 1
        raise InputError(
            f"{name}: times must be sorted to match poses by time, but t[{k}] = "
            f"{trajectory.t[k]:.6f} s comes after t[{k - 1}] = {trajectory.t[k - 1]:.6f} s"
        )


def associate(estimate: Trajectory, truth: Trajectory, max_dt: float = MATCH_MAX_DT_S) -> tuple:
    """Match rows by nearest timestamp within ``max_dt``; returns the matched pair."""
    index = np.clip(np.searchsorted(truth.t, estimate.t), 1, max(len(truth) - 1, 1))
    left = np.maximum(index - 1, 0)
    nearer = np.where(
        np.abs(truth.t[left] - estimate.t) <= np.abs(truth.t[index] - estimate.t), left, index
    )
    ok = np.abs(truth.t[nearer] - estimate.t) <= max_dt
    return estimate.subset(np.flatnonzero(ok)), truth.subset(nearer[ok])


NO_MATCH = f"fewer than two timestamps match the ground truth's (within {MATCH_MAX_DT_S:g} s)"
"""Why an estimate could not be evaluated by time."""


def evaluate_by_time(
    estimate: Trajectory,
    truth: Trajectory,
    alignment: Alignment = Alignment.START,
    up: np.ndarray | None = None,
    max_dt: float = MATCH_MAX_DT_S,
) -> TrajectoryErrors | None:
    """:func:`evaluate` on the poses whose times match the ground truth's (:func:`associate`),
    with the share of the estimate they cover (``coverage``, and a note when part is left out);
    None when fewer than two match (:data:`NO_MATCH` says so). Times must be finite and
    sorted (an :class:`InputError` naming the argument otherwise: unsorted times would match
    wrongly or not at all, and read as :data:`NO_MATCH`)."""
    _check_time_order(estimate, "estimate")
    _check_time_order(truth, "truth")
    checked(Alignment, alignment, "alignment")
    matched, matched_truth = associate(estimate, truth, max_dt)
    if len(matched) < 2:
        return None
    errors = evaluate(matched, matched_truth, alignment, up)
    errors.coverage = time_coverage(estimate.t, matched.t)
    note = errors.coverage.note()
    if note:
        errors.notes.insert(0, note)
    return errors


def attitude_roughness_deg(truth: Trajectory) -> np.ndarray:
    """Change of the frame-to-frame rotation at frames 1 … N−2 (deg): the attitude's second
    difference. A measured attitude jitters; an interpolated one is smooth."""
    R = truth.orientations.as_matrix()
    relative = Rotation.from_matrix(np.einsum("nji,njk->nik", R[:-1], R[1:])).as_rotvec()
    return np.degrees(np.linalg.norm(np.diff(relative, axis=0), axis=1))
