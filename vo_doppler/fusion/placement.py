"""The starting heading of a trajectory: the rotation about z that turns it into the absolute
headings of its first seconds, one rule for ``run`` (every pipeline) and ``correct``."""

from __future__ import annotations

import logging

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.fusion.heading_blend import BlendConfig, vo_direction
from vo_doppler.fusion.heading_correction import headings_at
from vo_doppler.geo import wrap_angle
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.timeseries import relative_times
from vo_doppler.model.trajectory import Trajectory

log = logging.getLogger(__name__)

INITIAL_HEADING_SPAN_S = 5.0
"""Seconds of absolute headings, from the first, whose median starts every trajectory."""

START_SOURCES = {
    "tc+conv": ("tc", "conv", "tc_vague"),
    "tc": ("tc", "tc_vague"),
    "conv": ("conv",),
}
"""For each heading source of ``correct`` (``run`` uses "tc+conv"), the headings that may start
a trajectory, in order of preference (:func:`initial_yaw_offset`)."""


def yaw_offset(
    trajectory: Trajectory,
    t: np.ndarray,
    yaw: np.ndarray,
    reference: str = "course",
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
    if reference == "course":
        poses = trajectory.matrices
        positions = poses[:, :3, 3] - poses[0, :3, 3]
        t_direction, yaw_direction = vo_direction(
            relative_times(trajectory.t, origin), positions, poses[:, :3, :3], "course", min_chord_m
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
    source: str = "tc+conv",
    reference: str = "course",
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
    if source not in START_SOURCES:
        raise ValueError(f"unknown heading source {source!r} ({', '.join(START_SOURCES)})")
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
