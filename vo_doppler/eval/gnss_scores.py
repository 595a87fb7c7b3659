"""GNSS outputs scored against ground truth (``vo-doppler eval gnss``): the conventional Doppler
velocity (``vel.csv``), the tight and conventional headings (``heading.csv``) and single-point
positions (``pos.csv``).

The truth's velocity is the central difference of its positions in its local ENU frame (per
stretch without a gap, :func:`truth_at`), linearly interpolated at each epoch; its course is the
file's own where it has one, else the velocity's, held through stops below
:data:`HOLD_BELOW_MPS` (a course from positions turns at random while standing). Only the epochs
inside the truth's time span (and not in a gap of it) are scored; the others are counted.

Moving epochs have a truth horizontal speed above ``moving_mps``, standstill ones below
``standstill_mps``. Figures (errors are absolute values):

* ``vel.csv``: availability = valid moving epochs / moving epochs; over the valid moving epochs
  the horizontal speed error |‖v_EN‖ − ‖v_EN,truth‖| and the course error, median / p95 / max,
  and how many course errors are beyond 5° and 15°; over the valid standstill epochs the
  horizontal speed itself and how many are above ``standstill_mps``.
* ``heading.csv``: the tight heading counts where it is available (finite) and ``tc_reliable``,
  the conventional one where ``conv_valid``; the same figures of the error against the truth
  course.
* ``pos.csv``: over the valid epochs, horizontal and vertical position error in the truth's ENU
  frame, median / p95 / max.

p95 is NumPy's linear-interpolation percentile. Pure functions over the model types: no file is
read here.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vo_doppler.geo import wrap_angle, yaw_to_course
from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution
from vo_doppler.model.ground_truth import GroundTruth
from vo_doppler.model.heading import HeadingTable

MOVING_MPS = 3.0
"""Default moving threshold: truth horizontal speed above it (m/s)."""
STANDSTILL_MPS = 0.2
"""Default standstill threshold: truth horizontal speed below it (m/s)."""
HOLD_BELOW_MPS = 1.0
"""Below this truth speed (m/s) the truth course is held from the last faster sample."""
ANGLE_LIMITS_DEG = (5.0, 15.0)
"""Heading and course errors beyond these are counted."""
GAP_FACTOR = 2.5
MIN_GAP_S = 1.0
"""A step between truth samples longer than max(GAP_FACTOR × the median step, MIN_GAP_S) is a
gap: nothing inside it is scored, and the velocity is not differenced across it."""


@dataclass(frozen=True)
class Thresholds:
    """What is moving and standing (m/s), and the error limits counted (degrees)."""

    moving_mps: float = MOVING_MPS
    standstill_mps: float = STANDSTILL_MPS
    hold_below_mps: float = HOLD_BELOW_MPS
    angle_limits_deg: tuple[float, ...] = ANGLE_LIMITS_DEG

    def __post_init__(self) -> None:
        if not 0.0 < self.standstill_mps <= self.moving_mps:
            raise ValueError(
                f"need 0 < standstill ({self.standstill_mps}) <= moving ({self.moving_mps}) m/s"
            )


@dataclass(frozen=True)
class TruthAt:
    """The truth at some epochs: ``covered`` (inside its span and not in a gap), ENU velocity
    (m/s), course (rad, clockwise from north) and ENU position (m); NaN where not covered."""

    covered: np.ndarray
    velocity_enu: np.ndarray
    course_rad: np.ndarray
    position_enu: np.ndarray

    @property
    def speed_mps(self) -> np.ndarray:
        """Horizontal speed (m/s)."""
        return np.hypot(self.velocity_enu[:, 0], self.velocity_enu[:, 1])


def _gaps(t: np.ndarray) -> np.ndarray:
    """Per step between samples: is it a gap (module docstring)?"""
    steps = np.diff(t)
    if not steps.size:
        return np.zeros(0, dtype=bool)
    return steps > max(GAP_FACTOR * float(np.median(steps)), MIN_GAP_S)


def truth_velocity(truth: GroundTruth) -> np.ndarray:
    """ENU velocity at the truth's samples: central differences (one-sided at the ends) within
    each stretch without a gap; NaN on a stretch of one sample."""
    velocity = np.full_like(truth.enu, np.nan)
    cuts = np.flatnonzero(_gaps(truth.t)) + 1
    for start, stop in zip(np.r_[0, cuts], np.r_[cuts, len(truth)], strict=True):
        if stop - start >= 2:
            velocity[start:stop] = np.gradient(truth.enu[start:stop], truth.t[start:stop], axis=0)
    return velocity


def held_course(
    velocity_enu: np.ndarray, own_course: np.ndarray | None, hold_below_mps: float
) -> np.ndarray:
    """Course (rad) at each truth sample: the file's own where finite, else the velocity's
    where the horizontal speed is at least ``hold_below_mps``; the others hold the last such
    course (the first one before it). NaN throughout when no sample has a course."""
    speed = np.hypot(velocity_enu[:, 0], velocity_enu[:, 1])
    course = np.where(
        speed >= hold_below_mps, np.arctan2(velocity_enu[:, 0], velocity_enu[:, 1]), np.nan
    )
    if own_course is not None:
        course = np.where(np.isfinite(own_course), own_course, course)
    known = np.flatnonzero(np.isfinite(course))
    if not known.size:
        return course
    last = np.maximum.accumulate(np.where(np.isfinite(course), np.arange(course.size), -1))
    return np.mod(course[np.where(last >= 0, last, known[0])], 2.0 * np.pi)


def truth_at(truth: GroundTruth, t: np.ndarray, hold_below_mps: float = HOLD_BELOW_MPS) -> TruthAt:
    """The truth linearly interpolated at ``t`` (module docstring); the course is interpolated
    unwrapped, the shorter way round."""
    t = np.asarray(t, dtype=float)
    n = len(truth)
    nan3 = np.full((t.size, 3), np.nan)
    if n < 2:
        return TruthAt(np.zeros(t.size, dtype=bool), nan3, np.full(t.size, np.nan), nan3)
    velocity = truth_velocity(truth)
    course = held_course(velocity, truth.course_rad, hold_below_mps)
    stretch = np.r_[0, np.cumsum(_gaps(truth.t))]  # per sample: which stretch without a gap
    before = np.clip(np.searchsorted(truth.t, t, side="right") - 1, 0, n - 1)
    after = np.clip(np.searchsorted(truth.t, t, side="left"), 0, n - 1)
    covered = (t >= truth.t[0]) & (t <= truth.t[-1]) & (stretch[before] == stretch[after])
    covered &= np.isfinite(velocity[before]).all(axis=1) & np.isfinite(velocity[after]).all(axis=1)

    def at(values: np.ndarray) -> np.ndarray:
        return np.where(covered, np.interp(t, truth.t, values), np.nan)

    course_at = np.full(t.size, np.nan)
    if np.isfinite(course).all():
        course_at = np.mod(at(np.unwrap(course)), 2.0 * np.pi)
    return TruthAt(
        covered,
        np.column_stack([at(velocity[:, i]) for i in range(3)]),
        course_at,
        np.column_stack([at(truth.enu[:, i]) for i in range(3)]),
    )


@dataclass(frozen=True)
class ErrorStats:
    """Median, p95 and max of some values (None when there are none), their count, and how
    many are beyond each limit (``beyond``: limit → count)."""

    count: int
    median: float | None
    p95: float | None
    max: float | None
    beyond: dict[float, int] = field(default_factory=dict)

    @classmethod
    def of(cls, values: np.ndarray, limits: tuple[float, ...] = ()) -> ErrorStats:
        values = np.asarray(values, dtype=float)
        beyond = {float(limit): int(np.sum(values > limit)) for limit in limits}
        if not values.size:
            return cls(0, None, None, None, beyond)
        return cls(
            int(values.size),
            float(np.median(values)),
            float(np.percentile(values, 95)),
            float(np.max(values)),
            beyond,
        )

    def to_dict(self) -> dict:
        out: dict = {"count": self.count, "median": self.median, "p95": self.p95, "max": self.max}
        out.update({f"beyond_{limit:g}": n for limit, n in self.beyond.items()})
        return out


@dataclass(frozen=True)
class Coverage:
    """An input's epochs: all of them, those scored (inside the truth's span, not in a gap),
    those left out, and the moving and standstill ones among the scored; the input's time span
    (GPS s)."""

    epochs: int
    scored: int
    moving: int
    standstill: int
    first_s: float | None
    last_s: float | None

    @property
    def outside(self) -> int:
        """Epochs not scored: outside the truth's span or in a gap of it."""
        return self.epochs - self.scored

    @classmethod
    def of(cls, t: np.ndarray, at: TruthAt, thresholds: Thresholds) -> Coverage:
        speed = at.speed_mps
        return cls(
            int(t.size),
            int(at.covered.sum()),
            int(np.sum(at.covered & (speed > thresholds.moving_mps))),
            int(np.sum(at.covered & (speed < thresholds.standstill_mps))),
            float(t[0]) if t.size else None,
            float(t[-1]) if t.size else None,
        )

    def to_dict(self) -> dict:
        return {
            "epochs": self.epochs,
            "scored": self.scored,
            "outside_truth": self.outside,
            "moving": self.moving,
            "standstill": self.standstill,
            "first_gps_time_s": self.first_s,
            "last_gps_time_s": self.last_s,
        }


