"""Integrity of the conventional Doppler velocity against the vehicle's own sensors
(docs/design.md, "Conventional velocity integrity").

Several reflected satellites at once can be fitted by a wrong velocity that the GNSS stage's
chi-square test cannot see (five or six satellites leave it one or two degrees of freedom).
A car knows its turning and its speed without GNSS: over a few seconds the conventional course
minus the integrated calibrated yaw rate is a constant (plus a drift from what is left of the
gyro bias), and the conventional speed minus the calibrated wheel speed is a constant (plus a
drift from the wheel scale and the wheel's lag in accelerations). At each epoch k both
differences of the other epochs within ``half_window_s`` are fitted by a line in time (Huber
IRLS, scale from the MAD), and the epoch's own difference is compared with the line at t_k:

    z_k = e_k / √(σ_k² + σ_fit,k²)                                              (I1)

σ_k the velocity's own course or speed σ, σ_fit,k the line's σ at t_k. The residuals also
measure how honest the σ are: λ = max(1, 1.4826·median|z|) over the tested epochs is the
factor by which the actual scatter exceeds the stated σ (an upper bound, the gyro's and the
wheel's own noise are in it). An epoch fails when |z_k| > K·λ, K the two-sided normal quantile
of ``false_alarm`` per test; the course and speed σ are reported times their λ. Epochs with
fewer than ``min_neighbours`` usable others in the window are not tested and keep the GNSS
stage's verdict. The fit looks ``half_window_s`` ahead and λ is taken over the recording, so
the check is not causal. A fault that lasts most of the window moves the line with it and is
not seen.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy.stats import norm

from vo_doppler.geo import wrap_angle

HUBER_K = 1.345
MAD_TO_SIGMA = 1.4826
IRLS_STEPS = 5
CHUNK_EPOCHS = 2048


@dataclass(frozen=True)
class ConsistencyConfig:
    enabled: bool = True
    half_window_s: float = 2.0
    false_alarm: float = 0.001
    """Probability that one test (course or speed) fails an epoch without a fault."""
    min_neighbours: int = 5
    min_tested_for_scale: int = 20
    """Fewer tested epochs than this give no σ factor (λ = 1)."""

    @property
    def threshold(self) -> float:
        return float(norm.isf(self.false_alarm / 2.0))


@dataclass(frozen=True)
class ConsistencyTest:
    """One quantity's test: normalised residual z (NaN where untested), the σ factor λ, and
    which epochs fail (|z| > K·λ)."""

    z: np.ndarray
    sigma_factor: float
    failed: np.ndarray

    @property
    def tested(self) -> np.ndarray:
        return np.isfinite(self.z)


def windowed_line_residuals(
    t: np.ndarray,
    values: np.ndarray,
    usable: np.ndarray,
    half_window_s: float,
    min_neighbours: int,
    angular: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Each epoch's value minus a robust line through the other usable epochs within
    ``half_window_s``, at its own time, and the line's variance there (I1). ``angular``:
    differences wrapped to (−π, π]. NaN where fewer than ``min_neighbours`` others are usable
    or the epoch itself is not."""
    t = np.asarray(t, dtype=float)
    values = np.asarray(values, dtype=float)
    usable = np.asarray(usable, dtype=bool) & np.isfinite(values) & np.isfinite(t)
    residual, variance = np.full(t.size, np.nan), np.full(t.size, np.nan)
    for start in range(0, t.size, CHUNK_EPOCHS):
        epochs = np.arange(start, min(start + CHUNK_EPOCHS, t.size))
        residual[epochs], variance[epochs] = _line_at_epochs(
            epochs, t, values, usable, half_window_s, min_neighbours, angular
        )
    return residual, variance


