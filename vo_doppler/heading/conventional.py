"""Conventional heading ([TK18] sec. 3.2): the direction of a Doppler velocity solution, and its
standard deviation from the velocity covariance."""

from __future__ import annotations

import numpy as np

from vo_doppler.geo import wrap_angle


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


def velocity_heading_sigma(
    velocity_enu: np.ndarray, covariance_ecef: np.ndarray, ecef_to_enu: np.ndarray
) -> np.ndarray:
    """Standard deviation (rad) of the yaw atan2(v_n, v_e) of GNSS velocities (N, 3) with
    their ECEF covariances (N, ≥3, ≥3), to first order: the cross-track velocity's standard
    deviation over the horizontal speed, √(uᵀ·C_EN·u)/|v_EN| with u = (−sin ψ, cos ψ) and
    C_EN the east-north block of R·C·Rᵀ (R: ECEF→ENU). NaN where the speed is zero or the
    velocity is not finite."""
    v = np.asarray(velocity_enu, dtype=float)
    rotation = np.asarray(ecef_to_enu, dtype=float)
    enu = rotation @ np.asarray(covariance_ecef, dtype=float)[:, :3, :3] @ rotation.T
    speed = np.hypot(v[:, 0], v[:, 1])
    yaw = np.arctan2(v[:, 1], v[:, 0])
    across = np.stack([-np.sin(yaw), np.cos(yaw)], axis=1)
    variance = np.einsum("ni,nij,nj->n", across, enu[:, :2, :2], across)
    with np.errstate(divide="ignore", invalid="ignore"):
        sigma = np.sqrt(variance) / speed
    return np.where(np.isfinite(sigma) & (speed > 0), sigma, np.nan)


def vehicle_heading_from_antenna(
    yaw: np.ndarray, speed: np.ndarray, wheel_speed: np.ndarray, offset_velocity: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Yaw and forward speed of the vehicle from the yaw and horizontal speed of its GNSS
    antenna's velocity, which moves at ``offset_velocity`` (N, 2) = ω × r (along, across)
    relative to the vehicle origin (``antenna_offset_velocity`` of the tight heading).

    In the vehicle frame the antenna moves at (s − ω·r_y, ω·r_x), at the angle
    δ = atan2(ω·r_x, s − ω·r_y) (s: the wheel speed) to the vehicle's x axis, so the vehicle's
    yaw is the antenna's minus δ and its speed the antenna velocity's forward component
    |v|·cos δ plus ω·r_y.
    """
    offset = np.asarray(offset_velocity, dtype=float)
    delta = np.arctan2(offset[:, 1], np.asarray(wheel_speed, dtype=float) + offset[:, 0])
    return wrap_angle(yaw - delta), speed * np.cos(delta) - offset[:, 0]
