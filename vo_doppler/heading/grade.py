"""Road grade prior of the tight heading from a forward accelerometer and the wheel speed,
its offset calibrated by the conventional Doppler velocity (this project's addition to [TK18]).

A forward accelerometer on a vehicle climbing at angle γ measures the specific force

    f = dv/dt + g₀·sin γ + f₀

(v the speed along the road, g₀ standard gravity, f₀ the accelerometer's bias plus g₀·sin of the
mounting pitch: constant over a drive). Averaged over the heading window (t_k − W, t_k], as the
tight heading's grade unknown is (:mod:`vo_doppler.heading.tight_heading`):

    sin γ̄ = [(1/W)·∫ f dt − (v(t_k) − v(t_k − W))/W − f₀] / g₀,      g = tan γ̄

with the calibrated wheel speed for v (a scale error of 1 % moves the speed term by 1 %,
0.01 m/s² in a 1 m/s² acceleration: 0.1 % of grade; braking at 3–5 m/s² makes it count).
f₀/g₀ is the median of the differences between that grade (with f₀ = 0) and the
conventional Doppler grade v_up/|v_h| over the valid epochs of the whole recording (f₀ is a
constant, so every epoch, the first seconds included, gets the estimate all the data give:
the run is post-processing), and the prior's σ is the robust scatter of those differences
(1.4826·MAD) less the share of the Doppler's own vertical noise where its σ is known
(:func:`grade_prior`), plus the median's own σ (1.25·scatter/√n), at least ``min_sigma``.
With fewer than ``min_samples`` differences there is no prior (NaN).

A running (causal) median left a drive's first seconds, before ``min_samples`` valid
velocities, at the zero-mean prior's σ, with wider tight headings and fewer of them used on the
simulated level drives of ``benchmarks/heading_nlos.py``; the calibrated wheel speed in dv/dt
likewise narrows the level roads' grade error. On the comma2k19 minute (device pitched down,
so f₀ is far from zero) the grade so found, offset fitted over the canyon emulation's open-sky
start, follows the ground truth's within the truth's own spread. Both in docs/benchmarks.md,
"A street canyon from the start" and "The heading stage's settings".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.model.series import SensorSeries
from vo_doppler.model.timeseries import integral_at, sample
from vo_doppler.robust import nmad

STANDARD_GRAVITY = 9.80665
"""g₀ (m/s²)."""


@dataclass(frozen=True)
class GradePriorConfig:
    """Calibration of the accelerometer grade (module docstring)."""

    min_speed_mps: float = 5.0
    """Conventional velocities slower than this do not calibrate: v_up/|v_h| is too noisy."""
    min_samples: int = 20
    min_sigma: float = 0.005


def accelerometer_grade(
    t_epoch: np.ndarray,
    window_s: float,
    forward_acceleration: SensorSeries,
    wheel_speed: SensorSeries,
) -> np.ndarray:
    """Mean grade tan γ̄ over each window (t_k − W, t_k] with the offset f₀ taken as zero
    (module docstring); NaN where either signal does not cover the window."""
    t_epoch = np.asarray(t_epoch, dtype=float)
    start = t_epoch - window_s
    acc = forward_acceleration
    mean_force = (
        integral_at(acc.t, acc.value, t_epoch) - integral_at(acc.t, acc.value, start)
    ) / window_s
    speed_change = sample(wheel_speed.t, wheel_speed.value, t_epoch) - sample(
        wheel_speed.t, wheel_speed.value, start
    )
    sine = (mean_force - speed_change / window_s) / STANDARD_GRAVITY
    return np.tan(np.arcsin(np.clip(sine, -1.0, 1.0)))


def grade_prior(
    raw_grade: np.ndarray,
    velocity_enu: np.ndarray,
    valid: np.ndarray,
    config: GradePriorConfig = GradePriorConfig(),
    vertical_sigma_mps: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """(μ, σ) of the grade at each epoch: ``raw_grade`` (:func:`accelerometer_grade`) less the
    offset calibrated on the conventional velocities (``velocity_enu``, flagged ``valid``) of
    the whole recording (module docstring); NaN everywhere with fewer than
    ``config.min_samples`` of them.

    With ``vertical_sigma_mps`` (σ_u of each conventional up velocity) the Doppler's own share
    of the scatter is taken out, a variance-component split of the differences
    d = (accelerometer grade error) − (Doppler grade error):

        σ_a² = max(s² − median(σ_u² / |v_h|²), 0),    σ = max(σ_a + 1.25·s/√n, σ_min)

    with s the robust scatter of d and n its count; the second term is the offset's own σ. In
    a street canyon the Doppler's vertical noise (VDOP) is most of s, which the split leaves
    out (simulated level drives with a longitudinal accelerometer: docs/benchmarks.md, "A
    street canyon from the start")."""
    velocity = np.asarray(velocity_enu, dtype=float).reshape(-1, 3)
    horizontal = np.hypot(velocity[:, 0], velocity[:, 1])
    calibrating = np.asarray(valid, dtype=bool) & (horizontal >= config.min_speed_mps)
    calibrating &= np.isfinite(raw_grade) & np.isfinite(velocity[:, 2])
    with np.errstate(invalid="ignore", divide="ignore"):
        difference = raw_grade - velocity[:, 2] / horizontal
        doppler_variance = (
            np.zeros_like(horizontal)
            if vertical_sigma_mps is None
            else (np.asarray(vertical_sigma_mps, dtype=float) / horizontal) ** 2
        )
    calibrating &= np.isfinite(doppler_variance)
    m = len(raw_grade)
    d = difference[calibrating]
    if d.size < config.min_samples:
        return np.full(m, np.nan), np.full(m, np.nan)
    offset = float(np.median(d))
    scatter = nmad(d)
    own = np.sqrt(max(scatter**2 - float(np.median(doppler_variance[calibrating])), 0.0))
    sigma = max(own + 1.25 * scatter / np.sqrt(d.size), config.min_sigma)
    return raw_grade - offset, np.full(m, sigma)
