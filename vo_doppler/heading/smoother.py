"""The tight headings of a drive combined through the gyro: a robust Rauch–Tung–Striebel smoother
of the offset between the absolute heading and the integrated, calibrated yaw rate.

Each tightly coupled window ([TK18], design (T1)–(T4)) gives its own heading θ_k with σ_k; at
1 Hz in a street canyon a window holds a few weak satellites and σ_k is several degrees, with
heavy tails (a window whose rows are mostly scattered signals). Over seconds the gyro is far
better than that: its calibrated integral Φ (design (C1)) turns by the vehicle's true yaw up to
a slowly varying offset. So the heading is ψ_k = Φ_k + c_k, and the windows measure c:

    z_k = wrap(θ_k − Φ_k) = c_k + e_k,        e_k ~ σ_k²·n_k / w_k                      (S1)
    c_{k+1} = c_k − δb·Δt + η_k,   η_k ~ N(0, q_a·Δt + (σ_s·|ΔΦ_k|)²),   δb_{k+1} = δb_k + ξ_k
                                                                                        (S2)

δb is the error of the calibrated gyro bias (prior σ from the calibration, a random walk of
``bias_walk`` per √s), q_a the gyro's angle random walk (from its own sample noise unless
given), σ_s its scale-factor error (a turn of ΔΦ adds σ_s·ΔΦ). n_k = max(1, W_k/Δt) is the
number of windows that share a row with window k: their errors are correlated, and counting
each window 1/n_k times gives the information of the independent windows. The smoother
(Rauch, Tung & Striebel, "Maximum likelihood estimates of linear dynamic systems", AIAA J. 3(8),
1965) gives c at every epoch from all windows before and after it, so a heading rests on tens of
seconds of windows instead of one.

Robustness (robust.py, (R2)–(R3)): the smoother is run again with weights w_k of the windows'
normalised residuals u_k = wrap(z_k − ĉ_k)/σ_k, Huber's first and then Cauchy's, which
redescend: a window on a mirror root or on reflected satellites stops pulling. The first
weights come from a consensus: each window's distance to the circular median of the offsets
within ±``consensus_span_s``. The smoothed σ is scaled by the windows' a-posteriori variance
factor λ = max(1, NMAD(u)) (their σ_k are models of the noise, which real canyons exceed).

An epoch is available where Φ is defined and the smoothed σ is within the tight heading's
``max_sigma_rad``; reliable where its σ is within ``reliable_max_sigma_rad`` and the windows
that agree (weight ≥ ½) within ±``consensus_span_s`` count at least ``min_support`` independent
windows (Σ w_j/n_j): a consensus in seconds with the gyro-propagated uncertainty, at any rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vo_doppler.geo import wrap_angle
from vo_doppler.robust import cauchy_weight, huber_weight, irls, nmad


@dataclass(frozen=True)
class HeadingSmootherConfig:
    """Settings of the smoother (module docstring); angles in rad, times in s."""

    enabled: bool = False
    angle_random_walk_rad_per_sqrt_s: float | None = None
    """q_a of (S2) as a σ per √s; None: from the yaw rate's own sample noise."""
    min_angle_random_walk_rad_per_sqrt_s: float = float(np.radians(0.005))
    """The least q_a: a gyro quantised or filtered smooth still wanders."""
    scale_sigma: float = 0.005
    """σ_s of (S2): the gyro's scale-factor error, relative (0.5 %: automotive yaw-rate
    sensors are specified to 1–2 %, the turns of a drive calibrate them partly)."""
    bias_walk_rad_per_s_sqrt_s: float = float(np.radians(0.0005))
    """The calibrated bias's error δb as a random walk of this σ per √s (its instability)."""
    huber_k: float = 2.0
    huber_passes: int = 3
    cauchy_c: float = 4.0
    cauchy_passes: int = 3
    consensus_span_s: float = 20.0
    """Half-width of the consensus that starts the weights and judges reliability."""
    max_variance_factor: float = 3.0
    """Largest λ at which the smoother's premise holds (the gyro links the windows: the
    offset changes slowly); beyond it the heading stage keeps the windows' own headings and
    says so (real canyons at 1 Hz give 1.5–1.6; a pedestrian, whose walking course leaves the
    body's yaw at every step and stop, 20)."""
    reliable_max_sigma_rad: float = float(np.radians(2.0))
    min_support: float = 2.0
    """Independent agreeing windows (Σ w_j/n_j) a reliable heading needs around it."""


