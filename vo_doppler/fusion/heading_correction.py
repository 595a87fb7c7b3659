"""Heading correction of VO by absolute heading ([TK18] sec. 3.6, Eq. 11–13).

Poses are processed in time order. For the window of poses in (t_i − W, t_i]:

* [TK18] Eq. (11): the offset Δθ is the circular mean of (VO heading − absolute heading) over the
  poses of the window that have an absolute heading;
* [TK18] Eq. (12): the window's headings are shifted by −Δθ (a yaw rotation applied on the world
  side, so pitch and roll are untouched);
* [TK18] Eq. (13): the window's positions are rotated by −Δθ about the window's oldest position.

New VO increments are rotated by the accumulated correction, so the last correction is held
through gaps in the absolute heading.

Frames: the input holds vehicle poses (x forward, y left, z up) in a level, z-up world (the
VO stage turns camera poses into these once, :func:`vo_doppler.vo.frames.vehicle_trajectory`).
Headings are yaw, counter-clockwise from east. The output keeps the input's first position.
"""

from __future__ import annotations

from enum import StrEnum

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.choices import checked
from vo_doppler.fusion.result import CorrectionResult
from vo_doppler.geo import wrap_angle, yaw_of
from vo_doppler.model.trajectory import Trajectory


class HeadingReference(StrEnum):
    """What an absolute heading is compared with: the VO's direction of travel or its yaw."""

    COURSE = "course"
    ORIENTATION = "orientation"


def headings_at(
    t_query: np.ndarray,
    t_heading: np.ndarray,
    yaw: np.ndarray,
    valid: np.ndarray | None = None,
    max_gap_s: float = 1.5,
) -> tuple[np.ndarray, np.ndarray]:
    """Absolute yaw at ``t_query``, interpolated along the shorter arc between the two valid
    samples around each time when they are at most ``max_gap_s`` apart; NaN/False otherwise."""
    t_heading = np.asarray(t_heading, dtype=float)
    yaw = np.asarray(yaw, dtype=float)
    ok = np.isfinite(yaw) & np.isfinite(t_heading)
    if valid is not None:
        ok &= np.asarray(valid, dtype=bool)
    th, yh = t_heading[ok], yaw[ok]
    t_query = np.asarray(t_query, dtype=float)
    if len(th) == 0:
        return np.full(t_query.shape, np.nan), np.zeros(t_query.shape, dtype=bool)
    right = np.clip(np.searchsorted(th, t_query, side="left"), 0, len(th) - 1)
    left = np.clip(right - 1, 0, len(th) - 1)
    exact = np.abs(th[right] - t_query) < 1e-9
    left = np.where(exact, right, left)
    span = th[right] - th[left]
    inside = (th[left] <= t_query + 1e-9) & (th[right] >= t_query - 1e-9) & (span <= max_gap_s)
    fraction = np.where(span > 0, (t_query - th[left]) / np.where(span > 0, span, 1.0), 0.0)
    out = yh[left] + fraction * wrap_angle(yh[right] - yh[left])
    return np.where(inside, wrap_angle(out), np.nan), inside


