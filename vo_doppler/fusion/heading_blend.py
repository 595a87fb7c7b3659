"""Adaptive heading blend: a 1-D Kalman filter (and RTS smoother) on the VO heading offset.

This is our addition beyond [TK18]. Its correction (sec. 3.6, Eq. 11–13, see
:mod:`vo_doppler.fusion.heading_correction`) replaces the VO heading by the window's mean
absolute heading, so a good VO inherits the absolute heading's noise; a fixed blend time
constant helps a good VO but hurts a drifting one. Here the gain follows from a model of both.

State: the offset δ = (true course − VO course), a scalar in rad, held unwrapped.

* Process (VO heading drift, a random walk in distance and in turning)::

      δ(b) = δ(a) + w,   w ~ N(0, q),   q = σ_d²·ΔD(a→b) + σ_ψ²·ΔΨ(a→b)           (B1)

  with ΔD the horizontal distance the VO travelled (m) and ΔΨ the absolute yaw it turned (rad)
  between the two times. Monocular VO loses heading through small rotation errors at every
  frame (a per-distance random walk, σ_d in rad/√m) and through a yaw-scale error while turning
  (σ_ψ in rad/√rad); standing still, it drifts neither.

* Measurement of an absolute heading (yaw) h::

      z_j = wrap(h_j − c_VO(t_j)) = δ(t_j) + v_j,   v_j ~ N(0, r_j),   r_j = (s·σ_j)²·κ_j   (B2)

  at the middle time t_j of the VO chord ending at every pose (at least ``min_chord_m`` long,
  :func:`~vo_doppler.fusion.heading_correction.chord_starts`; at every pose for the
  orientation reference), c_VO(t_j) the chord's course (or the pose's yaw), h_j and its
  standard deviation σ_j interpolated between GNSS epochs, s a scale on σ_j and
  κ_j = max(1, T_c/Δt) the number of measurements within the heading's error-correlation time
  T_c: the tight heading of consecutive epochs comes from overlapping windows (T_c = its
  window), so the κ measurements of one window carry about one measurement's information.

* Forward filter, wrapping the innovation ν_j = wrap(z_j − δ⁻_j) and starting diffuse (the
  start sets δ = z₀, P = r₀)::

      P⁻_j = P_{j−1} + q_j,  S_j = P⁻_j + r_j,  K_j = P⁻_j/S_j,
      δ_j = δ⁻_j + K_j·ν_j,  P_j = (1 − K_j)·P⁻_j                                      (B3)

* Robust update (B3′): an absolute heading can be biased for seconds (a conventional Doppler
  velocity from reflected signals in a street canyon: p95 course errors of 20° on a real
  u-blox drive; a tight heading from a window whose reflected satellites looked like the
  consistent majority), far beyond its σ. Each update therefore uses Huber's weight on the
  normalised innovation u_j = ν_j/√S'_j, S'_j = P⁻_j + (s·σ_j)² the variance of the
  innovation of one measurement: κ_j of (B2) accounts for the information that correlated
  measurements share, not for the error of each, which is (s·σ_j)² whatever its neighbours
  (judged against S_j, a 20σ error of a tight heading with κ = 40 would pass as a 3σ one).
  With w_j = min(1, k/|u_j|) the innovation variance is taken as S_j/w_j (``robust`` (R2″);
  r_j inflated to S_j/w_j − P⁻_j), so an innovation beyond k standard deviations moves δ by
  at most k·√S'_j·K_j. k = ∞ gives (B3).

* Likelihood of the fit (B3″): a contaminated normal density of each innovation,
  (1 − ε)·N(ν_j; 0, S'_j) + ε/(2π), a share ε of headings being anything at all (Huber's
  ε-contamination, "Robust estimation of a location parameter", Ann. Math. Statist. 1964).
  Huber's ρ, whose cost grows with every degree of a reflected heading, made a fit in which
  the VO follows every heading cheaper than one outlier burst: one second of conventional
  headings 60° off (1° noise otherwise) on a drift-free simulated VO gave σ_d = 0.04 rad/√m
  and a corrected heading 6.4° RMS off; an outlier now costs at most ln(2π/ε).

* Robust start: z₀ is the first measurement unless it lies beyond k standard deviations
  (√(r₀ + r_m + the process variance accumulated between them), r = (s·σ)²) from the
  circular median z_m of the first ``start_measurements`` measurements at least their
  correlation time and ``start_spacing_s`` apart (:func:`decimate`); then z_m: a reflection
  can fault a second of consecutive single-epoch headings. One wrong heading (or one wrong window
  of correlated ones) cannot set δ, which the bounded update (B3′) would then leave only
  slowly. The start looks ahead by those correlation times (4 s for the tight heading's
  2-s window), the only look-ahead of the forward filter.

* RTS smoother (offline use), and between measurement nodes a < b, at a time k::

      C_j = P_j/P⁻_{j+1},  δˢ_j = δ_j + C_j·(δˢ_{j+1} − δ_j)
      δˢ(k) = δ_a + (P_a + q(a→k))/(P_a + q(a→b))·(δˢ_b − δ_a)                          (B4)

  which is the RTS recursion of (B1) carried through the steps between the nodes: with no
  measurement the smoothed offset moves from one node to the next in proportion to the
  process variance (distance and turning) accumulated. The forward (causal) filter holds the
  last estimate through gaps.

* Noise by maximum likelihood over the drive: σ_d, σ_ψ and s maximise the innovation
  log-likelihood −½·Σ(ln S_j + ν_j²/S_j) of (B3) on a log grid, over measurements at least T_c
  apart (so that their errors are close to independent, as (B2) assumes); σ_d and σ_ψ have
  floors. Without enough measurements the defaults hold. On the simulated 120-s drives the
  fit follows the VO: with the tight heading, σ_d ≈ 1–2·10⁻⁴ rad/√m and σ_ψ ≈ 1–4·10⁻⁴ with
  an exact camera calibration, σ_ψ = 0.01 with a focal length 1 % off (whose VO heading error
  grows by about 1 % of every turn), and s ≈ 1.6 (the tight heading's σ is optimistic by about
  that factor against the truth).

* Correlation time from the data (B5): a heading's T_c is structural (the tight heading's
  window) or zero (a single-epoch conventional heading), but reflections that last seconds make
  consecutive conventional headings err alike, and a fit that takes them as independent reads
  their common error as VO drift (on a simulated 120-s canyon drive: σ_d = 0.06 rad/√m, and
  a corrected heading 47° RMS off). The fit is therefore checked by the whiteness of its
  innovations (R. K. Mehra, "On the identification of variances and adaptive Kalman
  filtering", IEEE Trans. Autom. Control 1970): the lag-1 autocorrelation ρ₁ of the
  normalised innovations u_j (Huber-clipped at k) over the decimated measurements must not
  exceed 2/√n (one-sided, 97.5 %). While it does, every T_c is raised to at least a floor F
  — the median measurement spacing, then doubling up to ``max_correlation_s`` — and the noise
  fitted again; κ_j and the decimation use the accepted T_c. A negative ρ₁ (over-modelled
  correlation, as the tight heading's overlapping windows give) is accepted as it is.

The corrected trajectory rotates every VO increment by δ at its middle time and every
orientation by δ at its time, both as a yaw rotation on the world side (pitch and roll kept),
as [TK18] Eq. (12)–(13) do with the window's offset; frames as in
:func:`vo_doppler.fusion.heading_correction.correct_heading`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.choices import checked
from vo_doppler.fusion.heading_correction import HeadingReference, chord_starts, headings_at
from vo_doppler.fusion.result import CorrectionResult
from vo_doppler.geo import wrap_angle, yaw_of
from vo_doppler.model.timeseries import TIME_TOLERANCE_S, relative_times
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.robust import huber_inflated_variance, huber_psi

SIGMA_GRID = np.logspace(-4.0, -1.0, 16)
"""Candidate σ_d (rad/√m) and σ_ψ (rad/√rad) for the maximum-likelihood fit, steps of 1.6×:
σ_d from 0.06° to 57° per √(100 m), σ_ψ from 0.01 % to 10 % of the turn."""
SCALE_GRID = np.logspace(-0.6, 1.2, 10)
"""Candidate scales s of the headings' standard deviations (0.25 to 16, steps of 1.6×)."""
OUTLIER_GRID = np.array([1e-3, 1e-2, 1e-1])
"""Candidate ε of (B3″); 0.01 without a fit."""
DEFAULT_OUTLIER_FRACTION = 0.01


