"""The VO stage's output frame: camera poses (OpenCV axes) become vehicle poses once, here.

A monocular VO writes camera poses in the frame of its first camera. With the camera→vehicle
extrinsic ``T_vehicle_camera`` the vehicle poses (x forward, y left, z up) are expressed in the
first vehicle frame, which is level when the vehicle starts level; ``world="level"`` declares
that the camera poses' world is already z-up (e.g. ENU), so only the extrinsic is removed.
"""

from __future__ import annotations

from enum import StrEnum

import numpy as np

from vo_doppler.choices import checked
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD
from vo_doppler.model.trajectory import Trajectory


class World(StrEnum):
    """The world of the camera poses given to :func:`vehicle_trajectory` (``correct
    --world``)."""

    FIRST_CAMERA = "first_camera"
    """The first camera's frame (OpenCV axes), what VO systems write."""
    LEVEL = "level"
    """Already level, z up (e.g. ENU)."""


MAX_ROAD_CLIMB = np.radians(30.0)
"""Steeper than any road (58 % grade): a vehicle track climbing so is in a wrongly oriented
world."""
WRONG_WORLD_FRACTION = 0.1
"""A :func:`steep_path_fraction` above which the declared world is probably wrong (a track in
its right world has none: 0.000 on the KITTI, comma2k19 and synthetic tracks at hand, 0.29 for
a level dead-reckoning track with one 90° turn read as ``first_camera``, 0.96 for KITTI camera
poses read as ``level``)."""


def vehicle_trajectory(
    camera: Trajectory,
    T_vehicle_camera: np.ndarray = CAMERA_TO_VEHICLE_FORWARD,
    world: World | str = World.FIRST_CAMERA,
) -> Trajectory:
    """Vehicle poses T_w_veh = T_w_cam · T_veh_cam⁻¹, re-expressed in the first vehicle frame
    for ``world="first_camera"``."""
    world = checked(World, world, "world")
    poses = camera.matrices @ np.linalg.inv(np.asarray(T_vehicle_camera, dtype=float))
    if world is World.FIRST_CAMERA and len(poses):
        poses = np.linalg.inv(poses[0]) @ poses
    return Trajectory.from_matrices(camera.t.copy(), poses)


def camera_trajectory(vehicle: Trajectory, T_vehicle_camera: np.ndarray) -> Trajectory:
    """Camera poses of vehicle poses (the inverse of :func:`vehicle_trajectory`'s extrinsic)."""
    return Trajectory.from_matrices(
        vehicle.t.copy(), vehicle.matrices @ np.asarray(T_vehicle_camera, dtype=float)
    )


def steep_path_fraction(
    vehicle: Trajectory, max_climb: float = MAX_ROAD_CLIMB, chord_fraction: float = 0.05
) -> float:
    """Share of the path (by length) along which the vehicle climbs or falls steeper than
    ``max_climb`` (rad) over the chord ahead of ``chord_fraction`` of the path length.

    No road is that steep, so a large share says the poses' world is not the one declared:
    a level (z-up) track read as ``first_camera`` poses puts its northward motion on the
    vertical, camera poses read as ``level`` their forward motion. Chords a twentieth of the
    path long average out VO jitter and a car creeping or standing; the share is scale-free,
    so a VO of arbitrary scale is judged as a metric one. 0 for a path that does not move.
    """
    distance = vehicle.cumulative_distance()
    total = float(distance[-1]) if len(distance) else 0.0
    if not total > 0.0:
        return 0.0
    end = np.searchsorted(distance, distance + chord_fraction * total)
    start = np.flatnonzero(end < len(distance))
    chord = vehicle.positions[end[start]] - vehicle.positions[start]
    climb = np.arctan2(np.abs(chord[:, 2]), np.hypot(chord[:, 0], chord[:, 1]))
    steps = np.diff(distance)[start]
    return float(steps[climb > max_climb].sum() / total)
