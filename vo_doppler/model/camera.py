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

    def size_mismatch(self, width: int, height: int) -> str | None:
        """Why images of ``width`` × ``height`` px cannot be used with this calibration: its
        intrinsics hold for the image size it states, and on images of another size (KITTI's
        1241×376 sequences with the 1226×370 ones' calibration) the principal point and the
        focal lengths in pixels are wrong with nothing to show it. None when the sizes agree or
        the calibration states none (a KITTI ``calib.txt``)."""
        if not (self.width and self.height) or (width, height) == (self.width, self.height):
            return None
        return (
            f"the images are {width}×{height} px but the camera calibration is for "
            f"{self.width}×{self.height} px: use the calibration of these images (its "
            "intrinsics hold only for the size it states)"
        )

    @property
    def has_distortion(self) -> bool:
        return bool(np.any(np.asarray(self.distortion) != 0.0))

    def project(self, points_camera: np.ndarray) -> np.ndarray:
        """Project camera-frame points (N, 3) to pixels (N, 2), ignoring distortion."""
        p = np.asarray(points_camera, dtype=float)
        return np.column_stack(
            [self.fx * p[:, 0] / p[:, 2] + self.cx, self.fy * p[:, 1] / p[:, 2] + self.cy]
        )