@dataclass(frozen=True)
class BlendConfig:
    """Parameters of (B1)–(B4); angles in rad."""

    sigma_distance_rad_per_sqrt_m: float | None = None
    """σ_d (rad/√m) of (B1); None: maximum-likelihood fit over the drive."""
    sigma_turn: float | None = None
    """σ_ψ (rad/√rad) of (B1); None: fitted with σ_d."""
    measurement_scale: float | None = None
    """s of (B2); None: fitted with σ_d."""
    default_sigma_distance_rad_per_sqrt_m: float = 0.002
    """σ_d without enough measurements to fit: 1.1° of drift per √(100 m), a common
    monocular VO (KITTI rotation errors are 0.5–2° per 100 m)."""
    default_sigma_turn: float = 0.01
    """σ_ψ without enough measurements to fit: a 90° turn adds 0.7° of drift std, as a 1 %
    yaw-scale error of the VO (e.g. a focal length 1 % off) would."""
    min_sigma_distance_rad_per_sqrt_m: float = 1e-4
    """Floor on σ_d: the VO is never trusted beyond 0.06° per √(100 m)."""
    min_sigma_turn: float = 1e-4
    """Floor on σ_ψ: 0.01 % yaw-scale error."""
    default_measurement_sigma_rad: float = np.radians(1.0)
    """σ_j of epochs whose heading carries no standard deviation (e.g. conventional headings
    read from a heading.csv written before it had their column)."""
    smooth: bool = True
    """RTS smoother (B4, offline); False: forward filter only (causal)."""
    min_chord_m: float = 0.5
    """Length of the VO chord whose direction is the course (shorter, slower motion has none)."""
    max_gap_s: float = 1.5
    """Longest gap across which the VO course (or yaw) is interpolated to an epoch."""
    min_fit_measurements: int = 20
    """Fewest measurements (after decimation to one per T_c) for the maximum-likelihood fit
    of the three noise parameters; below it the defaults hold."""
    huber_k: float = 3.0
    """k of the robust update (B3′), in standard deviations of the innovation (inf: (B3))."""
    start_measurements: int = 5
    """Measurements, at least a correlation time and ``start_spacing_s`` apart, whose median
    starts the filter (1: the first measurement)."""
    start_spacing_s: float = 1.0
    """Least spacing of the start's measurements (s): two faulty seconds among five cannot
    set the start."""
    outlier_fraction: float | None = None
    """ε of (B3″); None: fitted with σ_d on ``OUTLIER_GRID``."""
    max_correlation_s: float = 8.0
    """Largest correlation-time floor (B5) tried; beyond it the measurements are too few for
    the fit anyway (a 2-minute drive leaves fifteen)."""
    fit_chunk_bytes: int = 32 * 2**20
    """Memory (bytes) for the grid points of the noise fit filtered side by side: the grid is
    filtered in chunks of as many points as fit (:func:`grid_log_likelihood`); the fit does
    not depend on it."""


