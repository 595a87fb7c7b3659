"""The VO output frame: how steep a vehicle track is in its declared world."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.helpers.level_track import level_turn
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD as FORWARD
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.vo.frames import camera_trajectory, steep_path_fraction, vehicle_trajectory


def test_a_track_in_its_own_world_is_not_steep():
    track = level_turn()
    assert steep_path_fraction(track) == 0.0
    assert steep_path_fraction(vehicle_trajectory(camera_trajectory(track, FORWARD))) == 0.0


# A chord is 5 m (a twentieth of the 100 m path); the 5 m before the end have none. A chord
# across the turn is steeper than 30° when its vertical part over its level part exceeds tan 30°:
# so for the 5 / (1 + tan 30°) = 3.17 m before the turn whichever leg is the vertical one. The
# grid of 0.5 m adds at most a step.
STEP_SHARE = 0.006
ACROSS_THE_TURN = 5.0 / (1.0 + np.tan(np.radians(30.0)))
NORTH_LEG_VERTICAL = (40.0 - 5.0 + ACROSS_THE_TURN) / 100.0
EAST_LEG_VERTICAL = (60.0 - 5.0 + ACROSS_THE_TURN) / 100.0


def test_a_level_track_read_as_first_camera_climbs_along_its_northward_leg():
    """Vehicle poses of a level world read as camera poses put the vehicle's left (here north)
    on the first camera's y axis, its down: the northward leg becomes vertical."""
    camera = camera_trajectory(level_turn(), FORWARD)
    wrong = vehicle_trajectory(level_turn(), FORWARD, "first_camera")
    assert steep_path_fraction(vehicle_trajectory(camera, FORWARD, "first_camera")) == 0.0
    assert steep_path_fraction(wrong) == pytest.approx(NORTH_LEG_VERTICAL, abs=STEP_SHARE)


def test_camera_poses_read_as_level_climb_along_their_forward_leg():
    """Camera poses in the first camera's frame read as level put the camera's forward axis
    (the first leg) on the vertical."""
    camera = camera_trajectory(level_turn(), FORWARD).matrices
    in_first_camera = Trajectory.from_matrices(level_turn().t, np.linalg.inv(camera[0]) @ camera)
    wrong = vehicle_trajectory(in_first_camera, FORWARD, "level")
    assert steep_path_fraction(wrong) == pytest.approx(EAST_LEG_VERTICAL, abs=STEP_SHARE)


def test_a_road_of_25_degrees_is_not_steep_and_a_still_track_is_zero():
    s = np.linspace(0.0, 100.0, 201)
    climb = np.radians(25.0)
    ramp = np.column_stack([s * np.cos(climb), np.zeros_like(s), s * np.sin(climb)])
    assert steep_path_fraction(Trajectory(s, ramp, Rotation.identity(len(s)))) == 0.0
    still = Trajectory(np.arange(5.0), np.zeros((5, 3)), Rotation.identity(5))
    assert steep_path_fraction(still) == 0.0