def _line_at_epochs(epochs, t, values, usable, half_window_s, min_neighbours, angular):
    """:func:`windowed_line_residuals` at ``epochs`` (an (epochs × window) block)."""
    lo = np.searchsorted(t, t[epochs] - half_window_s, "left")
    hi = np.searchsorted(t, t[epochs] + half_window_s, "right")
    index = lo[:, None] + np.arange(int((hi - lo).max()))
    inside = index < hi[:, None]
    index = np.minimum(index, t.size - 1)
    mask = inside & usable[index] & (index != epochs[:, None]) & usable[epochs, None]
    dt = np.where(mask, t[index] - t[epochs, None], 0.0)
    y = values[index] - values[epochs, None]
    if angular:
        y = wrap_angle(y)
    y = np.where(mask, y, 0.0)
    weight = mask.astype(float)
    for _ in range(IRLS_STEPS):
        s0, s1, s2 = weight.sum(1), (weight * dt).sum(1), (weight * dt**2).sum(1)
        y0, y1 = (weight * y).sum(1), (weight * dt * y).sum(1)
        with np.errstate(divide="ignore", invalid="ignore"):
            det = s0 * s2 - s1**2
            c0 = (s2 * y0 - s1 * y1) / det
            c1 = (s0 * y1 - s1 * y0) / det
            fit = np.abs(y - c0[:, None] - c1[:, None] * dt)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # rows without neighbours
                scale = MAD_TO_SIGMA * np.nanmedian(np.where(mask, fit, np.nan), axis=1)
            huber = np.minimum(1.0, HUBER_K * scale[:, None] / fit)
        weight = np.where(mask, np.nan_to_num(huber, nan=1.0), 0.0)
    enough = mask.sum(1) >= min_neighbours
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(enough, -c0, np.nan), np.where(enough, scale**2 * s2 / det, np.nan)


def consistency_test(
    t: np.ndarray,
    difference: np.ndarray,
    sigma: np.ndarray,
    usable: np.ndarray,
    config: ConsistencyConfig,
    angular: bool = False,
) -> ConsistencyTest:
    """Test (I1) of one quantity: ``difference`` is the GNSS value minus the sensor's (course
    minus integrated yaw rate, or speed minus wheel speed), ``sigma`` the GNSS value's σ."""
    residual, variance = windowed_line_residuals(
        t, difference, usable, config.half_window_s, config.min_neighbours, angular
    )
    with np.errstate(invalid="ignore"):
        z = residual / np.sqrt(np.asarray(sigma, dtype=float) ** 2 + variance)
    z = np.where(np.isfinite(z), z, np.nan)
    tested = np.isfinite(z)
    factor = 1.0
    if tested.sum() >= config.min_tested_for_scale:
        factor = max(1.0, MAD_TO_SIGMA * float(np.median(np.abs(z[tested]))))
    with np.errstate(invalid="ignore"):
        failed = tested & (np.abs(z) > config.threshold * factor)
    return ConsistencyTest(z, factor, failed)


@dataclass(frozen=True)
class ConventionalIntegrity:
    """The course and speed tests of the conventional velocity (None where its σ is unknown)
    and the epochs still valid after them."""

    course: ConsistencyTest | None
    speed: ConsistencyTest | None
    valid: np.ndarray


def conventional_integrity(
    t: np.ndarray,
    valid: np.ndarray,
    yaw: np.ndarray,
    yaw_sigma: np.ndarray | None,
    yaw_angle: np.ndarray,
    speed: np.ndarray,
    speed_sigma: np.ndarray | None,
    wheel_speed: np.ndarray,
    config: ConsistencyConfig = ConsistencyConfig(),
) -> ConventionalIntegrity:
    """Test (I1) of the conventional yaw against the integrated calibrated yaw rate
    ``yaw_angle`` and of its horizontal speed against the calibrated ``wheel_speed``, at the
    epochs ``valid`` so far (rad, m/s; module docstring)."""
    valid = np.asarray(valid, dtype=bool)
    if not config.enabled:
        return ConventionalIntegrity(None, None, valid.copy())
    course = speed_test = None
    failed = np.zeros(valid.shape, dtype=bool)
    if yaw_sigma is not None:
        course = consistency_test(
            t, np.asarray(yaw) - np.asarray(yaw_angle), yaw_sigma, valid, config, angular=True
        )
        failed |= course.failed
    if speed_sigma is not None:
        speed_test = consistency_test(
            t, np.asarray(speed) - np.asarray(wheel_speed), speed_sigma, valid, config
        )
        failed |= speed_test.failed
    return ConventionalIntegrity(course, speed_test, valid & ~failed)
