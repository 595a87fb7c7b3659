"""Conventional heading (sec. 3.2): the direction of a Doppler velocity solution."""

from __future__ import annotations

import numpy as np

from vo_doppler.geo import yaw_to_course


def heading_from_velocity(
    velocity_enu: np.ndarray, valid: np.ndarray | None = None, min_speed_mps: float = 0.5
) -> tuple[np.ndarray, np.ndarray]:
    """Yaw (rad, counter-clockwise from east) of ENU velocities (…, 3) and its validity.

    The heading is undefined below ``min_speed_mps`` horizontal speed or where the velocity
    solution is invalid; those entries are NaN and False.
    """
    v = np.asarray(velocity_enu, dtype=float)
    horizontal = np.hypot(v[..., 0], v[..., 1])
    ok = np.isfinite(horizontal) & (horizontal >= min_speed_mps)
    if valid is not None:
        ok &= np.asarray(valid, dtype=bool)
    yaw = np.where(ok, np.arctan2(v[..., 1], v[..., 0]), np.nan)
    return yaw, ok


def course_from_velocity(
    velocity_enu: np.ndarray, valid: np.ndarray | None = None, min_speed_mps: float = 0.5
) -> tuple[np.ndarray, np.ndarray]:
    """Course (rad, clockwise from north, [0, 2π)) of ENU velocities and its validity."""
    yaw, ok = heading_from_velocity(velocity_enu, valid, min_speed_mps)
    return np.where(ok, yaw_to_course(np.nan_to_num(yaw)), np.nan), ok
