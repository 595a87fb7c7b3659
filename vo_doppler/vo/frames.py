"""The VO stage's output frame: camera poses (OpenCV axes) become vehicle poses once, here.

A monocular VO writes camera poses in the frame of its first camera. With the camera→vehicle
extrinsic ``T_vehicle_camera`` the vehicle poses (x forward, y left, z up) are expressed in the
first vehicle frame, which is level when the vehicle starts level; ``world="level"`` declares
that the camera poses' world is already z-up (e.g. ENU), so only the extrinsic is removed.
"""

from __future__ import annotations

import numpy as np

from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD
from vo_doppler.model.trajectory import Trajectory

WORLDS = ("first_camera", "level")


def vehicle_trajectory(
    camera: Trajectory,
    T_vehicle_camera: np.ndarray = CAMERA_TO_VEHICLE_FORWARD,
    world: str = "first_camera",
) -> Trajectory:
    """Vehicle poses T_w_veh = T_w_cam · T_veh_cam⁻¹, re-expressed in the first vehicle frame
    for ``world="first_camera"``."""
    if world not in WORLDS:
        raise ValueError(f"unknown world {world!r} ({' or '.join(WORLDS)})")
    poses = camera.matrices @ np.linalg.inv(np.asarray(T_vehicle_camera, dtype=float))
    if world == "first_camera" and len(poses):
        poses = np.linalg.inv(poses[0]) @ poses
    return Trajectory.from_matrices(camera.t.copy(), poses)


def camera_trajectory(vehicle: Trajectory, T_vehicle_camera: np.ndarray) -> Trajectory:
    """Camera poses of vehicle poses (the inverse of :func:`vehicle_trajectory`'s extrinsic)."""
    return Trajectory.from_matrices(
        vehicle.t.copy(), vehicle.matrices @ np.asarray(T_vehicle_camera, dtype=float)
    )
