"""Vehicle sensor series sampled at GNSS epochs: speed by interpolation, yaw by integration.

Yaw rate is counter-clockwise positive (docs/design.md); the integrated yaw angle Φ(t) is the
trapezoidal integral of the yaw rate from the first sample, so Φ(t₂) − Φ(t₁) is the yaw change
between two epochs.
"""

from __future__ import annotations

import numpy as np

from vo_doppler.model.timeseries import integral_at, sample


def calibrated_epoch_inputs(
    t_epoch: np.ndarray,
    speed_t: np.ndarray,
    speed: np.ndarray,
    yaw_rate_t: np.ndarray,
    yaw_rate: np.ndarray,
    wheel_scale: float = 1.0,
    gyro_bias: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Calibrated speed k·v and integrated calibrated yaw ∫(ω − b) at the epochs
    ([TK18] sec. 3.3–3.4)."""
    speed_at = wheel_scale * sample(speed_t, speed, t_epoch)
    yaw_at = integral_at(yaw_rate_t, np.asarray(yaw_rate, dtype=float) - gyro_bias, t_epoch)
    return speed_at, yaw_at