def _rz(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def chord_starts(positions: np.ndarray, min_chord_m: float) -> np.ndarray:
    """For every pose j, the latest earlier pose k with |p_j − p_k| ≥ ``min_chord_m``
    (horizontal), or −1 when there is none. Its direction is the course at the chord's middle
    time (exact on a circular arc, and independent of the frame rate)."""
    n = len(positions)
    starts = np.full(n, -1, dtype=int)
    xy = positions[:, :2]
    k = -1
    for j in range(n):
        while k + 1 < j and np.hypot(*(xy[j] - xy[k + 1])) >= min_chord_m:
            k += 1
        if k >= 0 and np.hypot(*(xy[j] - xy[k])) >= min_chord_m:
            starts[j] = k
    return starts


def _window_yaw(
    positions: np.ndarray,
    rotations: np.ndarray,
    start: int,
    stop: int,
    reference: HeadingReference,
    chord_start: np.ndarray,
) -> np.ndarray:
    """VO yaw of poses start..stop−1: orientation yaw, or the course of the chord ending at each
    pose (NaN where the chord would begin before ``start`` or there is none)."""
    if reference is HeadingReference.ORIENTATION:
        return yaw_of(rotations[start:stop])
    index = np.arange(start, stop)
    begin = chord_start[index]
    inside = begin >= start
    chord = positions[index, :2] - positions[np.where(inside, begin, index), :2]
    return np.where(inside, np.arctan2(chord[:, 1], chord[:, 0]), np.nan)


def correct_heading(
    vehicle: Trajectory,
    t_heading: np.ndarray,
    yaw_heading: np.ndarray,
    valid: np.ndarray | None = None,
    window_s: float = 2.0,
    max_gap_s: float = 1.5,
    gate_rad: float | None = None,
    reference: HeadingReference = HeadingReference.COURSE,
    min_chord_m: float = 0.5,
) -> CorrectionResult:
    """Correct the VO heading with absolute headings ([TK18] sec. 3.6, [TK18] Eq. 11–13).

    ``t_heading``/``yaw_heading`` are on the trajectory's clock (shift them beforehand);
    ``valid`` marks the usable samples. With ``gate_rad``, once a first correction has been
    made, absolute headings further than the gate from the corrected VO heading are ignored
    (an innovation gate against wrong but self-consistent absolute solutions).

    ``reference`` is what [TK18] Eq. (11) compares with the absolute heading: the VO's
    ``"orientation"`` (vehicle yaw), or its ``"course"``, the direction of the chord of at least
    ``min_chord_m`` ending at each pose (:func:`chord_starts`) compared with the absolute
    heading at the chord's middle time. A Doppler heading is a direction of travel, so "course"
    is immune to a yaw error of the camera→vehicle extrinsic or to a VO whose motion is skewed
    against its optical axis; the chord keeps the tiny, noisy steps of a vehicle that is
    slowing down or creeping out of the comparison.

    Many parameters because it is the correction's public entry point with [TK18]'s tuning:
    after the inputs, each argument is one independent setting with its default, passed by
    keyword (:mod:`vo_doppler.fusion.correction` and the tests); gathering them into a
    configuration is issue 32's open work together with its caller.
    """
    reference = checked(HeadingReference, reference, "reference")
    poses = vehicle.matrices
    n = len(poses)
    vo_positions = poses[:, :3, 3] - (poses[0, :3, 3] if n else 0.0)
    chord_start = chord_starts(vo_positions, min_chord_m)
    t_compare = vehicle.t
    if reference is HeadingReference.COURSE:
        t_compare = 0.5 * (vehicle.t + vehicle.t[np.maximum(chord_start, 0)])
    absolute, has_absolute = headings_at(t_compare, t_heading, yaw_heading, valid, max_gap_s)
    if reference is HeadingReference.COURSE:
        has_absolute &= chord_start >= 0
    vo_rotations = poses[:, :3, :3]
    positions = np.zeros((n, 3))
    rotations = np.zeros((n, 3, 3))
    offset = np.zeros(n)
    total = np.zeros(n)
    correction = 0.0
    oldest = 0
    established = False
    for i in range(n):
        rotate = _rz(correction)
        if i:
            positions[i] = positions[i - 1] + rotate @ (vo_positions[i] - vo_positions[i - 1])
        rotations[i] = rotate @ vo_rotations[i]
        while vehicle.t[oldest] <= vehicle.t[i] - window_s:
            oldest += 1
        window = slice(oldest, i + 1)
        vo_yaw = _window_yaw(positions, rotations, oldest, i + 1, reference, chord_start)
        use = has_absolute[window] & np.isfinite(vo_yaw)
        if gate_rad is not None and established:
            innovation = wrap_angle(vo_yaw - absolute[window])
            use &= np.abs(np.nan_to_num(innovation, nan=np.inf)) < gate_rad
        if use.any():
            established = True
            difference = wrap_angle(vo_yaw[use] - absolute[window][use])
            delta = float(np.arctan2(np.mean(np.sin(difference)), np.mean(np.cos(difference))))
            turn = _rz(-delta)
            pivot = positions[oldest].copy()
            positions[window] = pivot + (positions[window] - pivot) @ turn.T
            rotations[window] = turn @ rotations[window]
            correction -= delta
            offset[i] = delta
        total[i] = correction
    positions += poses[0, :3, 3] if n else 0.0
    corrected = Trajectory(vehicle.t.copy(), positions, Rotation.from_matrix(rotations))
    return CorrectionResult(corrected, total, has_absolute, window_offset=offset)