@dataclass
class OffsetMeasurements:
    """(B2) at the VO direction samples that have an absolute heading."""

    t: np.ndarray
    z: np.ndarray
    sigma: np.ndarray
    """σ_j (rad), before the scale s and the inflation κ_j."""
    correlation_s: np.ndarray
    """T_c of each epoch (s)."""

    def __len__(self) -> int:
        return len(self.t)


@dataclass
class FilterOutput:
    """Forward pass (B3) at the measurement nodes: filtered δ and P, predicted P, and the
    innovation log-likelihood (all but the first, diffuse, measurement)."""

    x: np.ndarray
    P: np.ndarray
    P_pred: np.ndarray
    log_likelihood: np.ndarray


@dataclass(frozen=True)
class NoiseModel:
    """σ_d (rad/√m) and σ_ψ (rad/√rad) of (B1), s of (B2), whether they were fitted, and the
    correlation-time floor F (s) that (B5) accepted (0: the headings' own T_c)."""

    sigma_distance: float
    sigma_turn: float
    scale: float
    fitted: bool
    correlation_floor_s: float = 0.0
    outlier_fraction: float = DEFAULT_OUTLIER_FRACTION
    """ε of (B3″)."""


def vo_direction(
    t: np.ndarray,
    positions: np.ndarray,
    rotations: np.ndarray,
    reference: HeadingReference,
    min_chord_m,
) -> tuple[np.ndarray, np.ndarray]:
    """Times and yaw (rad) of the VO direction: the course of the chord of at least
    ``min_chord_m`` ending at each pose, at the chord's middle time, or the orientation yaw at
    every pose."""
    if reference is HeadingReference.ORIENTATION:
        return t, yaw_of(rotations)
    start = chord_starts(positions, min_chord_m)
    has = np.flatnonzero(start >= 0)
    chord = positions[has, :2] - positions[start[has], :2]
    return 0.5 * (t[has] + t[start[has]]), np.arctan2(chord[:, 1], chord[:, 0])


