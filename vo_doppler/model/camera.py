"""Pinhole camera with OpenCV distortion and its mounting on the vehicle.

Camera frame: OpenCV (x right, y down, z forward). ``T_vehicle_camera`` maps camera
coordinates to vehicle coordinates (vehicle: x forward, y left, z up).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

CAMERA_TO_VEHICLE_FORWARD = np.array(
    [
        [0.0, 0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0, 0.0],
        [0.0, -1.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]
)
"""Default extrinsic of a forward-looking camera: camera z → vehicle x, x → −y, y → −z."""


@dataclass
class Camera:
    fx: float
    fy: float
    cx: float
    cy: float
    width: int = 0
    height: int = 0
    distortion: np.ndarray = field(default_factory=lambda: np.zeros(5))
    T_vehicle_camera: np.ndarray = field(default_factory=lambda: CAMERA_TO_VEHICLE_FORWARD.copy())

    @property
    def K(self) -> np.ndarray:
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def has_distortion(self) -> bool:
        return bool(np.any(np.asarray(self.distortion) != 0.0))

    def project(self, points_camera: np.ndarray) -> np.ndarray:
        """Project camera-frame points (N, 3) to pixels (N, 2), ignoring distortion."""
        p = np.asarray(points_camera, dtype=float)
        return np.column_stack(
            [self.fx * p[:, 0] / p[:, 2] + self.cx, self.fy * p[:, 1] / p[:, 2] + self.cy]
        )
