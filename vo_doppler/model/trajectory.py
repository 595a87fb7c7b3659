"""Timestamped 6-DoF trajectories.

A pose maps body coordinates to world coordinates: p_world = R @ p_body + t.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.geo import yaw_of
from vo_doppler.model.timeseries import sample

YAW_CHUNK = 8192
"""Poses whose rotation matrices :meth:`Trajectory.yaw` holds at once (a 30-min ground truth
at 100 Hz: 12 MiB of matrices in one piece, taken again by every figure and table that compares
headings with it)."""


@dataclass
class Trajectory:
    """Poses at times ``t`` (N,), positions (N, 3) and orientations as scipy Rotations (N).

    ``t`` and ``positions`` are copies of the arrays given (as :class:`SensorSeries` keeps
    its own): a later change to the caller's arrays does not reach the trajectory.
    """

    t: np.ndarray
    positions: np.ndarray
    orientations: Rotation

    def __post_init__(self) -> None:
        self.t = np.array(self.t, dtype=float).reshape(-1)
        self.positions = np.array(self.positions, dtype=float).reshape(-1, 3)
        n = len(self.t)
        if len(self.positions) != n or len(self.orientations) != n:
            raise ValueError(
                f"trajectory arrays disagree: {n} times, {len(self.positions)} positions, "
                f"{len(self.orientations)} orientations"
            )

    def __len__(self) -> int:
        return len(self.t)

    @classmethod
    def from_matrices(cls, t: np.ndarray, poses: np.ndarray) -> Trajectory:
        """Build from (N, 4, 4) or (N, 3, 4) pose matrices."""
        poses = np.asarray(poses, dtype=float)
        return cls(t, poses[:, :3, 3], Rotation.from_matrix(poses[:, :3, :3]))

    @property
    def matrices(self) -> np.ndarray:
        """Poses as (N, 4, 4) homogeneous matrices."""
        out = np.tile(np.eye(4), (len(self), 1, 1))
        if len(self):
            out[:, :3, :3] = self.orientations.as_matrix()
        out[:, :3, 3] = self.positions
        return out

    @property
    def path_length(self) -> float:
        return float(np.sum(np.linalg.norm(np.diff(self.positions, axis=0), axis=1)))

    def cumulative_distance(self) -> np.ndarray:
        steps = np.linalg.norm(np.diff(self.positions, axis=0), axis=1)
        return np.concatenate([[0.0], np.cumsum(steps)])

    def transformed(self, rotation: np.ndarray, translation: np.ndarray, scale: float = 1.0):
        """Apply the similarity x ↦ s·R·x + t to every pose (orientations are rotated by R)."""
        rot = Rotation.from_matrix(np.asarray(rotation, dtype=float))
        positions = scale * self.positions @ np.asarray(rotation).T + np.asarray(translation)
        return Trajectory(self.t, positions, rot * self.orientations)

    def subset(self, index) -> Trajectory:
        return Trajectory(self.t[index], self.positions[index], self.orientations[index])

    def yaw(self) -> np.ndarray:
        """Yaw (rad, counter-clockwise about z, unwrapped) of every pose, from the rotation
        matrices of :data:`YAW_CHUNK` poses at a time (each pose's yaw is its own matrix's:
        the same values as of all matrices at once, without their 72 bytes per pose)."""
        if not len(self):
            return np.zeros(0)
        yaw = np.concatenate(
            [
                yaw_of(self.orientations[k : k + YAW_CHUNK].as_matrix())
                for k in range(0, len(self), YAW_CHUNK)
            ]
        )
        return np.unwrap(yaw)

    def yaw_at(self, t_query) -> np.ndarray:
        """Yaw interpolated at ``t_query`` (unwrapped; NaN outside the trajectory's times)."""
        return sample(self.t, self.yaw(), t_query)