def offset_measurements(
    t_heading: np.ndarray,
    yaw_heading: np.ndarray,
    sigma_heading: np.ndarray,
    correlation_s: np.ndarray,
    t_direction: np.ndarray,
    yaw_direction: np.ndarray,
    max_gap_s: float,
) -> OffsetMeasurements:
    """z of (B2) at the VO direction samples (step middles for the course, as [TK18] Eq. (11)'s
    course reference compares them) that have an absolute heading interpolated on the short
    arc between epochs at most ``max_gap_s`` apart; σ and T_c interpolated alike."""
    ok = np.isfinite(yaw_heading) & np.isfinite(sigma_heading)
    absolute, inside = headings_at(t_direction, t_heading, yaw_heading, ok, max_gap_s)
    t = t_direction[inside]
    t_ok = t_heading[ok]
    return OffsetMeasurements(
        t,
        wrap_angle(absolute[inside] - yaw_direction[inside]),
        np.interp(t, t_ok, sigma_heading[ok]) if len(t) else np.zeros(0),
        np.interp(t, t_ok, correlation_s[ok]) if len(t) else np.zeros(0),
    )


def inflation(measurements: OffsetMeasurements) -> np.ndarray:
    """κ_j of (B2): epochs per correlation time, at least 1."""
    if len(measurements) < 2:
        return np.ones(len(measurements))
    spacing = float(np.median(np.diff(measurements.t)))
    if spacing <= 0:
        return np.ones(len(measurements))
    return np.maximum(1.0, measurements.correlation_s / spacing)


def forward_filter(
    z: np.ndarray,
    r: np.ndarray,
    q: np.ndarray,
    huber_k: float = np.inf,
    r_single: np.ndarray | None = None,
    start: np.ndarray | float | None = None,
    outlier_fraction: np.ndarray | float = 0.0,
) -> FilterOutput:
    """(B3), robust as (B3′) with ``huber_k``, over measurements ``z`` (M,) with variances
    ``r`` (inflated by κ) and process variances ``q`` since the previous measurement (q[0]
    unused); ``r_single`` the variance of each measurement's own error, (s·σ_j)², which the
    robust weight judges (default ``r``); ``start`` the initial δ (default z[0]). ``r``,
    ``r_single`` and ``q`` may carry trailing axes of parameter sets, filtered side by side.
    The log-likelihood is that of the contaminated normal density of (B3″) with
    ``outlier_fraction`` ε (0: Gaussian), which broadcasts against those trailing axes: ε does
    not enter (B3)–(B3′), so one filter gives the likelihood of every ε (e.g. parameter sets
    of shape (G, 1) and ε of shape (E,) give a (G, E) log-likelihood)."""
    r = np.asarray(r, dtype=float)
    r_single = r if r_single is None else np.asarray(r_single, dtype=float)
    q = np.asarray(q, dtype=float)
    epsilon = np.asarray(outlier_fraction, dtype=float)
    trailing = np.broadcast_shapes(r.shape[1:], r_single.shape[1:], q.shape[1:])
    shape = (len(z), *trailing)

    def spread(a):
        return np.broadcast_to(a.reshape(a.shape + (1,) * (len(shape) - a.ndim)), shape)

    single_is_inflated = r_single is r
    r, r_single, q = spread(r), spread(r_single), spread(q)
    x = np.empty(shape)
    P = np.empty(shape)
    P_pred = np.full(shape, np.inf)
    log_likelihood = np.zeros(np.broadcast_shapes(trailing, epsilon.shape))
    if len(z) == 0:
        return FilterOutput(x, P, P_pred, log_likelihood)
    density = ContaminatedDensity.of(epsilon)
    x[0], P[0] = z[0] if start is None else start, r[0]
    for j in range(1, len(z)):
        P_pred[j] = P[j - 1] + q[j]
        S = P_pred[j] + r[j]
        S_single = S if single_is_inflated else P_pred[j] + r_single[j]
        innovation = wrap_angle(z[j] - x[j - 1])
        size = np.abs(innovation) / np.sqrt(S_single)
        gain = P_pred[j] / huber_inflated_variance(S, size, huber_k)
        x[j] = x[j - 1] + gain * innovation
        P[j] = (1.0 - gain) * P_pred[j]
        log_likelihood += density(size, S_single)
    return FilterOutput(x, P, P_pred, log_likelihood)


