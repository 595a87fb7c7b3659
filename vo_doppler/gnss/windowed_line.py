"""A quantity tested against a robust line through its neighbours in time (docs/design.md,
"Conventional velocity integrity"): the machinery of the GNSS stage's continuity test
(:mod:`vo_doppler.gnss.continuity`) and of the heading stage's test against the car's sensors
(:mod:`vo_doppler.heading.integrity`).

At each epoch k the values of the other usable epochs within ``half_window_s`` are fitted by a
line (Huber IRLS on residuals in units of each epoch's own σ, started from the median, the
slope optionally with a Gaussian prior), and the epoch's own value is compared with the line at
t_k:

    z_k = e_k / √(σ_k² + σ_fit,k²)                                              (I1)

σ_k the value's own σ, σ_fit,k the line's σ at t_k. The residuals also measure how honest the
σ are: λ = max(1, 1.4826·median|z|) over the tested epochs is the factor by which the actual
scatter exceeds the stated σ. An epoch fails when |z_k| > K·λ, K the two-sided normal quantile
of ``false_alarm`` per test. Epochs with fewer than ``min_neighbours`` usable others in the
window are not tested. The fit looks ``half_window_s`` ahead and λ is taken over the
recording, so the test is not causal; a fault that lasts most of the window moves the line with
it and is not seen.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy.special import ndtri

from vo_doppler.geo import wrap_angle
from vo_doppler.robust import huber_weight, irls, nmad

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
    degree: int = 1
    """Of the polynomial in time fitted to the neighbours: 1 a line, 2 a parabola."""

    @property
    def threshold(self) -> float:
        return float(-ndtri(self.false_alarm / 2.0))


@dataclass(frozen=True)
class ConsistencyTest:
    """One quantity's test: normalised residual z (NaN where untested), the σ factor λ, and
    which epochs fail (|z| > K·λ); also the residual e_k itself and the fitted line's σ at
    t_k (NaN where untested)."""

    z: np.ndarray
    sigma_factor: float
    failed: np.ndarray
    residual: np.ndarray | None = None
    line_sigma: np.ndarray | None = None
    decidable: np.ndarray | None = None
    """Usable epochs whose window holds enough other epochs of the recording for the test,
    usable or not: untested there, the epoch's neighbours were not usable."""

    @property
    def tested(self) -> np.ndarray:
        return np.isfinite(self.z)

    @property
    def unjudged(self) -> np.ndarray:
        """Untested epochs whose window could have held the neighbours the test needs (its
        neighbours were not usable); False where the recording's rate or a gap left too few
        epochs to decide."""
        if self.decidable is None:
            return np.zeros(self.z.shape, dtype=bool)
        return self.decidable & ~self.tested


@dataclass(frozen=True)
class LineFit:
    """How the line through an epoch's neighbours is fitted (I1): over the other usable epochs
    within ±``half_window_s``, at least ``min_neighbours`` of them; ``angular``: differences
    wrapped to (−π, π]; ``degree`` 2 a parabola instead of the line."""

    half_window_s: float
    min_neighbours: int
    angular: bool = False
    degree: int = 1


@dataclass(frozen=True)
class _Samples:
    """The series tested: times (s), values, their σ and which epochs are usable."""

    t: np.ndarray
    values: np.ndarray
    sigma: np.ndarray
    usable: np.ndarray