@dataclass(frozen=True)
class SmoothedHeading:
    """Per epoch: yaw (rad, NaN where unavailable), σ (rad), ``available``, ``reliable``;
    per window: its final ``weight`` (0 where there is none); the windows' variance factor λ."""

    yaw: np.ndarray
    sigma: np.ndarray
    available: np.ndarray
    reliable: np.ndarray
    weight: np.ndarray
    variance_factor: float


def angle_random_walk(sample_noise_rad_s: float, sample_interval_s: float) -> float:
    """A gyro's angle random walk (rad/√s) from the σ of its samples (rad/s) taken every
    ``sample_interval_s``: white rate noise σ integrated over Δt has σ·√Δt per sample."""
    return float(sample_noise_rad_s * np.sqrt(sample_interval_s))


@dataclass(frozen=True)
class WindowHeadings:
    """The tight windows' headings per epoch: times (s), yaw (rad, NaN where a window has
    none), σ (rad) and the windows' lengths (s)."""

    t: np.ndarray
    yaw: np.ndarray
    sigma: np.ndarray
    window_s: np.ndarray


@dataclass(frozen=True)
class GyroAngle:
    """The calibrated integrated yaw rate Φ per epoch (rad, NaN where the vehicle signals do
    not cover), the σ of its calibrated bias (rad/s) and its angle random walk (rad/√s)."""

    yaw_angle: np.ndarray
    bias_sigma: float
    angle_random_walk: float


def smooth_heading(
    windows: WindowHeadings,
    gyro: GyroAngle,
    config: HeadingSmootherConfig,
    max_sigma_rad: float,
) -> SmoothedHeading:
    """Smooth the window headings through the gyro's Φ; runs of epochs with Φ defined are
    smoothed apart (module docstring). ``max_sigma_rad``: the largest σ of an available
    heading."""
    t = np.asarray(windows.t, dtype=float)
    sigma = np.asarray(windows.sigma, dtype=float)
    yaw_angle = np.asarray(gyro.yaw_angle, dtype=float)
    m = len(t)
    out_yaw = np.full(m, np.nan)
    out_sigma = np.full(m, np.nan)
    weight = np.zeros(m)
    covered = np.isfinite(yaw_angle)
    z = wrap_angle(np.asarray(windows.yaw, dtype=float) - yaw_angle)
    measured = covered & np.isfinite(z) & np.isfinite(sigma) & (sigma > 0)
    step = float(np.median(np.diff(t))) if m > 1 else 1.0
    overlap = np.maximum(1.0, np.nan_to_num(np.asarray(windows.window_s, dtype=float)) / step)
    q_a = max(gyro.angle_random_walk, config.min_angle_random_walk_rad_per_sqrt_s)
    residuals: list[np.ndarray] = []
    for run in _runs(covered):
        inside = run[measured[run]]
        if not inside.size:
            continue
        model = _Model(t[run], yaw_angle[run], q_a, config.scale_sigma, gyro.bias_sigma, config)
        rows = np.searchsorted(run, inside)
        base = sigma[inside] ** 2 * overlap[inside]
        offset, variance, w = _robust_offset(model, rows, z[inside], base, config)
        out_yaw[run] = wrap_angle(yaw_angle[run] + offset)
        out_sigma[run] = np.sqrt(variance)
        weight[inside] = w
        residuals.append(wrap_angle(z[inside] - offset[rows]) / sigma[inside])
    factor = _variance_factor(residuals)
    out_sigma *= factor
    available = np.isfinite(out_yaw) & (out_sigma <= max_sigma_rad)
    support = _support(t, weight, overlap, config.consensus_span_s)
    reliable = available & (out_sigma <= config.reliable_max_sigma_rad)
    reliable &= support >= config.min_support
    return SmoothedHeading(
        yaw=np.where(available, out_yaw, np.nan),
        sigma=np.where(available, out_sigma, np.nan),
        available=available,
        reliable=reliable,
        weight=weight,
        variance_factor=factor,
    )


