"""Receiver positions for the Doppler rows' lines of sight: the SPP fixes smoothed along the
Doppler velocities, held where nothing anchors them.

A row's predicted range rate depends on the receiver position through the line of sight e:
an error δr in the position turns e by δr/ρ (ρ ≈ 20,000 km) and moves the row by about
|v_s,⊥|·δr/ρ, with v_s,⊥ the satellite's velocity across the line of sight (up to 3.9 km/s):
0.02 m/s per 100 m. In a street canyon single-point fixes are off by tens to hundreds of metres
(reflected pseudoranges, four-satellite geometry), the nearest fix in time can be a whole block
behind, and that bias, constant over a heading window and different per satellite, looks like
a reflection to the tight heading (simulated canyons: the fixes' errors and the tight
heading's p95 with the true positions in docs/benchmarks.md, "The GNSS velocity's settings").

The track is the least-squares fit, per ENU axis, of positions p_k to the fixes s_k and to the
displacements the Doppler velocities give between consecutive epochs:

    min Σ_k w_k (p_k − s_k)² / σ_k²  +  Σ_k (p_{k+1} − p_k − d_k)² / τ_k²,            (T1)
    d_k = ½ (v_k + v_{k+1}) Δt_k,    τ_k² = ¼ (σ_v,k² + σ_v,k+1²) Δt_k²

a tridiagonal system (a fixed-interval smoother with the velocity as its input). Where an epoch
has no velocity, its velocity is interpolated from the nearest ones in time and its σ_v grows by
``acceleration_sigma_mps2`` per second of distance to them (a car's speed changes by up to a few
m/s per second); without any velocity a step has τ_k = ∞ and links nothing. The fixes' σ_k are
their formal σ (the horizontal σ of the SPP covariance per horizontal axis, ``vertical_ratio``
times it for up), scaled per axis by the robust scatter of the normalised residuals. Reflected
fixes are biased for seconds at a time; iteratively re-weighted passes give them Huber weights
w_k (k = ``huber_k``) for the first half of the passes, then Cauchy weights (c = ``cauchy_c``),
which leave a fix a block off almost no weight once the track is near the others; on the
simulated canyons the rows' positions come several times closer than the nearest valid fix
(docs/benchmarks.md, "The GNSS velocity's settings"). (T1) is solved only on the epochs a
chain of finite steps links to a fix; the others have no solution of their own.

A canyon lasts: with two satellites for minutes there is neither a fix nor a velocity, and (T1)
alone carries the last velocity on in a straight line, kilometres off within minutes on a
simulated drive that circles (docs/benchmarks.md, "The GNSS velocity's settings"). So every
epoch gets the σ of its track position, per axis

    P_k = (1/P⁻_f,k + w_k/σ_k² + 1/P⁻_b,k)⁻¹,                                         (T2)
    P⁻_f,k = (1/P⁻_f,k−1 + w_k−1/σ_k−1²)⁻¹ + τ_k−1²   (P⁻_b,k likewise from the end)

(the smoother's variance, two-filter form: fixes average down, white velocity noise adds up),

    σ_k² = Σ_axes P_k + D_k²,   D_k = min(Σ_{j=a..k−1} δ_j, Σ_{j=k..b−1} δ_j),  δ_j = τ_j  (T3)

with a < k ≤ b the nearest anchoring fixes (w ≥ ``anchor_weight``) either side: D_k is the drift
of a velocity bias as large as its σ, which does not average down (reflected Doppler is biased
for seconds to minutes). The track is trusted where σ_k ≤ ``trusted_sigma_m`` (the default
250 m tilts a GPS line of sight, ρ ≥ 20,200 km, v_s ≤ 3.9 km/s, by at most 0.05 m/s), or twice
the best epoch's σ where that is larger (fixes that poor are all the data have). Elsewhere the
position is held at the trusted neighbour in time, before or after, whose held σ is smaller:

    σ_held,k = σ_j + |L_k − L_j|,   L_k = Σ_{i<k} min(|d_i| + |δ_i|, v_max Δt_i)          (T4)

the distance the receiver can have covered since epoch j (``max_speed_mps`` bounds a step whose
velocity is unknown). The same drive, held: the track stays within the circle's diameter of
the truth, and its lines of sight close enough for the rows (same section). Without a single
velocity (no Doppler row, no solved epoch) every step is unlinked: the fixes as they are, held
in between (it was a singular system).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import solveh_banded

from vo_doppler.geo import ecef_to_enu_rotation, ecef_to_geodetic
from vo_doppler.robust import cauchy_weight, huber_weight, irls, nmad

MIN_STEP_VARIANCE_M2 = 1e-12
"""Floor of τ_k² in (T1): a step of exactly known displacement stays a finite weight."""


@dataclass(frozen=True)
class TrackConfig:
    """The smoother's settings (module docstring)."""

    acceleration_sigma_mps2: float = 2.0
    min_fix_sigma_m: float = 1.0
    vertical_ratio: float = 2.0
    huber_k: float = 1.5
    cauchy_c: float = 2.385
    passes: int = 8
    trusted_sigma_m: float = 250.0
    anchor_weight: float = 0.5
    max_speed_mps: float = 70.0


