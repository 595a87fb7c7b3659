"""Integrity of the conventional Doppler velocity against the vehicle's own sensors
(docs/design.md, "Conventional velocity integrity against the car's sensors").

Several reflected satellites at once can be fitted by a wrong velocity that the GNSS stage's
chi-square test cannot see (five or six satellites leave it one or two degrees of freedom).
A car knows its turning and its speed without GNSS: over a few seconds the conventional course
minus the integrated calibrated yaw rate is a constant plus a slope, what is left of the gyro
bias (prior N(0, σ_b²) from the calibration), and the conventional speed minus the calibrated
wheel speed a constant plus a slope (the wheel scale and the wheel's lag in accelerations). At
each epoch k both differences of the other epochs within ``half_window_s`` are fitted by such a
line (Huber IRLS on residuals in units of each epoch's own σ, started from the median), and the
epoch's own difference is compared with the line at t_k:

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
from scipy.special import ndtri

from vo_doppler.geo import wrap_angle
from vo_doppler.heading.calibration import MAD_TO_SIGMA

HUBER_K = 1.345
IRLS_STEPS = 5
CHUNK_EPOCHS = 512
MIN_SLOPE_SIGMA = 1e-9


@dataclass(frozen=True)
class ConsistencyConfig:
    """The test (I1): its window (±``half_window_s``), false-alarm rate per test and the
    neighbours an epoch needs to be tested."""

    enabled: bool = True
    half_window_s: float = 5.0
    false_alarm: float = 0.001
    """Probability that one test (course or speed) fails an epoch without a fault."""
    min_neighbours: int = 5
    min_tested_for_scale: int = 20
    """Fewer tested epochs than this give no σ factor (λ = 1)."""

    @property
    def threshold(self) -> float:
        return float(-ndtri(self.false_alarm / 2.0))


@dataclass(frozen=True)
class ConsistencyTest:
    """One quantity's test: normalised residual z (NaN where untested), the σ factor λ, and
    which epochs fail (|z| > K·λ)."""

    z: np.ndarray
    sigma_factor: float
    failed: np.ndarray


def windowed_line_residuals(
    t: np.ndarray,
    values: np.ndarray,
    sigma: np.ndarray,
    usable: np.ndarray,
    half_window_s: float,
    min_neighbours: int,
    angular: bool = False,
    slope_sigma: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Each epoch's value minus a robust line through the other usable epochs within
    ``half_window_s``, at its own time, and the line's variance there (I1): Huber IRLS on the
    residuals in units of each value's ``sigma``, from the median (slope zero).
    ``angular``: differences wrapped to (−π, π]. ``slope_sigma`` (per epoch, units of value per
    second): a prior N(0, σ²) on the line's slope (none where infinite or not given). NaN
    where fewer than ``min_neighbours`` others are usable or the epoch itself is not."""
    t = np.asarray(t, dtype=float)
    values = np.asarray(values, dtype=float)
    sigma = np.asarray(sigma, dtype=float)
    usable = np.asarray(usable, dtype=bool) & np.isfinite(values) & np.isfinite(t)
    usable &= np.isfinite(sigma) & (sigma > 0)
    slope_sigma = np.full(t.size, np.inf) if slope_sigma is None else np.asarray(slope_sigma)
    slope_precision = np.maximum(slope_sigma, MIN_SLOPE_SIGMA) ** -2.0
    residual, variance = np.full(t.size, np.nan), np.full(t.size, np.nan)
    for start in range(0, t.size, CHUNK_EPOCHS):
        epochs = np.arange(start, min(start + CHUNK_EPOCHS, t.size))
        line, line_variance, count = _line_at_epochs(
            epochs, t, values, sigma, usable, half_window_s, angular, slope_precision[epochs]
        )
        enough = count >= min_neighbours
        residual[epochs] = np.where(enough, line, np.nan)
        variance[epochs] = np.where(enough, line_variance, np.nan)
    return residual, variance


def _line_at_epochs(epochs, t, values, sigma, usable, half_window_s, angular, slope_precision):
    """:func:`windowed_line_residuals` at ``epochs`` (an (epochs × window) block of the other
    usable epochs in each window): weighted normal equations with the slope prior's precision
    added to the slope's diagonal; also the number of neighbours."""
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
    precision = np.where(mask, sigma[index] ** -2.0, 0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # rows without neighbours
        c0 = np.nanmedian(np.where(mask, y, np.nan), axis=1)
    c1 = np.zeros(epochs.size)
    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(IRLS_STEPS):
            normalised = np.abs(y - c0[:, None] - c1[:, None] * dt) * np.sqrt(precision)
            weight = precision * np.minimum(1.0, HUBER_K / normalised)
            s0, s1 = weight.sum(1), (weight * dt).sum(1)
            s2 = (weight * dt**2).sum(1) + slope_precision
            y0, y1 = (weight * y).sum(1), (weight * dt * y).sum(1)
            det = s0 * s2 - s1**2
            c0 = (s2 * y0 - s1 * y1) / det
            c1 = (s0 * y1 - s1 * y0) / det
        return -c0, s2 / det, mask.sum(1)


def consistency_test(
    t: np.ndarray,
    difference: np.ndarray,
    sigma: np.ndarray,
    usable: np.ndarray,
    config: ConsistencyConfig,
    angular: bool = False,
    slope_sigma: np.ndarray | None = None,
) -> ConsistencyTest:
    """Test (I1) of one quantity: ``difference`` is the GNSS value minus the sensor's (course
    minus integrated yaw rate, or speed minus wheel speed), ``sigma`` the GNSS value's σ,
    ``slope_sigma`` the σ of the sensor's drift (:func:`windowed_line_residuals`)."""
    residual, variance = windowed_line_residuals(
        t,
        difference,
        sigma,
        usable,
        config.half_window_s,
        config.min_neighbours,
        angular,
        slope_sigma,
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
    gyro_bias_sigma: np.ndarray,
    config: ConsistencyConfig = ConsistencyConfig(),
) -> ConventionalIntegrity:
    """Test (I1) of the conventional yaw against the integrated calibrated yaw rate
    ``yaw_angle`` and of its horizontal speed against the calibrated ``wheel_speed``, at the
    epochs ``valid`` so far (rad, m/s; module docstring). The course line's slope is what is
    left of the gyro bias: its prior is N(0, ``gyro_bias_sigma``²) (rad/s, per epoch)."""
    valid = np.asarray(valid, dtype=bool)
    if not config.enabled:
        return ConventionalIntegrity(None, None, valid.copy())
    course = speed_test = None
    failed = np.zeros(valid.shape, dtype=bool)
    if yaw_sigma is not None:
        course = consistency_test(
            t,
            np.asarray(yaw) - np.asarray(yaw_angle),
            yaw_sigma,
            valid,
            config,
            angular=True,
            slope_sigma=gyro_bias_sigma,
        )
        failed |= course.failed
    if speed_sigma is not None:
        speed_test = consistency_test(
            t, np.asarray(speed) - np.asarray(wheel_speed), speed_sigma, valid, config
        )
        failed |= speed_test.failed
    return ConventionalIntegrity(course, speed_test, valid & ~failed)