@dataclass(frozen=True)
class ContaminatedDensity:
    """ln[(1 − ε)·N(ν; 0, S) + ε/(2π)] of (B3″), its terms in ε taken once for every
    innovation of a filter."""

    log_inlier: np.ndarray | None
    """ln(1 − ε); None when ε = 0 everywhere (the normal density)."""
    log_outlier: np.ndarray
    """ln(ε) − ln(2π)."""

    @classmethod
    def of(cls, outlier_fraction: np.ndarray | float) -> ContaminatedDensity:
        epsilon = np.asarray(outlier_fraction, dtype=float)
        if not np.any(epsilon > 0):
            return cls(None, epsilon)
        return cls(np.log1p(-epsilon), np.log(epsilon) - np.log(2.0 * np.pi))

    def __call__(self, size: np.ndarray, variance: np.ndarray) -> np.ndarray:
        """The log-density of an innovation of ``size`` |ν|/√S, S ``variance``."""
        normal = -0.5 * size**2 - 0.5 * np.log(2.0 * np.pi * variance)
        if self.log_inlier is None:
            return normal
        return np.logaddexp(self.log_inlier + normal, self.log_outlier)


def robust_start(
    z: np.ndarray, r_single: np.ndarray, accumulated: np.ndarray, first: np.ndarray, huber_k: float
):
    """The filter's start (module docstring): z[0], unless it lies more than ``huber_k``
    standard deviations from the circular median z_m of the measurements ``first`` (the first
    few at least a correlation time apart, z[0] the first of them); then z_m. The deviation
    of z[0] − z_m is √(r₀ + r_m + Q_m − Q₀), ``r_single`` the measurements' variances (s·σ)²
    and ``accumulated`` Q the process variance of (B1) accumulated at them (both (M,) or
    (M, G) for G parameter sets, giving G starts)."""
    differences = wrap_angle(z[first] - z[0])
    median = float(np.median(differences))
    middle = first[np.argmin(np.abs(differences - median))]
    spread = np.sqrt(r_single[0] + r_single[middle] + accumulated[middle] - accumulated[0])
    return np.where(np.abs(median) > huber_k * spread, wrap_angle(z[0] + median), z[0])


def rts_smooth(forward: FilterOutput) -> tuple[np.ndarray, np.ndarray]:
    """(B4) at the measurement nodes: smoothed δ and its variance."""
    x, P = forward.x.copy(), forward.P.copy()
    for j in range(len(x) - 2, -1, -1):
        gain = forward.P[j] / forward.P_pred[j + 1] if forward.P_pred[j + 1] > 0 else 1.0
        x[j] = forward.x[j] + gain * (x[j + 1] - forward.x[j])
        P[j] = forward.P[j] + gain**2 * (P[j + 1] - forward.P_pred[j + 1])
    return x, P


@dataclass
class DriftClock:
    """Cumulative distance D and turn Ψ of the VO at its pose times, for q of (B1)."""

    t: np.ndarray
    distance: np.ndarray
    turn: np.ndarray

    @classmethod
    def from_poses(cls, t: np.ndarray, positions: np.ndarray, rotations: np.ndarray):
        step = np.hypot(*np.diff(positions[:, :2], axis=0).T)
        turn = np.abs(wrap_angle(np.diff(yaw_of(rotations))))
        return cls(
            t, np.concatenate([[0.0], np.cumsum(step)]), np.concatenate([[0.0], np.cumsum(turn)])
        )

    def variance(self, t: np.ndarray, sigma_distance, sigma_turn) -> np.ndarray:
        """σ_d²·D(t) + σ_ψ²·Ψ(t), the accumulated process variance of (B1) at times ``t``;
        with arrays of G values of σ_d and σ_ψ, one column per pair (shape (len(t), G))."""
        distance = np.interp(t, self.t, self.distance)
        turn = np.interp(t, self.t, self.turn)
        return np.multiply.outer(distance, np.square(sigma_distance)) + np.multiply.outer(
            turn, np.square(sigma_turn)
        )


def start_indices(t: np.ndarray, correlation_s: np.ndarray, config: BlendConfig) -> np.ndarray:
    """The measurements whose median may start the filter (:func:`robust_start`): the first
    ``config.start_measurements`` at least their correlation time and
    ``config.start_spacing_s`` apart."""
    spacing = np.maximum(correlation_s, config.start_spacing_s)
    return decimate(t, spacing)[: config.start_measurements]


def decimate(t: np.ndarray, spacing_s: np.ndarray) -> np.ndarray:
    """Indices of measurements kept greedily so that each is at least its own correlation
    time after the previous kept one (within :data:`TIME_TOLERANCE_S`).

    Computed on times relative to the first, comparing differences: the indices do not depend
    on a constant shift of every time (GPS seconds or seconds from the start of a log)."""
    t = np.asarray(t, dtype=float)
    relative = t - t[0] if len(t) else t
    keep = []
    last = -np.inf
    for j, (tj, gap) in enumerate(zip(relative, spacing_s, strict=True)):
        if tj - last >= gap - TIME_TOLERANCE_S:
            keep.append(j)
            last = tj
    return np.asarray(keep, dtype=int)