def windowed_line_residuals(
    t: np.ndarray,
    values: np.ndarray,
    sigma: np.ndarray,
    usable: np.ndarray,
    fit: LineFit,
    slope_sigma: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Each epoch's value minus a robust line through the other usable epochs of its window
    (``fit``), at its own time, and the line's variance there (I1): Huber IRLS on the
    residuals in units of each value's ``sigma``, from the median (slope zero).
    ``slope_sigma`` (per epoch, units of value per second): a prior N(0, σ²) on the line's
    slope (none where infinite or not given). NaN where fewer than ``fit.min_neighbours``
    others are usable or the epoch itself is not."""
    t = np.asarray(t, dtype=float)
    values = np.asarray(values, dtype=float)
    sigma = np.asarray(sigma, dtype=float)
    usable = np.asarray(usable, dtype=bool) & np.isfinite(values) & np.isfinite(t)
    usable &= np.isfinite(sigma) & (sigma > 0)
    samples = _Samples(t, values, sigma, usable)
    slope_sigma = np.full(t.size, np.inf) if slope_sigma is None else np.asarray(slope_sigma)
    slope_precision = np.maximum(slope_sigma, MIN_SLOPE_SIGMA) ** -2.0
    residual, variance = np.full(t.size, np.nan), np.full(t.size, np.nan)
    for start in range(0, t.size, CHUNK_EPOCHS):
        epochs = np.arange(start, min(start + CHUNK_EPOCHS, t.size))
        line, line_variance, count = _line_at_epochs(epochs, samples, fit, slope_precision[epochs])
        enough = count >= max(fit.min_neighbours, fit.degree + 1)
        residual[epochs] = np.where(enough, line, np.nan)
        variance[epochs] = np.where(enough, line_variance, np.nan)
    return residual, variance


def _line_at_epochs(epochs, samples: _Samples, fit: LineFit, slope_precision):
    """:func:`windowed_line_residuals` at ``epochs`` (an (epochs × window) block of the other
    usable epochs in each window): weighted normal equations of the polynomial in the time
    offset with the slope prior's precision added to the slope's diagonal; also the number of
    neighbours."""
    t, values, sigma, usable = samples.t, samples.values, samples.sigma, samples.usable
    half_window_s, angular, degree = fit.half_window_s, fit.angular, fit.degree
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
    powers = dt[..., None] ** np.arange(degree + 1)
    count = mask.sum(1)
    solvable = count > degree
    prior = np.zeros((epochs.size, degree + 1, degree + 1))
    prior[:, 1, 1] = slope_precision
    prior[~solvable] = np.eye(degree + 1)
    coefficients = np.zeros((epochs.size, degree + 1))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # rows without neighbours
        coefficients[:, 0] = np.nanmedian(np.where(mask, y, np.nan), axis=1)
    coefficients[~solvable] = 0.0

    def normalised(coefficients):
        return np.abs(y - np.einsum("kwp,kp->kw", powers, coefficients)) * np.sqrt(precision)

    def weigh(normalised, _pass=0):
        return huber_weight(normalised, HUBER_K, prior=precision)

    def solve(weight):
        normal = np.einsum("kw,kwi,kwj->kij", weight, powers, powers) + prior
        right = np.einsum("kw,kwi,kw->ki", weight, powers, y)
        return np.linalg.solve(normal, right[..., None])[..., 0], normal

    with np.errstate(divide="ignore", invalid="ignore"):
        start = weigh(normalised(coefficients))
        weight = irls(lambda w: normalised(solve(w)[0]), weigh, start, IRLS_STEPS - 1)
        coefficients, normal = solve(weight)
    variance = np.linalg.inv(normal)[:, 0, 0]
    return -coefficients[:, 0], variance, count


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
    fit = LineFit(config.half_window_s, config.min_neighbours, angular, config.degree)
    residual, variance = windowed_line_residuals(t, difference, sigma, usable, fit, slope_sigma)
    with np.errstate(invalid="ignore"):
        z = residual / np.sqrt(np.asarray(sigma, dtype=float) ** 2 + variance)
    z = np.where(np.isfinite(z), z, np.nan)
    tested = np.isfinite(z)
    factor = 1.0
    if tested.sum() >= config.min_tested_for_scale:
        factor = max(1.0, nmad(z[tested], centre=False))
    with np.errstate(invalid="ignore"):
        failed = tested & (np.abs(z) > config.threshold * factor)
    line_sigma = np.where(tested, np.sqrt(variance), np.nan)
    decidable = np.asarray(usable, dtype=bool) & (
        epochs_in_window(t, config.half_window_s) >= max(config.min_neighbours, config.degree + 1)
    )
    return ConsistencyTest(
        z, factor, failed, np.where(tested, residual, np.nan), line_sigma, decidable
    )


def epochs_in_window(t: np.ndarray, half_window_s: float) -> np.ndarray:
    """How many other epochs of ``t`` (sorted) lie within ±``half_window_s`` of each."""
    t = np.asarray(t, dtype=float)
    lo = np.searchsorted(t, t - half_window_s, "left")
    hi = np.searchsorted(t, t + half_window_s, "right")
    return hi - lo - 1
