"""Dead reckoning from step lengths and yaw-rate increments, [KZ] Eq. (15)–(17).

[KZ] writes the update in a clockwise heading θ measured from north:
    x ← x + ΔL·sin(θ + Δθ/2)     (15)   east
    y ← y + ΔL·cos(θ + Δθ/2)     (16)   north
    θ ← θ + Δθ                   (17)
The public functions take and return docs/design.md's yaw ψ (counter-clockwise from east, positive
yaw rate turns left); the conversion θ = π/2 − ψ, Δθ = −Δψ happens only at the boundary.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.errors import InputError
from vo_doppler.geo import wrap_angle
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.timeseries import increments, travelled_distance
from vo_doppler.model.trajectory import Trajectory


@dataclass(frozen=True)
class DeadReckoning:
    """Positions (m, ENU east/north) and yaw (rad, CCW from east, wrapped) per epoch."""

    t: np.ndarray
    east: np.ndarray
    north: np.ndarray
    yaw: np.ndarray

    @property
    def path_length(self) -> float:
        return float(np.sum(np.hypot(np.diff(self.east), np.diff(self.north))))

    def trajectory(self, up: float = 0.0) -> Trajectory:
        """Vehicle poses in ENU at height ``up`` (m), the yaw a rotation about up."""
        positions = np.column_stack([self.east, self.north, np.full(len(self.t), up)])
        return Trajectory(
            self.t, positions, Rotation.from_euler("z", np.asarray(self.yaw)[:, None])
        )


def dead_reckon(
    t: np.ndarray,
    step_length: np.ndarray,
    delta_yaw: np.ndarray,
    yaw0: float,
    start: tuple[float, float] = (0.0, 0.0),
) -> DeadReckoning:
    """[KZ] Eq. (15)–(17) over N epochs from N − 1 step lengths (m) and yaw increments (rad,
    CCW)."""
    t = np.asarray(t, dtype=float)
    step_length = np.asarray(step_length, dtype=float)
    delta_yaw = np.asarray(delta_yaw, dtype=float)
    if not (len(step_length) == len(delta_yaw) == len(t) - 1):
        raise InputError(
            f"{len(t)} epochs need {len(t) - 1} steps, got {len(step_length)} step lengths "
            f"and {len(delta_yaw)} yaw increments"
        )
    theta0 = np.pi / 2.0 - yaw0
    delta_theta = -delta_yaw
    theta = theta0 + np.concatenate([[0.0], np.cumsum(delta_theta)])
    mid = theta[:-1] + delta_theta / 2.0
    east = start[0] + np.concatenate([[0.0], np.cumsum(step_length * np.sin(mid))])
    north = start[1] + np.concatenate([[0.0], np.cumsum(step_length * np.cos(mid))])
    return DeadReckoning(t, east, north, wrap_angle(np.pi / 2.0 - theta))


def track_yaw(east: np.ndarray, north: np.ndarray, min_step_m: float = 1.0) -> np.ndarray:
    """Direction of travel (rad, CCW from east) of a track at each point, from the step that
    leaves it; points whose step is shorter than ``min_step_m`` get NaN (no direction)."""
    de = np.diff(np.asarray(east, dtype=float))
    dn = np.diff(np.asarray(north, dtype=float))
    yaw = np.where(np.hypot(de, dn) >= min_step_m, np.arctan2(dn, de), np.nan)
    return np.concatenate([yaw, [np.nan]])


def wheel_gyro_track(speed: SensorSeries, yaw_rate: SensorSeries, t: np.ndarray) -> Trajectory:
    """Planar wheel + gyro dead reckoning ([KZ] Eq. 15–17) at times ``t`` inside both records,
    starting at the origin facing east (yaw 0)."""
    steps = np.diff(travelled_distance(speed.t, speed.value, t))
    turns = increments(yaw_rate.t, yaw_rate.value, t)
    return dead_reckon(t, steps, turns, 0.0).trajectory()