@dataclass(frozen=True)
class ReceiverTrack:
    """Receiver positions (N, 3, ECEF) at the epochs, their σ (N,) (m, 3-D: (T3) where the
    track is trusted, (T4) where it is held) and ``held`` (N,) where the position is a trusted
    neighbour's (module docstring)."""

    position_ecef: np.ndarray
    sigma_m: np.ndarray
    held: np.ndarray


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


def _predicted_variance(weight: list[float], step_variance: list[float]) -> list[float]:
    """P⁻_f,k of (T2): the variance at epoch k from the fixes before it, carried by the steps
    (∞ where none reaches it)."""
    predicted = [math.inf]
    variance = math.inf
    for w, s in zip(weight[:-1], step_variance, strict=True):
        information = 1.0 / variance + w
        variance = (1.0 / information if information > 0.0 else math.inf) + s
        predicted.append(variance)
    return predicted


def _smoothed_variance(weight: np.ndarray, step_variance: np.ndarray) -> np.ndarray:
    """P_k of (T2) for one axis: ``weight`` (N,) w_k/σ_k², ``step_variance`` (N−1,) τ_k²."""
    forward = np.array(_predicted_variance(weight.tolist(), step_variance.tolist()))
    backward = _predicted_variance(weight[::-1].tolist(), step_variance[::-1].tolist())
    information = 1.0 / forward + weight + 1.0 / np.array(backward[::-1])
    with np.errstate(divide="ignore"):
        return np.where(information > 0.0, 1.0 / information, np.inf)


def _drift(anchor: np.ndarray, step_sigma: np.ndarray) -> np.ndarray:
    """D_k of (T3) for one axis: the smaller of the summed step σ δ_j from the nearest anchor
    before and after epoch k (∞ without one, or across a step of infinite σ)."""
    n = anchor.size
    finite = np.isfinite(step_sigma)
    summed = np.concatenate([[0.0], np.cumsum(np.where(finite, step_sigma, 0.0))])
    breaks = np.concatenate([[0], np.cumsum(~finite)])
    index = np.arange(n)
    before = np.maximum.accumulate(np.where(anchor, index, -1))
    after = np.minimum.accumulate(np.where(anchor, index, n)[::-1])[::-1]
    b, a = np.maximum(before, 0), np.minimum(after, n - 1)
    forward = np.where((before >= 0) & (breaks == breaks[b]), summed - summed[b], np.inf)
    backward = np.where((after < n) & (breaks[a] == breaks), summed[a] - summed, np.inf)
    return np.minimum(forward, backward)


def _held(t_size, trusted, sigma, path):
    """Index of the trusted epoch each epoch takes its position from (itself where trusted)
    and its σ: (T4), the neighbour before or after with the smaller one."""
    index = np.arange(t_size)
    before = np.maximum.accumulate(np.where(trusted, index, -1))
    after = np.minimum.accumulate(np.where(trusted, index, t_size)[::-1])[::-1]
    b, a = np.maximum(before, 0), np.minimum(after, t_size - 1)
    from_before = np.where(before >= 0, sigma[b] + path - path[b], np.inf)
    from_after = np.where(after < t_size, sigma[a] + path[a] - path, np.inf)
    source = np.where(from_before <= from_after, b, a)
    held_sigma = np.minimum(from_before, from_after)
    return np.where(trusted, index, source), np.where(trusted, sigma, held_sigma)


