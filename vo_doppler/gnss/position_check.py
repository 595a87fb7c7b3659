"""Single-point fixes checked against each other along the Doppler velocities: what an epoch's
own chi-square test cannot see, and how far the formal σ understate the real scatter.

In a street canyon most satellites are reflected or diffracted, each pseudorange delayed by
metres to tens of metres; the biases that are common to the satellites, or grow with their
elevation, move the fix and the clock without showing in the residuals (the Hong Kong canyon
drive: fixes 10 m off at the median and 137 m in height with a dozen satellites whose weighted
residuals pass the test). The geometry of those paths changes as the car moves, so the fixes of
a few seconds apart disagree; the Doppler velocity, thirty times more precise than a fix over
such spans, carries each fix to its neighbours' times. For each fix k that passed its own test
and the others j within ±``WINDOW_S`` linked to it by known velocities (per ENU axis):

    p̂_k = median_j (s_j + D_k − D_j),    z_k = (s_k − p̂_k) / √(σ_k² + σ_p̂²)           (P1)

with D the displacement integrated from the velocities (trapezoid) and σ_p̂² = (π/2)·median_j
(σ_j² + V_jk)/n, V_jk the variance the velocities add between j and k (the median's variance
for n Gaussian samples). The robust scale λ = max(1, 1.4826·median |z|) over the recording, one
for the horizontal axes and one for up, is how much the scatter exceeds the stated σ (the
velocity's (I1) of docs/design.md, with the Doppler track in place of the car's sensors); the
fix stays valid only if |z_k| ≤ ``GATE``·λ on every axis, and its σ and protection levels are
multiplied by λ. A fix with fewer than ``MIN_NEIGHBOURS`` linked neighbours keeps its own
verdict. Limits: a bias that lasts the whole window moves the neighbours with the fix and is
not seen, and a static receiver's constant error never shows (the σ budget of the satellites'
orbits, clocks and atmosphere, ``pseudorange_noise``, must cover it).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from vo_doppler.geo import EnuFrame
from vo_doppler.gnss.spp import nearest_time
from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution
from vo_doppler.robust import nmad

WINDOW_S = 60.0
"""Half-width (s) of the neighbours: longer than a canyon's reflection episodes (on the Hong Kong
drive fixes 110–125 m too high for 20 s at a stop), so that most neighbours lie outside the
episode of a biased fix. Hong Kong canyon, valid fixes beyond 3σ horizontally (±5, 10, 30,
60 s): 25, 14, 7, 2 %."""
GATE = 3.29
"""|z| beyond which a fix is inconsistent: a false-alarm rate of 0.001 for Gaussian errors."""
MIN_NEIGHBOURS = 3
ACCELERATION_SIGMA_MPS2 = 2.0
"""Where an epoch has no velocity, it is interpolated from the nearest known ones, its σ grown
by this much per second away from them (a car's speed changes by a few m/s per second)."""
MAX_STEP_S = 5.0
"""A step between epochs longer than this links nothing (no velocity to carry a fix across)."""


def doppler_consistency(spp: SppSolution, velocity: VelocitySolution) -> SppSolution:
    """``spp`` with (P1) applied (module docstring): ``valid`` the verified fixes consistent
    with their neighbours, σ and protection levels scaled by λ, ``consistency_scale`` = (λ_h,
    λ_u) and ``consistency_tested`` the fixes (P1) could judge."""
    verified = spp.valid if spp.verified is None else spp.verified
    if verified.sum() < MIN_NEIGHBOURS + 1 or spp.horizontal_sigma_m is None:
        return spp
    frame = EnuFrame.from_ecef(np.median(spp.position_ecef[verified], axis=0))
    fix = frame.ecef_to_enu(spp.position_ecef)
    horizontal = spp.horizontal_sigma_m / np.sqrt(2.0)
    vertical = spp.vertical_sigma_m if spp.vertical_sigma_m is not None else 2.0 * horizontal
    sigma = np.column_stack([horizontal, horizontal, vertical])
    rotation = frame.rotation
    known = velocity.valid if velocity.untestable is None else velocity.valid | velocity.untestable
    known = known & np.all(np.isfinite(velocity.velocity_ecef), axis=1)
    if not known.any():
        return spp
    v, v_var = _filled_velocity(spp.t, velocity, known, rotation)
    dt = np.diff(spp.t)
    step = 0.5 * (v[:-1] + v[1:]) * dt[:, None]
    step_var = 0.25 * (v_var[:-1] + v_var[1:]) * dt[:, None] ** 2
    linked = np.all(np.isfinite(step), axis=1) & (dt <= MAX_STEP_S)
    segment = np.concatenate([[0], np.cumsum(~linked)])
    displacement = np.concatenate(
        [np.zeros((1, 3)), np.cumsum(np.where(linked[:, None], step, 0.0), axis=0)]
    )
    drift = np.concatenate(
        [np.zeros((1, 3)), np.cumsum(np.where(linked[:, None], step_var, 0.0), axis=0)]
    )
    z = np.full((spp.t.size, 3), np.nan)
    candidates = np.flatnonzero(verified)
    for k in candidates:
        near = candidates[
            (np.abs(spp.t[candidates] - spp.t[k]) <= WINDOW_S)
            & (candidates != k)
            & (segment[candidates] == segment[k])
        ]
        if near.size < MIN_NEIGHBOURS:
            continue
        carried = fix[near] + displacement[k] - displacement[near]
        variance = sigma[near] ** 2 + np.abs(drift[k] - drift[near])
        centre = np.median(carried, axis=0)
        centre_var = 0.5 * np.pi * np.median(variance, axis=0) / near.size
        z[k] = (fix[k] - centre) / np.sqrt(sigma[k] ** 2 + centre_var)
    tested = np.all(np.isfinite(z), axis=1)
    if not tested.any():
        return spp
    scale_h = max(1.0, nmad(z[tested, :2], centre=False))
    scale_u = max(1.0, nmad(z[tested, 2], centre=False))
    limit = GATE * np.array([scale_h, scale_h, scale_u])
    consistent = ~tested | np.all(np.abs(np.nan_to_num(z)) <= limit, axis=1)
    return replace(
        spp,
        valid=verified & consistent,
        horizontal_sigma_m=spp.horizontal_sigma_m * scale_h,
        vertical_sigma_m=None if spp.vertical_sigma_m is None else spp.vertical_sigma_m * scale_u,
        horizontal_protection_m=_scaled(spp.horizontal_protection_m, scale_h),
        vertical_protection_m=_scaled(spp.vertical_protection_m, scale_u),
        consistency_scale=(scale_h, scale_u),
        consistency_tested=tested,
    )


def _filled_velocity(t, velocity, known, rotation):
    """ENU velocities and their variances per axis at every epoch: the solution's where
    ``known``, else interpolated in time from the known ones with the variance of a speed
    change of ``ACCELERATION_SIGMA_MPS2`` per second to the nearest known epoch."""
    enu = velocity.velocity_ecef[known] @ rotation.T
    cov = rotation @ velocity.covariance[known][:, :3, :3] @ rotation.T
    var = np.nan_to_num(np.diagonal(cov, axis1=1, axis2=2))
    v = np.column_stack([np.interp(t, t[known], enu[:, i]) for i in range(3)])
    v_var = np.column_stack([np.interp(t, t[known], var[:, i]) for i in range(3)])
    gap = np.abs(t - t[known][nearest_time(t[known], t)])
    return v, v_var + (ACCELERATION_SIGMA_MPS2 * gap[:, None]) ** 2


def _scaled(values: np.ndarray | None, scale: float) -> np.ndarray | None:
    return None if values is None else values * scale