def _runs(covered: np.ndarray) -> list[np.ndarray]:
    """Index arrays of the maximal runs of True in ``covered``."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], covered.astype(int), [0]])))
    return [np.arange(a, b) for a, b in zip(edges[::2], edges[1::2], strict=True)]


@dataclass(frozen=True)
class _Model:
    """The process (S2) over one run of epochs: times, Φ, q_a, σ_s, the bias prior."""

    t: np.ndarray
    yaw_angle: np.ndarray
    q_a: float
    scale_sigma: float
    bias_sigma: float
    config: HeadingSmootherConfig


def _robust_offset(model: _Model, rows, z, base_variance, config):
    """IRLS over the smoother: consensus weights first, then Huber, then Cauchy passes; the
    final smoothed offset, its variance and the windows' weights."""
    t = model.t[rows]
    start = _consensus_weights(t, z, np.sqrt(base_variance), config)
    huber = config.huber_passes

    def fit(weights):
        offset, _ = _rts(model, rows, z, base_variance / np.maximum(weights, 1e-9))
        return wrap_angle(z - offset[rows]) / np.sqrt(base_variance)

    def weigh(u, n):
        if n < huber:
            return huber_weight(u, config.huber_k, floor=1e-12)
        return cauchy_weight(u, config.cauchy_c)

    weights = irls(fit, weigh, start, huber + config.cauchy_passes)
    offset, variance = _rts(model, rows, z, base_variance / np.maximum(weights, 1e-9))
    return offset, variance, weights


def _consensus_weights(t, z, scale, config):
    """Huber weights of each offset's distance to the consensus of the offsets within
    ±``consensus_span_s``: their median about their circular mean, taken every quarter span
    and held to the nearest (the smoother's first pass must not follow a gross window)."""
    span = config.consensus_span_s
    centres = np.arange(t[0], t[-1] + 0.25 * span, 0.25 * span)
    lo = np.searchsorted(t, centres - span, side="left")
    hi = np.searchsorted(t, centres + span, side="right")
    reference = np.empty(len(centres))
    for i, (a, b) in enumerate(zip(lo, hi, strict=True)):
        local = z[a:b]
        mean = np.angle(np.mean(np.exp(1j * local)))
        reference[i] = mean + np.median(wrap_angle(local - mean))
    nearest = np.clip(np.rint((t - t[0]) / (0.25 * span)).astype(int), 0, len(centres) - 1)
    distance = np.abs(wrap_angle(z - reference[nearest]))
    return huber_weight(distance / scale, config.huber_k, floor=1e-12)


