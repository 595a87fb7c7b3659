"""Heading drift in deg/min and the start–end gap of a closed loop, in [KZ]'s Table 1 layout.

Drift of a yaw history against a reference (ground truth, the GPS course, or a constant heading
on a standstill): e(t) = ψ(t) − ψ_ref(t), unwrapped, and drift = (ē_end − ē_start) / Δt, where ē
are means over ``window_s`` seconds at each end of the evaluated epochs (a single epoch when 0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.geo import wrap_angle

VARIANTS = (
    "sensor 1",
    "sensor 2",
    "combined",
    "combined + threshold",
    "combined + ε0 removed",
    "combined + ε0 removed + threshold",
)


def heading_error(yaw: np.ndarray, reference_yaw: np.ndarray) -> np.ndarray:
    """ψ − ψ_ref wrapped per epoch, then unwrapped along time so that whole turns accumulate."""
    return np.unwrap(wrap_angle(np.asarray(yaw, dtype=float) - np.asarray(reference_yaw)))


def drift_rate_deg_per_min(t: np.ndarray, error_rad: np.ndarray, window_s: float = 0.0) -> float:
    """(mean error over the last ``window_s`` − mean over the first) per minute, in degrees."""
    t = np.asarray(t, dtype=float)
    error_rad = np.asarray(error_rad, dtype=float)
    if len(t) < 2 or t[-1] <= t[0]:
        raise InputError("drift needs at least two epochs spanning some time")
    first = t <= t[0] + window_s
    last = t >= t[-1] - window_s
    span = float(np.mean(t[last]) - np.mean(t[first]))
    if span <= 0:
        raise InputError(f"drift window {window_s} s is longer than half the record")
    change = float(np.mean(error_rad[last]) - np.mean(error_rad[first]))
    return float(np.degrees(change) / (span / 60.0))


@dataclass(frozen=True)
class LoopGap:
    """Start–end distance of a trajectory and its ratio to the travelled length."""

    gap_m: float
    length_m: float

    @property
    def percent(self) -> float:
        return 100.0 * self.gap_m / self.length_m if self.length_m > 0 else float("nan")


def closed_loop_gap(east: np.ndarray, north: np.ndarray) -> LoopGap:
    """Distance between the first and the last position, and the path length."""
    east = np.asarray(east, dtype=float)
    north = np.asarray(north, dtype=float)
    length = float(np.sum(np.hypot(np.diff(east), np.diff(north))))
    return LoopGap(float(np.hypot(east[-1] - east[0], north[-1] - north[0])), length)


@dataclass(frozen=True)
class DriftRow:
    """One row of the drift table."""

    variant: str
    drift_deg_per_min: float
    final_heading_error_deg: float
    gap: LoopGap
