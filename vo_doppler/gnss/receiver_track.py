"""Receiver positions for the Doppler rows' lines of sight: the SPP fixes smoothed along the
Doppler velocities.

A row's predicted range rate depends on the receiver position through the line of sight e:
an error δr in the position turns e by δr/ρ (ρ ≈ 20,000 km) and moves the row by about
|v_s,⊥|·δr/ρ, with v_s,⊥ the satellite's velocity across the line of sight (up to 3.9 km/s):
0.02 m/s per 100 m. In a street canyon single-point fixes are off by tens to hundreds of metres
(reflected pseudoranges, four-satellite geometry), the nearest fix in time can be a whole block
behind, and that bias, constant over a heading window and different per satellite, looks like
a reflection to the tight heading (simulated canyons: fixes 27–86 m off at the median, 150–290 m
at p95; the tight heading's p95 0.61° → 0.28° with the true positions).

The track is the least-squares fit, per ENU axis, of positions p_k to the fixes s_k and to the
displacements the Doppler velocities give between consecutive epochs:

    min Σ_k w_k (p_k − s_k)² / σ_k²  +  Σ_k (p_{k+1} − p_k − d_k)² / τ_k²,
    d_k = ½ (v_k + v_{k+1}) Δt_k,    τ_k² = ¼ (σ_v,k² + σ_v,k+1²) Δt_k²

a tridiagonal system (a fixed-interval smoother with the velocity as its input). Where an epoch
has no velocity, its velocity is interpolated from the nearest ones in time and its σ_v grows by
``acceleration_sigma_mps2`` per second of distance to them (a car's speed changes by up to a few
m/s per second). The fixes' σ_k are their formal σ (the horizontal σ of the SPP covariance per
horizontal axis, ``vertical_ratio`` times it for up), scaled per axis by the robust scatter of
the normalised residuals. Reflected fixes are biased for seconds at a time; iteratively
re-weighted passes give them Huber weights w_k (k = ``huber_k``) for the first half of the
passes, then Cauchy weights (c = ``cauchy_c``), which leave a fix a block off almost no weight
once the track is near the others. Simulated canyons: the rows' positions 6–19 m off at the
median, 15–52 m at p95 (from 27–86 m and 150–290 m with the nearest valid fix).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import solveh_banded

from vo_doppler.geo import ecef_to_enu_rotation, ecef_to_geodetic
from vo_doppler.gnss.doppler_noise import MAD_TO_SIGMA


@dataclass(frozen=True)
class TrackConfig:
    """The smoother's settings (module docstring)."""

    acceleration_sigma_mps2: float = 2.0
    min_fix_sigma_m: float = 1.0
    vertical_ratio: float = 2.0
    huber_k: float = 1.5
    cauchy_c: float = 2.385
    passes: int = 8


def _filled_velocity(t, velocity, sigma, known, acceleration_sigma):
    """Velocities (N, 3) and their σ (N, 3) at every epoch: measured ones where ``known``, else
    interpolated in time with σ grown by the distance in time to the nearest measured one."""
    if not known.any():
        return np.zeros_like(velocity), np.full_like(velocity, np.inf)
    tk = t[known]
    filled = np.stack([np.interp(t, tk, velocity[known, i]) for i in range(3)], axis=1)
    index = np.clip(np.searchsorted(tk, t), 1, max(tk.size - 1, 1))
    gap = np.minimum(np.abs(t - tk[index - 1]), np.abs(t - tk[np.minimum(index, tk.size - 1)]))
    grown = np.where(known[:, None], sigma, 0.0) ** 2 + (acceleration_sigma * gap[:, None]) ** 2
    return filled, np.sqrt(grown)


def _solve_axis(fix, fix_weight, step, step_weight):
    """Minimiser of Σ fix_weight (p − fix)² + Σ step_weight (Δp − step)² (tridiagonal)."""
    n = fix.size
    diagonal = fix_weight.copy()
    diagonal[:-1] += step_weight
    diagonal[1:] += step_weight
    right = fix_weight * np.nan_to_num(fix)
    right[:-1] -= step_weight * step
    right[1:] += step_weight * step
    bands = np.zeros((2, n))
    bands[0, 1:] = -step_weight
    bands[1] = diagonal
    return solveh_banded(bands, right)


def smoothed_track(
    t: np.ndarray,
    fix_ecef: np.ndarray,
    fix_sigma_m: np.ndarray,
    velocity_ecef: np.ndarray,
    velocity_covariance: np.ndarray,
    velocity_known: np.ndarray,
    config: TrackConfig = TrackConfig(),
) -> np.ndarray | None:
    """Positions (N, 3, ECEF) at the epochs ``t`` from the fixes (NaN where an epoch has none;
    ``fix_sigma_m`` their horizontal σ) and the velocities (ECEF, covariance (N, ≥3, ≥3)) where
    ``velocity_known`` (module docstring); None with fewer than two fixes."""
    t = np.asarray(t, dtype=float)
    fixed = np.all(np.isfinite(fix_ecef), axis=1)
    if fixed.sum() < 2 or t.size < 2:
        return None
    origin = np.median(fix_ecef[fixed], axis=0)
    lat, lon, _ = ecef_to_geodetic(origin)
    rotation = ecef_to_enu_rotation(float(lat), float(lon))
    fix = (fix_ecef - origin) @ rotation.T
    known = np.asarray(velocity_known, dtype=bool) & np.all(np.isfinite(velocity_ecef), axis=1)
    velocity = np.where(known[:, None], np.nan_to_num(velocity_ecef) @ rotation.T, 0.0)
    covariance = rotation @ np.nan_to_num(np.asarray(velocity_covariance)[:, :3, :3]) @ rotation.T
    velocity_sigma = np.sqrt(np.clip(np.diagonal(covariance, axis1=1, axis2=2), 0.0, None))
    velocity, velocity_sigma = _filled_velocity(
        t, velocity, velocity_sigma, known, config.acceleration_sigma_mps2
    )
    dt = np.diff(t)[:, None]
    step = 0.5 * (velocity[:-1] + velocity[1:]) * dt
    step_variance = 0.25 * (velocity_sigma[:-1] ** 2 + velocity_sigma[1:] ** 2) * dt**2
    step_weight = 1.0 / np.maximum(step_variance, 1e-12)
    horizontal = np.nan_to_num(fix_sigma_m, nan=np.inf) / np.sqrt(2.0)
    horizontal = np.maximum(horizontal, config.min_fix_sigma_m)
    fix_sigma = np.stack([horizontal, horizontal, config.vertical_ratio * horizontal], axis=1)
    fix_sigma = np.where(fixed[:, None], fix_sigma, np.inf)
    scale = np.ones(3)
    robust = np.ones((t.size, 3))
    track = np.zeros((t.size, 3))
    for done in range(1, config.passes + 1):
        weight = np.where(fixed[:, None], robust / (scale * fix_sigma) ** 2, 0.0)
        for axis in range(3):
            track[:, axis] = _solve_axis(
                fix[:, axis], weight[:, axis], step[:, axis], step_weight[:, axis]
            )
        z = (fix - track) / fix_sigma
        scale = np.maximum(MAD_TO_SIGMA * np.nanmedian(np.abs(z[fixed]), axis=0), 1e-3)
        normalised = np.abs(z) / scale
        if 2 * done <= config.passes:
            robust = np.minimum(1.0, config.huber_k / np.maximum(normalised, 1e-12))
        else:
            robust = 1.0 / (1.0 + (normalised / config.cauchy_c) ** 2)
    return track @ rotation + origin
