"""Turning and placing a trajectory: the starting heading (the rotation about z that turns it into
the absolute headings of its first seconds, one rule for ``run`` (every pipeline) and
``correct``) and the placement by the antenna track (docs/design.md, "Heading correction of
VO")."""

from __future__ import annotations

import logging

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.choices import checked
from vo_doppler.fusion.antenna_track import AntennaTrack
from vo_doppler.fusion.correction import HeadingSource
from vo_doppler.fusion.heading_blend import BlendConfig, vo_direction
from vo_doppler.fusion.heading_correction import HeadingReference, headings_at
from vo_doppler.geo import wrap_angle
from vo_doppler.gnss.spp import nearest_time
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.timeseries import relative_times
from vo_doppler.model.trajectory import Trajectory

log = logging.getLogger(__name__)

INITIAL_HEADING_SPAN_S = 5.0
"""Seconds of absolute headings, from the first, whose median starts every trajectory."""

START_SOURCES = {
    HeadingSource.TC_CONV: ("tc", "conv", "tc_vague"),
    HeadingSource.TC: ("tc", "tc_vague"),
    HeadingSource.CONV: ("conv",),
}
"""For each heading source of ``correct`` (``run`` uses "tc+conv"), the headings that may start
a trajectory, in order of preference (:func:`initial_yaw_offset`)."""


def yaw_offset(
    trajectory: Trajectory,
    t: np.ndarray,
    yaw: np.ndarray,
    reference: HeadingReference | str = HeadingReference.COURSE,
    min_chord_m: float = BlendConfig.min_chord_m,
    max_gap_s: float = BlendConfig.max_gap_s,
) -> float:
    """Circular median of the absolute headings ``yaw`` (at ``t``) minus the trajectory's
    direction: the rotation about z that best turns the trajectory into the absolute headings.

    The direction is the one the correction compares them with
    (:func:`~vo_doppler.fusion.heading_blend.offset_measurements`): for ``reference``
    "course", the course of the trajectory's chords of at least ``min_chord_m`` (its vehicle
    origin's direction of travel, which the heading table's headings are: the heading stage
    takes the antenna's lever arm out of them), at each chord's middle time, with the absolute
    heading interpolated there across gaps of at most ``max_gap_s``; for "orientation", or
    where the trajectory does not move that far within the headings' times, its yaw at ``t``.
    In a sharp turn the two differ (a vehicle origin under the camera slips sideways: 7.7° on
    a simulated drive), and a start from the yaw would leave that difference in the whole
    trajectory. Times relative to the trajectory's start: no dependence on the time origin."""
    origin = float(trajectory.t[0]) if len(trajectory.t) else 0.0
    t = relative_times(np.asarray(t, dtype=float), origin)
    yaw = np.asarray(yaw, dtype=float)
    differences = np.zeros(0)
    if checked(HeadingReference, reference, "reference") is HeadingReference.COURSE:
        poses = trajectory.matrices
        positions = poses[:, :3, 3] - poses[0, :3, 3]
        t_direction, yaw_direction = vo_direction(
            relative_times(trajectory.t, origin),
            positions,
            poses[:, :3, :3],
            HeadingReference.COURSE,
            min_chord_m,
        )
        absolute, inside = headings_at(t_direction, t, yaw, None, max_gap_s)
        differences = wrap_angle(absolute[inside] - yaw_direction[inside])
    if not differences.size:
        differences = wrap_angle(yaw - trajectory.yaw_at(t + origin))
    return float(differences[0] + np.median(wrap_angle(differences - differences[0])))


def initial_yaw_offset(
    table: HeadingTable,
    tc_usable: np.ndarray,
    trajectory: Trajectory,
    span_s: float = INITIAL_HEADING_SPAN_S,
    source: HeadingSource | str = HeadingSource.TC_CONV,
    reference: HeadingReference | str = HeadingReference.COURSE,
) -> float:
    """Rotation about z that starts a trajectory with the absolute heading.

    The circular median of (absolute heading − trajectory yaw) over the usable tightly coupled
    headings of the ``span_s`` seconds from the first one inside the trajectory's time span, so
    that one heading that is off cannot turn the whole trajectory; without any, the conventional
    headings the same way; without those, the reliable tightly coupled headings too vague to
    correct (a canyon from the start: two satellites, an uncalibrated wheel scale); without
    those, the trajectory starts facing east (with a warning). ``source`` keeps the headings
    of one kind only (:data:`START_SOURCES`: "tc" without the conventional ones, "conv" the
    conventional ones alone). ``reference``: what the headings are compared with, as the
    correction compares them (:func:`yaw_offset`: the trajectory's 'course' or its
    'orientation' yaw); ``run`` and ``correct`` pass their correction's.
    """
    source = checked(HeadingSource, source, "source")
    candidates = {
        "tc": (table.yaw_tc, tc_usable),
        "conv": (table.yaw_conv, table.conv_valid),
        "tc_vague": (table.yaw_tc, table.tc_available & table.tc_reliable),
    }
    inside = (table.t >= trajectory.t[0]) & (table.t <= trajectory.t[-1])
    for name in START_SOURCES[source]:
        yaw, valid = candidates[name]
        rows = np.flatnonzero(valid & inside & np.isfinite(yaw))
        if rows.size:
            rows = rows[table.t[rows] <= table.t[rows[0]] + span_s]
            return yaw_offset(trajectory, table.t[rows], yaw[rows], reference)
    log.warning(
        "no absolute heading during the %.0f s of a trajectory: it starts facing east",
        trajectory.t[-1] - trajectory.t[0],
    )
    return float(-trajectory.yaw()[0])


