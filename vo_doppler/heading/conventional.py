"""Conventional heading ([TK18] sec. 3.2): the direction of a Doppler velocity solution, and its
standard deviation from the velocity covariance; and the conventional velocities as the heading
stage takes them (:class:`ConventionalVelocity`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.geo import EnuFrame, wrap_angle
from vo_doppler.model.gnss_solutions import VelocitySolution


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


@dataclass(frozen=True)
class ConventionalVelocity:
    """The GNSS stage's conventional velocities as the heading stage takes them, one per GNSS
    epoch ([TK18] sec. 3.2; docs/design.md (2), (2a)); the σ are optional."""

    velocity_enu: np.ndarray
    """ENU velocity (m/s), (E, 3)."""
    valid: np.ndarray
    """The GNSS stage's verdict (``VelocitySolution.valid``)."""
    sigma_mps: np.ndarray | None = None
    """σ of each velocity (√trace of its covariance); where given, only velocities within
    ``HeadingPipelineConfig.calibration_max_velocity_sigma_mps`` calibrate the sensors."""
    yaw_sigma_rad: np.ndarray | None = None
    """σ of each conventional heading (:func:`velocity_heading_sigma`), kept in the heading
    table for the heading correction."""
    speed_sigma_mps: np.ndarray | None = None
    """σ of each horizontal speed. With ``yaw_sigma_rad`` it lets the heading stage test the
    velocity against the calibrated gyro and wheel speed (docs/design.md (I1))."""
    untestable: np.ndarray | None = None
    """Epochs solved without redundancy (four satellites), whose fault the GNSS stage cannot
    detect (``VelocitySolution.untestable``). They are not valid, but they calibrate the
    sensors under the same gates as the valid ones: the calibration's robust fit over many
    epochs is their test, as in [TK18] sec. 3.3, whose conventional headings need only four
    satellites. In a street canyon they are most of the solved epochs (a simulated 120-s canyon
    drive: 190 valid, 414 more untestable), and a calibration from the few valid ones converges
    late."""
    vertical_sigma_mps: np.ndarray | None = None
    """σ of each up velocity, whose share the grade prior's σ leaves out
    (:func:`~vo_doppler.heading.grade.grade_prior`)."""

    @classmethod
    def from_solution(cls, velocity: VelocitySolution, enu: EnuFrame) -> ConventionalVelocity:
        """A velocity solution's velocities, verdicts and σ, its heading σ from its covariance
        turned into the ENU frame ``enu`` (:func:`velocity_heading_sigma`)."""
        return cls(
            velocity_enu=velocity.velocity_enu,
            valid=velocity.valid,
            sigma_mps=velocity.sigma_mps,
            yaw_sigma_rad=velocity_heading_sigma(
                velocity.velocity_enu, velocity.covariance, enu.rotation
            ),
            speed_sigma_mps=velocity.speed_sigma_mps,
            untestable=velocity.untestable,
            vertical_sigma_mps=velocity.vertical_sigma_mps,
        )