def innovation_whiteness(
    measurements: OffsetMeasurements, clock: DriftClock, noise: NoiseModel, config: BlendConfig
) -> tuple[float, int]:
    """(ρ₁, n) of (B5): the lag-1 autocorrelation of the normalised innovations u_j (clipped at
    ``config.huber_k``) of the forward filter (B3′) with ``noise`` over the decimated
    measurements, and the number of pairs it is taken over (ρ₁ NaN below three)."""
    keep = decimate(measurements.t, measurements.correlation_s)
    z = measurements.z[keep]
    r = (noise.scale * measurements.sigma[keep]) ** 2
    accumulated = clock.variance(measurements.t[keep], noise.sigma_distance, noise.sigma_turn)
    first = start_indices(measurements.t[keep], measurements.correlation_s[keep], config)
    if len(keep) < 4:
        return float("nan"), max(len(keep) - 2, 0)
    start = robust_start(z, r, accumulated, first, config.huber_k)
    q = np.diff(accumulated, prepend=accumulated[:1])
    forward = forward_filter(z, r, q, config.huber_k, start=start)
    innovation = wrap_angle(z[1:] - forward.x[:-1]) / np.sqrt(forward.P_pred[1:] + r[1:])
    u = huber_psi(innovation, config.huber_k)
    u = u - u.mean()
    denominator = float(np.sum(u**2))
    rho = float(np.sum(u[1:] * u[:-1]) / denominator) if denominator > 0 else float("nan")
    return rho, len(u) - 1


def whitened_noise(
    measurements: OffsetMeasurements, clock: DriftClock, config: BlendConfig
) -> tuple[OffsetMeasurements, NoiseModel]:
    """The measurements with their T_c raised to the floor that (B5) accepts, and the noise
    fitted with it (:func:`fit_process_noise`); unchanged when nothing is fitted."""
    spacing = float(np.median(np.diff(measurements.t))) if len(measurements) > 1 else 0.0
    floor = 0.0
    while True:
        raised = replace(measurements, correlation_s=np.maximum(measurements.correlation_s, floor))
        noise = replace(fit_process_noise(raised, clock, config), correlation_floor_s=floor)
        if not noise.fitted or spacing <= 0:
            return raised, noise
        rho, pairs = innovation_whiteness(raised, clock, noise, config)
        following = 2.0 * floor if floor > 0 else spacing
        if not rho > 2.0 / np.sqrt(max(pairs, 1)) or following > config.max_correlation_s:
            return raised, noise
        floor = following


def fit_process_noise(
    measurements: OffsetMeasurements, clock: DriftClock, config: BlendConfig
) -> NoiseModel:
    """σ_d, σ_ψ, s and ε (those the config leaves None) maximising the innovation likelihood
    (B3″) over decimated measurements (module docstring), each on its grid with its floor; the
    defaults when fewer than ``min_fit_measurements`` remain or nothing is left to fit."""
    keep = decimate(measurements.t, measurements.correlation_s)
    fixed = (
        config.sigma_distance_rad_per_sqrt_m,
        config.sigma_turn,
        config.measurement_scale,
        config.outlier_fraction,
    )
    defaults = (
        config.default_sigma_distance_rad_per_sqrt_m,
        config.default_sigma_turn,
        1.0,
        DEFAULT_OUTLIER_FRACTION,
    )
    chosen = [d if f is None else f for f, d in zip(fixed, defaults, strict=True)]
    if len(keep) < config.min_fit_measurements or all(f is not None for f in fixed[:3]):
        return NoiseModel(*chosen[:3], fitted=False, outlier_fraction=chosen[3])
    grids = (
        np.maximum(SIGMA_GRID, config.min_sigma_distance_rad_per_sqrt_m),
        np.maximum(SIGMA_GRID, config.min_sigma_turn),
        SCALE_GRID,
        OUTLIER_GRID,
    )
    axes = [np.array([f]) if f is not None else g for f, g in zip(fixed, grids, strict=True)]
    grid = tuple(g.ravel() for g in np.meshgrid(*axes[:3], indexing="ij"))
    log_likelihood = grid_log_likelihood(measurements, keep, clock, grid, axes[3], config)
    point, outlier = np.unravel_index(np.argmax(log_likelihood), log_likelihood.shape)
    d, psi, scale = (float(g[point]) for g in grid)
    return NoiseModel(d, psi, scale, True, outlier_fraction=float(axes[3][outlier]))


FIT_FLOATS_PER_MEASUREMENT = 8
"""Floats per measurement and grid point alive at once in :func:`grid_log_likelihood`: the
accumulated variance and its two terms, q, r, and the filter's δ, P and P⁻ (B3)."""