def _share(count: int, of: int) -> float | None:
    return count / of if of else None


def _course_error_deg(course_rad: np.ndarray, truth_course_rad: np.ndarray) -> np.ndarray:
    return np.degrees(np.abs(wrap_angle(course_rad - truth_course_rad)))


@dataclass(frozen=True)
class VelocityScores:
    """``vel.csv`` against the truth (module docstring)."""

    coverage: Coverage
    availability: float | None
    speed_error_mps: ErrorStats
    course_error_deg: ErrorStats
    standstill_speed_mps: ErrorStats

    def to_dict(self) -> dict:
        return {
            "coverage": self.coverage.to_dict(),
            "availability": self.availability,
            "speed_error_mps": self.speed_error_mps.to_dict(),
            "course_error_deg": self.course_error_deg.to_dict(),
            "standstill_speed_mps": self.standstill_speed_mps.to_dict(),
        }


def score_velocity(
    solution: VelocitySolution, truth: GroundTruth, thresholds: Thresholds = Thresholds()
) -> VelocityScores:
    """The conventional velocity's figures over the epochs the truth covers."""
    at = truth_at(truth, solution.t, thresholds.hold_below_mps)
    truth_speed = at.speed_mps
    moving = at.covered & (truth_speed > thresholds.moving_mps)
    standstill = at.covered & (truth_speed < thresholds.standstill_mps)
    v = solution.velocity_enu
    valid = solution.valid & np.isfinite(v[:, :2]).all(axis=1)
    speed = np.hypot(v[:, 0], v[:, 1])
    course = np.arctan2(v[:, 0], v[:, 1])
    used = valid & moving
    return VelocityScores(
        Coverage.of(solution.t, at, thresholds),
        _share(int(used.sum()), int(moving.sum())),
        ErrorStats.of(np.abs(speed - truth_speed)[used]),
        ErrorStats.of(_course_error_deg(course, at.course_rad)[used], thresholds.angle_limits_deg),
        ErrorStats.of(speed[valid & standstill], (thresholds.standstill_mps,)),
    )


