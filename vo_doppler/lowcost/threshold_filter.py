"""Threshold ("high-pass") filter of a yaw rate, [KZ] Eq. (9): rates with |ω| < h become zero."""

from __future__ import annotations

import numpy as np


def threshold_filter(rate: np.ndarray, h: float) -> np.ndarray:
    """[KZ] Eq. (9): ω where |ω| ≥ h, else 0 (h in rad/s, h ≥ 0)."""
    if h < 0:
        raise ValueError(f"the threshold must be non-negative, got {h}")
    rate = np.asarray(rate, dtype=float)
    return np.where(np.abs(rate) >= h, rate, 0.0)
