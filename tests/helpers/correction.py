"""Camera-pose adapters for the correction tests: a VO writes camera poses, the correction
takes vehicle poses; these convert once, as the VO stage does, and convert the result back."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.fusion.heading_blend import blend_heading
from vo_doppler.fusion.heading_correction import correct_heading
from vo_doppler.fusion.result import CorrectionResult
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.vo.frames import camera_trajectory, vehicle_trajectory


@dataclass
class CameraCorrection:
    result: CorrectionResult
    camera: Trajectory

    def __getattr__(self, name):
        return getattr(self.result, name)


def correct_camera(
    camera: Trajectory,
    *args,
    camera_to_vehicle: np.ndarray = CAMERA_TO_VEHICLE_FORWARD,
    world: str = "first_camera",
    reference: str = "orientation",
    **kwargs,
) -> CameraCorrection:
    """[TK18] Eq. 11–13 on camera poses (orientation reference unless told otherwise)."""
    vehicle = vehicle_trajectory(camera, camera_to_vehicle, world)
    result = correct_heading(vehicle, *args, reference=reference, **kwargs)
    return CameraCorrection(result, camera_trajectory(result.vehicle, camera_to_vehicle))


def blend_camera(
    camera: Trajectory,
    *args,
    camera_to_vehicle: np.ndarray = CAMERA_TO_VEHICLE_FORWARD,
    world: str = "first_camera",
    **kwargs,
) -> CameraCorrection:
    """The Kalman blend (B1)–(B4) on camera poses."""
    vehicle = vehicle_trajectory(camera, camera_to_vehicle, world)
    result = blend_heading(vehicle, *args, **kwargs)
    return CameraCorrection(result, camera_trajectory(result.vehicle, camera_to_vehicle))