@dataclass(frozen=True)
class HeadingFigures:
    """One heading's availability over the moving epochs and its error where available."""

    availability: float | None
    error_deg: ErrorStats

    def to_dict(self) -> dict:
        return {"availability": self.availability, "error_deg": self.error_deg.to_dict()}


@dataclass(frozen=True)
class HeadingScores:
    """``heading.csv`` against the truth: the tight heading where available and reliable, the
    conventional heading where ``conv_valid``."""

    coverage: Coverage
    tight: HeadingFigures
    conventional: HeadingFigures

    def to_dict(self) -> dict:
        return {
            "coverage": self.coverage.to_dict(),
            "tight": self.tight.to_dict(),
            "conventional": self.conventional.to_dict(),
        }


def score_heading(
    table: HeadingTable, truth: GroundTruth, thresholds: Thresholds = Thresholds()
) -> HeadingScores:
    """The tight and conventional headings' figures over the moving epochs the truth covers."""
    at = truth_at(truth, table.t, thresholds.hold_below_mps)
    moving = at.covered & (at.speed_mps > thresholds.moving_mps)

    def figures(yaw_rad: np.ndarray, usable: np.ndarray) -> HeadingFigures:
        used = usable & np.isfinite(yaw_rad) & moving
        error = _course_error_deg(yaw_to_course(np.nan_to_num(yaw_rad)), at.course_rad)
        return HeadingFigures(
            _share(int(used.sum()), int(moving.sum())),
            ErrorStats.of(error[used], thresholds.angle_limits_deg),
        )

    return HeadingScores(
        Coverage.of(table.t, at, thresholds),
        figures(table.yaw_tc, table.tc_reliable),
        figures(table.yaw_conv, table.conv_valid),
    )