def turned_about_start(trajectory: Trajectory, turn: float) -> Trajectory:
    """The trajectory rotated about the vertical through its first position by ``turn`` (rad,
    counter-clockwise): every position and orientation, the first position kept."""
    if not len(trajectory):
        return trajectory
    rotation = Rotation.from_euler("z", turn)
    start = trajectory.positions[0]
    positions = start + rotation.apply(trajectory.positions - start)
    return Trajectory(trajectory.t, positions, rotation * trajectory.orientations)


PLACEMENT_SPAN_S = 60.0
"""Seconds of antenna positions, from the first inside a trajectory, that place it. A street
canyon's fixes are off by tens of metres for seconds at a time (reflections), while a
trajectory carries a fix back with its own drift, a few metres per minute even for the VO
alone: a minute of fixes outvotes a canyon's biased first seconds at little cost in drift
(the first dead-reckoning pose against the truth with a span of 5 s and of 60 s in
docs/benchmarks.md, "Error per 100 m on the simulator's drives", "The placement span")."""
PLACEMENT_MIN_FIXES = 5
"""At least this many antenna positions place a trajectory (if it has them), however long."""


def level_with_yaw(
    trajectory: Trajectory,
    turn: float,
    antenna: AntennaTrack,
    lever_arm_m: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> Trajectory:
    """Rotate vehicle poses (first-vehicle frame) about z by ``turn`` (rad), then move them by
    the median, per axis, of (antenna position − the trajectory's antenna) over the antenna
    positions of the first ``PLACEMENT_SPAN_S`` seconds inside the trajectory's times (at least
    ``PLACEMENT_MIN_FIXES``): each fix is carried back to the start along the trajectory
    itself, the vehicle placed where it was then, not where it was seconds later, and one bad
    fix cannot move it. The height likewise, from the positions whose heights are good
    (``AntennaTrack.height_rows``: valid fixes with a small vertical σ), their inverse-variance
    weighted median; without any, the first pose at the sequence origin's height (up 0). The
    trajectory's antenna at a fix's time: its position interpolated
    there plus the lever arm (``lever_arm_m`` from the vehicle's origin, x forward, y left,
    z up) turned by its pose nearest in time. Without an antenna position inside, the one
    nearest in time places the trajectory's nearest end (with a warning); an untimed one, the
    first pose.
    """
    rotation = np.eye(4)
    rotation[:3, :3] = Rotation.from_euler("z", turn).as_matrix()
    out = rotation @ trajectory.matrices
    t = trajectory.t
    if not antenna.t.size:
        shift = antenna.position[0] - out[0, :3, 3]
        if not antenna.height_rows.size:
            shift[2] = -out[0, 2, 3]
        out[:, :3, 3] += shift
        return Trajectory.from_matrices(t, out)
    lever = np.asarray(lever_arm_m, dtype=float)
    rows = _placing_rows(antenna.t, np.arange(antenna.t.size), t, warn=True)
    shift = np.median(antenna.position[rows] - _carried(out, t, antenna.t[rows], lever), axis=0)
    heights = antenna.height_rows
    if heights.size:
        rows = _placing_rows(antenna.t, heights, t, warn=False)
        carried = _carried(out, t, antenna.t[rows], lever)[:, 2]
        weight = np.ones(rows.size)
        if antenna.height_sigma is not None:
            weight = np.maximum(antenna.height_sigma[rows], 1e-3) ** -2.0
        shift[2] = weighted_median(antenna.position[rows, 2] - carried, weight)
    else:
        shift[2] = -out[0, 2, 3]
    out[:, :3, 3] += shift
    return Trajectory.from_matrices(t, out)


def _placing_rows(t_fix: np.ndarray, rows: np.ndarray, t: np.ndarray, warn: bool) -> np.ndarray:
    """Of the antenna positions ``rows`` (times ``t_fix[rows]``), those of the first
    ``PLACEMENT_SPAN_S`` seconds inside the trajectory's times ``t`` (at least
    ``PLACEMENT_MIN_FIXES``); without any inside, the nearest in time (with a warning if
    ``warn``)."""
    outside_s = np.maximum(t[0] - t_fix[rows], t_fix[rows] - t[-1])
    inside = rows[outside_s <= 0.0]
    if inside.size:
        span = t_fix[inside] <= t_fix[inside[0]] + PLACEMENT_SPAN_S
        return inside[: max(int(span.sum()), PLACEMENT_MIN_FIXES)]
    nearest = int(np.argmin(outside_s))
    if warn:
        log.warning(
            "no GNSS fix within the trajectory from %.1f to %.1f s: it is placed by the antenna "
            "position %.1f s outside it",
            t[0],
            t[-1],
            outside_s[nearest],
        )
    return rows[[nearest]]


def _carried(poses: np.ndarray, t: np.ndarray, t_fix: np.ndarray, lever: np.ndarray):
    """The trajectory's antenna (position interpolated at ``t_fix`` plus the lever arm turned
    by the pose nearest in time), (M, 3)."""
    t_fix = np.clip(t_fix, t[0], t[-1])
    carried = np.column_stack([np.interp(t_fix, t, poses[:, axis, 3]) for axis in range(3)])
    return carried + poses[nearest_time(t, t_fix), :3, :3] @ lever


def weighted_median(values: np.ndarray, weights: np.ndarray) -> float:
    """The value at which the cumulative weight of the sorted ``values`` reaches half of the
    total (the lower one on a tie): the median when the weights are equal and unmoved by values
    holding less than half of the weight, however far off."""
    order = np.argsort(values, kind="stable")
    cumulative = np.cumsum(weights[order])
    return float(values[order][np.searchsorted(cumulative, 0.5 * cumulative[-1])])
