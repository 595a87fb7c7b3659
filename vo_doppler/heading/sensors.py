"""Vehicle sensor series sampled at GNSS epochs: speed by interpolation, yaw by integration.

Yaw rate is counter-clockwise positive (DESIGN.md); the integrated yaw angle Φ(t) is the
trapezoidal integral of the yaw rate from the first sample, so Φ(t₂) − Φ(t₁) is the yaw change
between two epochs.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import cumulative_trapezoid


def integrate_rate(t: np.ndarray, rate: np.ndarray, t_query: np.ndarray) -> np.ndarray:
    """Φ(t_query): trapezoidal integral of ``rate`` from ``t[0]``; NaN outside the samples."""
    t = np.asarray(t, dtype=float)
    angle = cumulative_trapezoid(np.asarray(rate, dtype=float), t, initial=0.0)
    return sample_at(t, angle, t_query)


def sample_at(t: np.ndarray, value: np.ndarray, t_query: np.ndarray) -> np.ndarray:
    """Linear interpolation at ``t_query``; NaN outside ``[t[0], t[-1]]`` (no extrapolation)."""
    t_query = np.asarray(t_query, dtype=float)
    if len(t) == 0:
        return np.full(t_query.shape, np.nan)
    out = np.interp(t_query, t, value)
    out[(t_query < t[0]) | (t_query > t[-1])] = np.nan
    return out


def calibrated_epoch_inputs(
    t_epoch: np.ndarray,
    speed_t: np.ndarray,
    speed: np.ndarray,
    yaw_rate_t: np.ndarray,
    yaw_rate: np.ndarray,
    wheel_scale: float = 1.0,
    gyro_bias: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Calibrated speed k·v and integrated calibrated yaw ∫(ω − b) at the epochs (sec. 3.3–3.4)."""
    speed_at = wheel_scale * sample_at(speed_t, speed, t_epoch)
    yaw_at = integrate_rate(yaw_rate_t, np.asarray(yaw_rate, dtype=float) - gyro_bias, t_epoch)
    return speed_at, yaw_at