def receiver_track(
    t: np.ndarray,
    fix_ecef: np.ndarray,
    fix_sigma_m: np.ndarray,
    velocity_ecef: np.ndarray,
    velocity_covariance: np.ndarray,
    velocity_known: np.ndarray,
    config: TrackConfig = TrackConfig(),
) -> ReceiverTrack | None:
    """The receiver track at the epochs ``t`` (s) from the fixes (ECEF, NaN where an epoch has
    none; ``fix_sigma_m`` their horizontal σ) and the velocities (ECEF, covariance (N, ≥3, ≥3))
    where ``velocity_known``: (T1) where trusted, held elsewhere (module docstring); None with
    fewer than two fixes."""
    t = np.asarray(t, dtype=float)
    fix_sigma_m = np.asarray(fix_sigma_m, dtype=float)
    fixed = np.all(np.isfinite(fix_ecef), axis=1) & np.isfinite(fix_sigma_m)
    if fixed.sum() < 2 or t.size < 2:
        return None
    origin = np.median(fix_ecef[fixed], axis=0)
    lat, lon, _ = ecef_to_geodetic(origin)
    rotation = ecef_to_enu_rotation(float(lat), float(lon))
    fix = (fix_ecef - origin) @ rotation.T
    step, step_variance, linked = _velocity_steps(
        t, rotation, (velocity_ecef, velocity_covariance, velocity_known), config
    )
    # Epochs a chain of finite steps links to a fix; (T1) is singular on the others.
    component = np.concatenate([[0], np.cumsum(~linked)])
    connected = (np.bincount(component, weights=fixed) > 0)[component]
    horizontal = np.maximum(fix_sigma_m / np.sqrt(2.0), config.min_fix_sigma_m)
    fix_sigma = np.stack([horizontal, horizontal, config.vertical_ratio * horizontal], axis=1)
    fix_sigma = np.where(fixed[:, None], fix_sigma, np.inf)
    track, used, state = _robust_track(
        (fix, fix_sigma, fixed, connected), step, 1.0 / step_variance, config
    )
    dt = np.diff(t)[:, None]
    anchor = fixed[:, None] & (state[0] >= config.anchor_weight)
    step_sigma = np.sqrt(step_variance)
    variance = sum(
        _smoothed_variance(used[:, axis], step_variance[:, axis])
        + _drift(anchor[:, axis], step_sigma[:, axis]) ** 2
        for axis in range(3)
    )
    sigma = np.where(connected, np.sqrt(variance), np.inf)
    bound = max(config.trusted_sigma_m, 2.0 * float(np.min(sigma)))
    trusted = sigma <= bound
    reach = np.linalg.norm(step, axis=1) + np.linalg.norm(step_sigma, axis=1)
    reach = np.minimum(reach, config.max_speed_mps * np.abs(dt[:, 0]))
    source, sigma = _held(t.size, trusted, sigma, np.concatenate([[0.0], np.cumsum(reach)]))
    return ReceiverTrack(track[source] @ rotation + origin, sigma, ~trusted)


def _velocity_steps(t, rotation, velocities, config: TrackConfig):
    """The steps between epochs in the local frame (``rotation`` from ECEF) integrated from the
    velocities (ECEF, covariance, known; unknown ones filled, :func:`_filled_velocity`), their
    variances (inf across a gap) and whether each links its two epochs (T1)."""
    velocity_ecef, velocity_covariance, velocity_known = velocities
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
    linked = np.all(np.isfinite(step_variance) & np.isfinite(step), axis=1)
    step_variance = np.where(
        linked[:, None], np.maximum(step_variance, MIN_STEP_VARIANCE_M2), np.inf
    )
    step = np.where(linked[:, None], step, 0.0)
    return step, step_variance, linked


def _robust_track(fixes, step, step_weight, config: TrackConfig):
    """(T1) solved per axis with robust weights of the fixes (Huber, then Cauchy passes, their
    per-axis scale the NMAD of the normalised residuals): the track, the fixes' final weights
    and the IRLS state (robust weights, scale). ``fixes``: local positions, their per-axis σ,
    which epochs have one and which a chain of steps links to a fix."""
    fix, fix_sigma, fixed, connected = fixes

    def solve(state):
        """(T1) with the fixes' robust weights and per-axis scale ``state``: the track and
        the fixes' weights."""
        robust, scale = state
        weight = np.where(fixed[:, None], robust / (scale * fix_sigma) ** 2, 0.0)
        solved = np.where(connected[:, None], weight, 1.0)  # a unit weight decouples the rest
        track = [
            _solve_axis(fix[:, i], solved[:, i], step[:, i], step_weight[:, i]) for i in range(3)
        ]
        return np.stack(track, axis=1), weight

    def weigh(z, n):
        scale = np.maximum(nmad(z[fixed], axis=0, centre=False, skip_nan=True), 1e-3)
        normalised = np.abs(z) / scale
        if 2 * (n + 1) <= config.passes:
            return huber_weight(normalised, config.huber_k, floor=1e-12), scale
        return cauchy_weight(normalised, config.cauchy_c), scale

    def normalised_residual(state):
        return (fix - solve(state)[0]) / fix_sigma

    start = (np.ones((len(fix), 3)), np.ones(3))
    state = irls(normalised_residual, weigh, start, config.passes - 1)
    track, used = solve(state)
    return track, used, state


def smoothed_track(
    t: np.ndarray,
    fix_ecef: np.ndarray,
    fix_sigma_m: np.ndarray,
    velocity_ecef: np.ndarray,
    velocity_covariance: np.ndarray,
    velocity_known: np.ndarray,
    config: TrackConfig = TrackConfig(),
) -> np.ndarray | None:
    """Positions (N, 3, ECEF) of :func:`receiver_track` at the epochs ``t``; None with fewer
    than two fixes."""
    track = receiver_track(
        t, fix_ecef, fix_sigma_m, velocity_ecef, velocity_covariance, velocity_known, config
    )
    return None if track is None else track.position_ecef