@dataclass(frozen=True)
class PositionScores:
    """``pos.csv`` against the truth: the valid share of the scored epochs and the horizontal
    and vertical error (m) over the valid ones."""

    coverage: Coverage
    availability: float | None
    horizontal_m: ErrorStats
    vertical_m: ErrorStats

    def to_dict(self) -> dict:
        return {
            "coverage": self.coverage.to_dict(),
            "availability": self.availability,
            "horizontal_error_m": self.horizontal_m.to_dict(),
            "vertical_error_m": self.vertical_m.to_dict(),
        }


def score_positions(
    solution: SppSolution, truth: GroundTruth, thresholds: Thresholds = Thresholds()
) -> PositionScores:
    """Position errors in the truth's ENU frame (which the truth must have: a TUM file read
    without its origin has none, ValueError)."""
    if truth.frame is None:
        raise ValueError("the ground truth has no geodetic frame: positions cannot be compared")
    at = truth_at(truth, solution.t, thresholds.hold_below_mps)
    enu = truth.frame.ecef_to_enu(solution.position_ecef)
    used = solution.valid & at.covered & np.isfinite(enu).all(axis=1)
    error = enu - at.position_enu
    return PositionScores(
        Coverage.of(solution.t, at, thresholds),
        _share(int(used.sum()), int(at.covered.sum())),
        ErrorStats.of(np.hypot(error[used, 0], error[used, 1])),
        ErrorStats.of(np.abs(error[used, 2])),
    )


@dataclass(frozen=True)
class GnssScores:
    """Every given output's scores (None: not given), the thresholds and the truth's extent."""

    thresholds: Thresholds
    truth_source: str
    truth_samples: int
    truth_first_s: float
    truth_last_s: float
    velocity: VelocityScores | None = None
    heading: HeadingScores | None = None
    positions: PositionScores | None = None

    def without_overlap(self) -> list[str]:
        """The given outputs ("velocity", "heading", "positions") of which no epoch is scored."""
        given = {"velocity": self.velocity, "heading": self.heading, "positions": self.positions}
        return [name for name, s in given.items() if s is not None and s.coverage.scored == 0]

    def to_dict(self) -> dict:
        th = self.thresholds
        return {
            "thresholds": {
                "moving_mps": th.moving_mps,
                "standstill_mps": th.standstill_mps,
                "truth_course_held_below_mps": th.hold_below_mps,
                "angle_limits_deg": list(th.angle_limits_deg),
            },
            "truth": {
                "source": self.truth_source,
                "samples": self.truth_samples,
                "first_gps_time_s": self.truth_first_s,
                "last_gps_time_s": self.truth_last_s,
            },
            "velocity": None if self.velocity is None else self.velocity.to_dict(),
            "heading": None if self.heading is None else self.heading.to_dict(),
            "positions": None if self.positions is None else self.positions.to_dict(),
        }


def score_gnss(
    truth: GroundTruth,
    velocity: VelocitySolution | None = None,
    heading: HeadingTable | None = None,
    positions: SppSolution | None = None,
    thresholds: Thresholds = Thresholds(),
) -> GnssScores:
    """Score every output given against ``truth`` (module docstring)."""
    if not len(truth):
        raise ValueError("the ground truth has no samples")
    return GnssScores(
        thresholds,
        truth.source,
        len(truth),
        float(truth.t[0]),
        float(truth.t[-1]),
        None if velocity is None else score_velocity(velocity, truth, thresholds),
        None if heading is None else score_heading(heading, truth, thresholds),
        None if positions is None else score_positions(positions, truth, thresholds),
    )