def _rts(model: _Model, rows, z, variance):
    """Forward Kalman filter and Rauch–Tung–Striebel pass of (S1)–(S2) over the run; the
    smoothed offset c and its variance at every epoch of the run, the 2×2 algebra written out in
    Python floats (against filterpy's KalmanFilter + rts_smoother: equal in
    tests/heading/test_smoother.py, timed in benchmarks/smoother_speed.py)."""
    n = len(model.t)
    first = int(rows[0])
    dts = np.diff(model.t).tolist()
    q_turn = ((model.scale_sigma * np.abs(np.diff(model.yaw_angle))) ** 2).tolist()
    q_a, q_b = model.q_a**2, model.config.bias_walk_rad_per_s_sqrt_s**2
    measurement = [None] * n
    for row, value, r in zip(rows.tolist(), z.tolist(), variance.tolist(), strict=True):
        if math.isfinite(value) and math.isfinite(r):
            measurement[row] = (value, r)
    filtered, predicted = [None] * n, [None] * n
    c, b = float(z[0]), 0.0
    p00, p01, p11 = float(variance[0]), 0.0, model.bias_sigma**2
    for k in range(first, n):
        if k > first:
            dt = dts[k - 1]
            c -= b * dt
            p00 += -2.0 * dt * p01 + dt * dt * p11 + q_a * dt + q_turn[k - 1]
            p01 -= dt * p11
            p11 += q_b * dt
        predicted[k] = (c, b, p00, p01, p11)
        if k > first and measurement[k] is not None:
            value, r = measurement[k]
            innovation = math.remainder(value - c, math.tau)
            s = p00 + r
            k0, k1 = p00 / s, p01 / s
            c += k0 * innovation
            b += k1 * innovation
            p00, p01, p11 = p00 - k0 * p00, p01 - k0 * p01, p11 - k1 * p01
        filtered[k] = (c, b, p00, p01, p11)
    offset = np.full(n, np.nan)
    variance_out = np.full(n, np.nan)
    sc, sb, s00, s01, s11 = filtered[n - 1]
    offset[n - 1], variance_out[n - 1] = sc, s00
    for k in range(n - 2, first - 1, -1):
        dt = dts[k]
        fc, fb, a00, a01, a11 = filtered[k]
        pc, pb, q00, q01, q11 = predicted[k + 1]
        # C = P_f Fᵀ P_p⁻¹ with F = [[1, −dt], [0, 1]]
        f00, f10 = a00 - dt * a01, a01 - dt * a11
        det = q00 * q11 - q01 * q01
        i00, i01, i11 = q11 / det, -q01 / det, q00 / det
        c00, c01 = f00 * i00 + a01 * i01, f00 * i01 + a01 * i11
        c10, c11 = f10 * i00 + a11 * i01, f10 * i01 + a11 * i11
        d0, d1 = math.remainder(sc - pc, math.tau), sb - pb
        sc, sb = fc + c00 * d0 + c01 * d1, fb + c10 * d0 + c11 * d1
        # P_s = P_f + C (P_s' − P_p') Cᵀ
        e00, e01, e11 = s00 - q00, s01 - q01, s11 - q11
        g00, g01 = c00 * e00 + c01 * e01, c00 * e01 + c01 * e11
        g10, g11 = c10 * e00 + c11 * e01, c10 * e01 + c11 * e11
        s00, s01, s11 = (
            a00 + g00 * c00 + g01 * c01,
            a01 + g00 * c10 + g01 * c11,
            a11 + g10 * c10 + g11 * c11,
        )
        offset[k], variance_out[k] = sc, s00
    return _before_first(offset, variance_out, model, first)


def _before_first(offset, variance, model: _Model, first: int):
    """Epochs before the run's first window take its smoothed offset, propagated back by the
    gyro with the process noise of (S2) (the bias term included)."""
    if first == 0:
        return offset, variance
    t, phi = model.t, model.yaw_angle
    dt = t[first] - t[:first]
    turn = model.scale_sigma * np.abs(phi[first] - phi[:first])
    growth = model.q_a**2 * dt + turn**2 + (model.bias_sigma * dt) ** 2
    offset[:first] = offset[first]
    variance[:first] = variance[first] + growth
    return offset, variance


def _variance_factor(residuals: list[np.ndarray]) -> float:
    """λ = max(1, NMAD) of the windows' normalised residuals about the smoothed offset."""
    if not residuals:
        return 1.0
    u = np.concatenate(residuals)
    return max(1.0, float(nmad(u, centre=False))) if u.size else 1.0


def _support(t, weight, overlap, span_s):
    """Σ w_j/n_j over the windows with w_j ≥ ½ within ±``span_s`` of each epoch."""
    agreeing = np.where(weight >= 0.5, 1.0 / overlap, 0.0)
    total = np.concatenate([[0.0], np.cumsum(agreeing)])
    lo = np.searchsorted(t, t - span_s, side="left")
    hi = np.searchsorted(t, t + span_s, side="right")
    return total[hi] - total[lo]
