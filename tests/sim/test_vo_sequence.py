"""Synthetic VO sequences: route, speed profile, ground truth, files, determinism, tracking."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import REPO_ROOT
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.trajectory import read_kitti, read_tum
from vo_doppler.sim.scene import CityLayout, city_scene
from vo_doppler.sim.vo_sequence import (
    CAMERA_HEIGHT_M,
    drive,
    generate_vo_sequence,
    loop_route,
    plan_vo_sequence,
    simulate_vo,
    synthetic_camera,
)

LAYOUT = CityLayout(4, 3, (60.0, 60.0), 16.0)


@pytest.fixture(scope="module")
def small_scene():
    return city_scene(seed=2, tile_size=256, n_facade_textures=2)


def test_loop_route_is_closed_and_continuous():
    route = loop_route(LAYOUT, laps=2)
    pitch = 76.0
    # Lap = perimeter of the lane rectangle (2·76+8 by 76+8) with four quarter circles of 10 m.
    lap = 2 * (160.0 + 84.0) - 8 * 10.0 + 2 * np.pi * 10.0
    assert route.length == pytest.approx(2 * lap)
    xy, yaw, _ = route.at(np.array([0.0, lap, 2 * lap]))
    np.testing.assert_allclose(xy, [[2 * pitch, pitch - 4.0]] * 3, atol=1e-9)
    np.testing.assert_allclose(yaw, [0.0, 2 * np.pi, 4 * np.pi], atol=1e-12)
    s = np.arange(0.0, route.length, 0.01)
    xy, yaw, curvature = route.at(s)
    steps = np.linalg.norm(np.diff(xy, axis=0), axis=1)
    np.testing.assert_allclose(steps, 0.01, rtol=1e-6)  # no jumps at segment joins
    assert set(np.round(np.unique(curvature), 9)) == {0.0, 0.1}
    heading = np.arctan2(np.diff(xy[:, 1]), np.diff(xy[:, 0]))
    np.testing.assert_allclose(np.angle(np.exp(1j * (heading - yaw[:-1]))), 0.0, atol=1e-3)


def test_speed_profile_limits_and_kinematics():
    route = loop_route(LAYOUT)
    t = np.arange(0.0, 40.0, 0.01)
    motion = drive(route, t, max_speed=12.0, max_lateral_accel=2.0, max_accel=1.5, max_decel=2.5)
    assert motion.speed.max() == pytest.approx(12.0, abs=1e-6)
    assert np.all(motion.speed[np.abs(motion.yaw_rate) > 0] <= np.sqrt(2.0 * 10.0) + 1e-6)
    accel = np.diff(motion.speed) / 0.01
    assert accel.max() <= 1.5 + 1e-3 and accel.min() >= -2.5 - 1e-3
    # Distance between samples is the integral of speed; yaw change the integral of yaw rate.
    distance = np.linalg.norm(np.diff(motion.xy, axis=0), axis=1)
    np.testing.assert_allclose(
        distance, 0.5 * (motion.speed[1:] + motion.speed[:-1]) * 0.01, atol=2e-4
    )
    # Away from the curvature jumps at turn entry/exit, the yaw step is the trapezoid of yaw rate.
    same = (motion.yaw_rate[1:] > 0) == (motion.yaw_rate[:-1] > 0)
    turned = 0.5 * (motion.yaw_rate[1:] + motion.yaw_rate[:-1]) * 0.01
    np.testing.assert_allclose(np.diff(motion.yaw)[same], turned[same], atol=1e-9)
    assert motion.yaw[-1] == pytest.approx(np.pi / 2 * round(motion.yaw[-1] / (np.pi / 2)))


@pytest.mark.slow
@settings(max_examples=15, deadline=None)
@given(
    max_speed=st.floats(3.0, 16.0),
    lateral=st.floats(1.0, 4.0),
    accel=st.floats(0.5, 3.0),
    decel=st.floats(0.5, 4.0),
    initial=st.floats(0.0, 16.0),
    stop=st.floats(20.0, 150.0),
)
def test_speed_profile_respects_its_limits(max_speed, lateral, accel, decel, initial, stop):
    route = loop_route(LAYOUT, laps=4)
    t = np.arange(0.0, 90.0, 0.02)
    motion = drive(route, t, max_speed, lateral, accel, decel, initial, stops_m=[stop])
    assert np.all(motion.speed >= 0.0)
    assert np.all(motion.speed <= max_speed + 1e-9)
    turning = np.abs(motion.yaw_rate) > 0
    assert np.all(motion.speed[turning] <= np.sqrt(lateral * 10.0) + 1e-6)
    change = np.diff(motion.speed) / 0.02
    assert change.max() <= accel + 1e-3 and change.min() >= -decel - 1e-3
    assert np.any(motion.speed == 0.0)  # the stop comes within 90 s even at 3 m/s


def test_stop_holds_the_vehicle_still():
    route = loop_route(LAYOUT)
    t = np.arange(0.0, 30.0, 0.05)
    motion = drive(route, t, stops_m=[60.0], stop_duration_s=4.0)
    still = motion.speed == 0.0
    assert 4.0 - 0.1 <= still.sum() * 0.05 <= 4.0 + 0.1
    assert np.ptp(motion.xy[still], axis=0).max() < 1e-9
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(motion.xy, axis=0), axis=1))])
    assert arc[still][0] == pytest.approx(60.0, abs=0.05)


def test_drive_rejects_times_beyond_the_route():
    with pytest.raises(ValueError, match="route ends"):
        drive(loop_route(LAYOUT), np.array([0.0, 1000.0]))


def test_camera_poses_follow_the_vehicle(small_scene):
    plan = plan_vo_sequence(3.0, 10.0, seed=2, scene=small_scene)
    T = plan.T_world_camera
    np.testing.assert_allclose(T[:, 2, 3], CAMERA_HEIGHT_M)
    np.testing.assert_allclose(
        T[:, :3, 2],
        np.column_stack([np.cos(plan.motion.yaw), np.sin(plan.motion.yaw), np.zeros(len(T))]),
        atol=1e-12,
    )  # optical axis = vehicle forward
    np.testing.assert_allclose(plan.T_first_camera[0], np.eye(4), atol=1e-12)
    # First-camera frame: driving straight ahead is +z (forward) in OpenCV axes.
    forward = plan.T_first_camera[10, :3, 3]
    assert forward[2] > 5.0 and abs(forward[0]) < 1e-9 and abs(forward[1]) < 1e-9


def test_simulation_is_deterministic_per_seed(small_scene):
    a = simulate_vo(0.3, 10.0, seed=2, scene=small_scene, noise_std=1.0)
    b = simulate_vo(0.3, 10.0, seed=2, scene=small_scene, noise_std=1.0)
    c = simulate_vo(0.3, 10.0, seed=3, scene=small_scene, noise_std=1.0)
    assert a.images.shape == (3, 360, 640) and a.images.dtype == np.uint8
    np.testing.assert_array_equal(a.images, b.images)
    np.testing.assert_array_equal(a.plan.T_world_camera, b.plan.T_world_camera)
    assert not np.array_equal(a.images, c.images)  # same poses, other noise


@pytest.mark.slow
def test_generated_files_read_back(tmp_path, small_scene):
    plan = generate_vo_sequence(tmp_path, 0.5, 10.0, seed=2, scene=small_scene, t0=100.0)
    images = sorted((tmp_path / "image_0").glob("*.png"))
    assert [p.name for p in images] == [f"{k:06d}.png" for k in range(5)]
    assert cv2.imread(str(images[0]), cv2.IMREAD_UNCHANGED).shape == (360, 640)
    times = np.loadtxt(tmp_path / "times.txt")
    np.testing.assert_allclose(times, 100.0 + np.arange(5) / 10.0)
    camera = read_camera(tmp_path / "calib.yaml")
    np.testing.assert_allclose(camera.K, plan.camera.K)
    np.testing.assert_allclose(camera.T_vehicle_camera, plan.camera.T_vehicle_camera)
    kitti = read_kitti(tmp_path / "ground_truth_camera.kitti", times)
    np.testing.assert_allclose(kitti.matrices, plan.T_first_camera, atol=1e-8)
    tum = read_tum(tmp_path / "ground_truth_camera.tum")
    np.testing.assert_allclose(tum.matrices, plan.T_first_camera, atol=1e-8)
    vehicle = read_tum(tmp_path / "ground_truth.tum")
    np.testing.assert_allclose(vehicle.matrices, plan.motion.T_world_vehicle, atol=1e-8)
    assert (tmp_path / "speed.csv").read_text().splitlines()[0] == "t,speed_mps"
    speed = np.loadtxt(tmp_path / "speed.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(speed, np.column_stack([times, plan.motion.speed]), atol=1e-6)


def test_regenerating_replaces_older_frames(tmp_path, small_scene):
    generate_vo_sequence(tmp_path, 0.5, 10.0, seed=2, scene=small_scene)
    generate_vo_sequence(tmp_path, 0.3, 10.0, seed=2, scene=small_scene, image_format="jpg")
    names = sorted(p.name for p in (tmp_path / "image_0").iterdir())
    assert names == ["000000.jpg", "000001.jpg", "000002.jpg"]
    assert len(np.loadtxt(tmp_path / "times.txt")) == 3


def test_bundled_calibration_is_the_synthetic_camera():
    camera = read_camera(REPO_ROOT / "calib" / "synthetic.yaml")
    expected = synthetic_camera()
    np.testing.assert_allclose(camera.K, expected.K)
    assert (camera.width, camera.height) == (expected.width, expected.height)
    np.testing.assert_allclose(camera.T_vehicle_camera, expected.T_vehicle_camera)


def test_consecutive_frames_are_trackable(small_scene):
    """Hundreds of corners; pyramidal KLT forward–backward error < 0.5 px for most of them."""
    sequence = simulate_vo(0.2, 15.0, seed=2, scene=small_scene, initial_speed=8.0)
    first, second = sequence.images[:2]
    corners = cv2.goodFeaturesToTrack(first, 1000, 0.01, 7)
    assert len(corners) >= 500
    ahead, status, _ = cv2.calcOpticalFlowPyrLK(
        first, second, corners, None, winSize=(15, 15), maxLevel=3
    )
    back, status_back, _ = cv2.calcOpticalFlowPyrLK(
        second, first, ahead, None, winSize=(15, 15), maxLevel=3
    )
    error = np.linalg.norm((back - corners)[:, 0], axis=1)
    good = (status[:, 0] == 1) & (status_back[:, 0] == 1) & (error < 0.5)
    assert good.mean() > 0.6