def grid_log_likelihood(
    measurements: OffsetMeasurements,
    keep: np.ndarray,
    clock: DriftClock,
    grid: tuple[np.ndarray, np.ndarray, np.ndarray],
    outlier_fractions: np.ndarray,
    config: BlendConfig,
) -> np.ndarray:
    """Innovation log-likelihood (B3″), from the robust start, over the measurements ``keep``
    for every grid point (σ_d, σ_ψ, s) (rows) and every ε of ``outlier_fractions`` (columns):
    one filter per point gives every ε's likelihood (ε enters only the density). The points
    are filtered side by side in chunks of at most ``config.fit_chunk_bytes`` (at least one
    point; each point's filter is elementwise in the points, so its value does not depend on
    the chunk it is in)."""
    grid_d, grid_psi, grid_s = grid
    t, z, variance = measurements.t[keep], measurements.z[keep], measurements.sigma[keep] ** 2
    per_point = 8 * FIT_FLOATS_PER_MEASUREMENT * max(len(keep), 1)
    size = max(1, config.fit_chunk_bytes // per_point)
    first = start_indices(t, measurements.correlation_s[keep], config)
    out = np.empty((grid_d.size, len(outlier_fractions)))
    for begin in range(0, grid_d.size, size):
        part = slice(begin, begin + size)
        accumulated = clock.variance(t, grid_d[part], grid_psi[part])
        q = np.diff(accumulated, axis=0, prepend=accumulated[:1])
        r = np.multiply.outer(variance, grid_s[part] ** 2)
        start = robust_start(z, r, accumulated, first, config.huber_k)
        out[part] = forward_filter(
            z,
            r[..., None],
            q[..., None],
            config.huber_k,
            start=start[:, None],
            outlier_fraction=outlier_fractions,
        ).log_likelihood
    return out


def offset_at(
    t_query: np.ndarray,
    t_node: np.ndarray,
    forward: FilterOutput,
    smoothed: tuple[np.ndarray, np.ndarray] | None,
    clock_node: np.ndarray,
    clock_query: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """δ and its variance at query times from the node estimates (``clock_*``: accumulated
    process variance of (B1) at the nodes and at the queries).

    Forward (``smoothed`` None, causal): the last node's estimate is held, its variance
    growing; before the first node δ = 0 (nothing known yet). Smoothed: (B4) between nodes,
    the end nodes' estimates held outside them."""
    n_query = len(t_query)
    if len(t_node) == 0:
        return np.zeros(n_query), np.full(n_query, np.inf)
    a = np.searchsorted(t_node, t_query, side="right") - 1
    before = a < 0
    a = np.clip(a, 0, len(t_node) - 1)
    grown = np.maximum(clock_query - clock_node[a], 0.0)
    held = forward.P[a] + grown
    if smoothed is None:
        return np.where(before, 0.0, forward.x[a]), np.where(before, np.inf, held)
    x_s, P_s = smoothed
    b = np.minimum(a + 1, len(t_node) - 1)
    predicted = forward.P[a] + np.maximum(clock_node[b] - clock_node[a], 0.0)
    interior = (b > a) & (predicted > 0)
    weight = np.where(interior, held / np.where(interior, predicted, 1.0), 0.0)
    value = np.where(interior, forward.x[a] + weight * (x_s[b] - forward.x[a]), x_s[a])
    variance = np.where(
        interior,
        held - weight * held + weight**2 * P_s[b],
        P_s[a] + grown,
    )
    first_grown = np.maximum(clock_node[0] - clock_query, 0.0)
    return np.where(before, x_s[0], value), np.where(before, P_s[0] + first_grown, variance)


def blend_heading(
    vehicle: Trajectory,
    t_heading: np.ndarray,
    yaw_heading: np.ndarray,
    sigma_heading: np.ndarray | float | None = None,
    valid: np.ndarray | None = None,
    correlation_s: np.ndarray | float = 0.0,
    config: BlendConfig = BlendConfig(),
    reference: HeadingReference = HeadingReference.COURSE,
) -> CorrectionResult:
    """Correct the VO heading with absolute headings by the Kalman blend (B1)–(B4).

    ``t_heading``/``yaw_heading`` (yaw, rad) are on the trajectory's clock; ``sigma_heading``
    their standard deviations (NaN or None: ``default_measurement_sigma_rad``), ``valid`` marks
    the usable epochs, ``correlation_s`` is T_c of (B2) per epoch or for all (the tight
    heading's window; 0 for the single-epoch conventional heading); ``reference`` compares
    them with the VO's 'course' or its 'orientation' yaw. Frames as in
    :func:`~vo_doppler.fusion.heading_correction.correct_heading`."""
    reference = checked(HeadingReference, reference, "reference")
    t_heading = np.asarray(t_heading, dtype=float)
    yaw, sigma, correlation = _measured(
        len(t_heading), (yaw_heading, sigma_heading, valid), correlation_s, config
    )
    poses = vehicle.matrices
    # Every step on times relative to the first pose: nothing depends on the time origin.
    origin = float(vehicle.t[0]) if len(vehicle.t) else 0.0
    t = relative_times(vehicle.t, origin)
    t_heading = relative_times(t_heading, origin)
    positions = poses[:, :3, 3] - (poses[0, :3, 3] if len(poses) else 0.0)
    rotations = poses[:, :3, :3]
    t_direction, yaw_direction = vo_direction(
        t, positions, rotations, reference, config.min_chord_m
    )
    measurements = offset_measurements(
        t_heading, yaw, sigma, correlation, t_direction, yaw_direction, config.max_gap_s
    )
    clock = DriftClock.from_poses(t, positions, rotations)
    measurements, noise = whitened_noise(measurements, clock, config)
    clock_node = clock.variance(measurements.t, noise.sigma_distance, noise.sigma_turn)
    r_single = np.maximum((noise.scale * measurements.sigma) ** 2, 1e-18)
    q = np.diff(clock_node, prepend=clock_node[:1])
    start = None
    if len(measurements):
        first = start_indices(measurements.t, measurements.correlation_s, config)
        start = robust_start(measurements.z, r_single, clock_node, first, config.huber_k)
    forward = forward_filter(
        measurements.z, r_single * inflation(measurements), q, config.huber_k, r_single, start
    )
    smoothed = rts_smooth(forward) if config.smooth else None
    middle = np.concatenate([t[:1], 0.5 * (t[1:] + t[:-1])])
    delta_step, _ = offset_at(
        middle,
        measurements.t,
        forward,
        smoothed,
        clock_node,
        clock.variance(middle, noise.sigma_distance, noise.sigma_turn),
    )
    delta, variance = offset_at(
        t,
        measurements.t,
        forward,
        smoothed,
        clock_node,
        clock.variance(t, noise.sigma_distance, noise.sigma_turn),
    )
    corrected = _turned(vehicle, (positions, rotations), delta_step, delta)
    _, has_absolute = headings_at(t, t_heading, yaw, None, config.max_gap_s)
    return CorrectionResult(
        corrected,
        delta,
        has_absolute,
        correction_sigma=np.sqrt(variance),
        noise=noise,
        measurements=len(measurements),
    )


def _measured(n_heading, headings, correlation_s, config: BlendConfig):
    """The absolute headings of :func:`blend_heading` (``headings`` = yaw, σ, valid), NaN where
    not valid, their σ (``default_measurement_sigma_rad`` where NaN or None) and T_c of (B2),
    each per epoch."""
    yaw_heading, sigma_heading, valid = headings
    yaw = np.asarray(yaw_heading, dtype=float).copy()
    if valid is not None:
        yaw[~np.asarray(valid, dtype=bool)] = np.nan
    sigma = np.broadcast_to(
        np.asarray(np.nan if sigma_heading is None else sigma_heading, dtype=float), (n_heading,)
    )
    sigma = np.where(np.isfinite(sigma), sigma, config.default_measurement_sigma_rad)
    correlation = np.broadcast_to(np.asarray(correlation_s, dtype=float), (n_heading,))
    return yaw, sigma, correlation


def _turned(vehicle: Trajectory, relative_poses, delta_step, delta) -> Trajectory:
    """The VO trajectory corrected by the heading offset (B4): each step (positions relative to
    the first pose, ``relative_poses`` = positions, rotations) turned by the offset at its
    middle ``delta_step``, each orientation by the offset ``delta`` at its pose."""
    positions, rotations = relative_poses
    poses = vehicle.matrices
    turn_step = Rotation.from_euler("z", delta_step[:, None]).as_matrix()
    steps = np.einsum("nij,nj->ni", turn_step[1:], np.diff(positions, axis=0))
    corrected_positions = np.concatenate([positions[:1], positions[:1] + np.cumsum(steps, axis=0)])
    corrected_rotations = Rotation.from_euler("z", delta[:, None]).as_matrix() @ rotations
    corrected_positions += poses[0, :3, 3] if len(poses) else 0.0
    return Trajectory(
        vehicle.t.copy(), corrected_positions, Rotation.from_matrix(corrected_rotations)
    )
