"""A level vehicle track with one turn, for the world-frame checks."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.model.trajectory import Trajectory


def level_turn(east_m: float = 60.0, north_m: float = 40.0, step_m: float = 0.5) -> Trajectory:
    """Vehicle poses in a level z-up world: east, then a 90° turn left, then north."""
    east = np.arange(0.0, east_m + step_m / 2, step_m)
    north = np.arange(step_m, north_m + step_m / 2, step_m)
    positions = np.concatenate(
        [
            np.column_stack([east, np.zeros_like(east), np.zeros_like(east)]),
            np.column_stack([np.full_like(north, east_m), north, np.zeros_like(north)]),
        ]
    )
    yaw = np.r_[np.zeros(len(east)), np.full(len(north), np.pi / 2)]
    t = np.arange(len(positions)) * 0.05
    return Trajectory(t, positions, Rotation.from_euler("z", yaw[:, None]))
