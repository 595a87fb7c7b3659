"""Heading drift in deg/min and the start–end gap of a closed loop, in [KZ]'s Table 1 layout
(the gap only on a route that closes; on any route the end's distance from the reference's).

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


LOOP_CLOSED_FRACTION = 0.05
LOOP_CLOSED_MIN_M = 10.0
"""A route closes when its reference track ends within 5 % of its length, and at least 10 m
(a GPS fix's error), of its start: only then is the dead reckoning's start–end gap a measure
of its error ([KZ] Table 1 drives loops); on an open route the gap is the route's own extent
(comma2k19's 1 km of straight road: "gap 99.995 %")."""


@dataclass(frozen=True)
class LoopGap:
    """Where a dead-reckoned trajectory ends. ``gap_m``: its start–end distance, NaN unless
    the route ``closed``; ``end_error_m``: its distance from the reference track's end (NaN
    without a reference); ``length_m``: its travelled length."""

    gap_m: float
    length_m: float
    closed: bool = True
    end_error_m: float = float("nan")

    @property
    def percent(self) -> float:
        return self._of_length(self.gap_m)

    @property
    def end_error_percent(self) -> float:
        return self._of_length(self.end_error_m)

    def _of_length(self, distance_m: float) -> float:
        return 100.0 * distance_m / self.length_m if self.length_m > 0 else float("nan")


def _path_length(east: np.ndarray, north: np.ndarray) -> float:
    return float(np.sum(np.hypot(np.diff(east), np.diff(north))))


def route_closes(east: np.ndarray, north: np.ndarray) -> bool:
    """Whether a track ends near its start (``LOOP_CLOSED_FRACTION``, ``LOOP_CLOSED_MIN_M``)."""
    east, north = np.asarray(east, dtype=float), np.asarray(north, dtype=float)
    gap = float(np.hypot(east[-1] - east[0], north[-1] - north[0]))
    return gap <= max(LOOP_CLOSED_MIN_M, LOOP_CLOSED_FRACTION * _path_length(east, north))


def closed_loop_gap(
    east: np.ndarray, north: np.ndarray, reference_enu: np.ndarray | None = None
) -> LoopGap:
    """The start–end distance and path length of a trajectory; with ``reference_enu`` (N, ≥2:
    the reference track at the same epochs, e.g. the GPS track), the gap only when the
    reference route closes (``route_closes``) and the distance between the two ends."""
    east = np.asarray(east, dtype=float)
    north = np.asarray(north, dtype=float)
    gap = float(np.hypot(east[-1] - east[0], north[-1] - north[0]))
    length = _path_length(east, north)
    if reference_enu is None:
        return LoopGap(gap, length)
    reference = np.asarray(reference_enu, dtype=float)
    closed = route_closes(reference[:, 0], reference[:, 1])
    end_error = float(np.hypot(east[-1] - reference[-1, 0], north[-1] - reference[-1, 1]))
    return LoopGap(gap if closed else float("nan"), length, closed, end_error)


@dataclass(frozen=True)
class DriftRow:
    """One row of the drift table."""

    variant: str
    drift_deg_per_min: float
    final_heading_error_deg: float
    gap: LoopGap
