"""A GNSS receiver's own navigation solution (u-blox NAV-PVT and the like), on GPS time."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ReceiverSolution:
    """Per-fix receiver output: ``t`` GPS s; ``lat``/``lon`` rad, ``height`` m above the
    ellipsoid; ``velocity_ned`` (N, 3) m/s; ``speed`` ground speed m/s and ``course`` rad
    clockwise from north, with their 1σ accuracies ``speed_accuracy`` (m/s) and
    ``course_accuracy`` (rad); ``horizontal_accuracy``/``vertical_accuracy`` m; ``fix_ok`` the
    receiver's own validity flag; ``n_sat`` satellites used."""

    t: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    height: np.ndarray
    velocity_ned: np.ndarray
    speed: np.ndarray
    course: np.ndarray
    speed_accuracy: np.ndarray
    course_accuracy: np.ndarray
    horizontal_accuracy: np.ndarray
    vertical_accuracy: np.ndarray
    fix_ok: np.ndarray
    n_sat: np.ndarray

    def __len__(self) -> int:
        return int(self.t.size)
