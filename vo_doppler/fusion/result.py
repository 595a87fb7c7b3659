"""What a heading correction returns, whichever method made it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.model.trajectory import Trajectory


@dataclass
class CorrectionResult:
    """Corrected vehicle poses (level world) and the yaw correction (rad, added to the input's
    yaw) at each pose.

    ``has_absolute``: poses with an absolute heading to compare with. The window method
    ([TK18] Eq. 11–13) also gives the offset Δθ it took at each pose (``window_offset``); the
    Kalman blend (B1)–(B4) gives the correction's standard deviation and its noise model.
    """

    vehicle: Trajectory
    correction: np.ndarray
    has_absolute: np.ndarray
    correction_sigma: np.ndarray | None = None
    window_offset: np.ndarray | None = None
    noise: object | None = None
    """The blend's fitted :class:`~vo_doppler.fusion.heading_blend.NoiseModel`."""
    measurements: int = 0
