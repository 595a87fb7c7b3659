"""comma2k19 layout readers on synthetic segment folders (extensionless numpy arrays)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from vo_doppler.errors import InputError
from vo_doppler.geo import EnuFrame
from vo_doppler.io.comma2k19 import (
    RAW_GNSS,
    DeviceMount,
    estimate_device_mount,
    gps_minus_log,
    gps_minus_mono,
    read_vehicle_poses,
)

WEEK_S = 604800.0


def _save(base: Path, parts: tuple[str, ...], array: np.ndarray) -> None:
    path = base.joinpath(*parts)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("wb") as handle:  # np.save on a handle keeps the name without ".npy"
        np.save(handle, array)


def _segment(base: Path, log_t: np.ndarray, tow: np.ndarray, pose_offset_s: float) -> Path:
    raw = np.zeros((log_t.size, 10))
    raw[:, 0], raw[:, 1], raw[:, 2] = 5, 2012, tow
    _save(base, (*RAW_GNSS, "t"), log_t)
    _save(base, (*RAW_GNSS, "value"), raw)
    frame_t = np.linspace(log_t[0], log_t[-1], 7)
    gps = np.column_stack([np.full(7, 2012.0), frame_t + pose_offset_s - 2012 * WEEK_S])
    _save(base, ("global_pose", "frame_times"), frame_t)
    _save(base, ("global_pose", "frame_gps_times"), gps)
    return base


def test_log_clock_offset_from_the_receiver_time_tags(tmp_path):
    """GPS − log time from raw_gnss_ublox's (week, time of week) against its ``t``; the pose's
    own offset is read separately (on the example segment the two differ by 0.126 s)."""
    log_t = 46408.5 + 0.1 * np.arange(20)
    offset = 2012 * WEEK_S + 357697.75
    base = _segment(tmp_path, log_t, log_t + offset - 2012 * WEEK_S, offset + 0.125)
    assert gps_minus_log(base) == pytest.approx(offset, abs=1e-6)
    assert gps_minus_mono(base) == pytest.approx(offset + 0.125, abs=1e-6)


def test_varying_offset_is_an_input_error(tmp_path):
    log_t = 46408.5 + 0.1 * np.arange(20)
    tow = log_t + 357697.75
    tow[10:] += 0.01  # a 10 ms jump: log times that are arrival times, not one clock offset
    base = _segment(tmp_path, log_t, tow, 357697.75)
    with pytest.raises(InputError, match="raw_gnss_ublox"):
        gps_minus_log(base)


ENU = EnuFrame(np.radians(37.72), np.radians(-122.47), 30.0)
FLIP = np.array([1.0, -1.0, -1.0])
"""Device frame (x forward, y right, z down) ↔ x forward, y left, z up."""


def _pose_segment(base: Path, mount: DeviceMount, body_roll_deg: np.ndarray) -> np.ndarray:
    """``global_pose`` of a car climbing and turning (12 m/s, grade 0 → 6 %, heading 30° →
    120°), its x axis along the velocity, rolled by ``body_roll_deg`` per epoch, carrying the
    device mounted by ``mount``; two stopped epochs at the start with the device at random.
    Returns the vehicle → ECEF rotations."""
    n = body_roll_deg.size
    t = 0.05 * np.arange(n)
    heading = np.radians(30.0) + np.radians(90.0) * t / t[-1]
    grade = np.arctan(0.06 * t / t[-1])
    direction = np.column_stack(
        [np.cos(grade) * np.cos(heading), np.cos(grade) * np.sin(heading), np.sin(grade)]
    )
    speed = np.where(np.arange(n) < 2, 0.0, 12.0)
    velocity_enu = speed[:, None] * direction
    positions_enu = np.cumsum(velocity_enu * 0.05, axis=0)
    vehicle_to_enu = Rotation.from_euler(
        "ZYX", np.column_stack([heading, -grade, np.radians(body_roll_deg)])
    ).as_matrix()
    vehicle_to_enu[:2] = Rotation.random(2, random_state=1).as_matrix()
    to_ecef = ENU.rotation.T  # the frame's ENU → ECEF (the segment spans 0.7 km)
    vehicle_to_ecef = to_ecef @ vehicle_to_enu
    device_to_ecef = (vehicle_to_ecef @ mount.vehicle_to_device.T) * FLIP
    quaternion_xyzw = Rotation.from_matrix(device_to_ecef).as_quat()
    _save(base, ("global_pose", "frame_times"), t)
    _save(base, ("global_pose", "frame_positions"), ENU.enu_to_ecef(positions_enu))
    _save(base, ("global_pose", "frame_velocities"), velocity_enu @ to_ecef.T)
    _save(base, ("global_pose", "frame_orientations"), quaternion_xyzw[:, [3, 0, 1, 2]])
    return vehicle_to_ecef


def test_a_known_device_mounting_is_recovered_and_removed(tmp_path):
    """Device mounted 3.8° nose down of the travel, 0.8° left of it, rolled 1.2°; the car's
    own roll swings ±2° about zero. Yaw and pitch need no vertical: exact to rounding. Roll: the
    median of a symmetric swing is zero, but the poses' local verticals turn by up to 0.006°
    over the 0.7 km against the one vertical of the simulated ENU frame: within 0.01°, and so
    is the vehicle's attitude."""
    mount = DeviceMount(np.radians(-0.8), np.radians(3.8), np.radians(-1.2))
    roll = 2.0 * np.sin(np.linspace(0.0, 6.0 * np.pi, 601))
    vehicle_to_ecef = _pose_segment(tmp_path, mount, roll)
    t, positions, poses, found = read_vehicle_poses(tmp_path)
    assert t.size == positions.shape[0] == poses.shape[0] == 601
    assert np.degrees(found.yaw) == pytest.approx(-0.8, abs=1e-9)
    assert np.degrees(found.pitch) == pytest.approx(3.8, abs=1e-9)
    assert np.degrees(found.roll) == pytest.approx(-1.2, abs=0.01)
    angle = Rotation.from_matrix(poses[2:]).inv() * Rotation.from_matrix(vehicle_to_ecef[2:])
    assert np.degrees(angle.magnitude()).max() < 0.01


def test_without_a_moving_epoch_the_device_frame_is_kept():
    frames = Rotation.random(3, random_state=2).as_matrix()
    found = estimate_device_mount(frames, np.full((3, 3), 0.1), np.tile([0.0, 0.0, 1.0], (3, 1)))
    np.testing.assert_array_equal(found.vehicle_to_device, np.eye(3))
