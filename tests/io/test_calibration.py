"""Camera calibration files: KITTI calib.txt rows and OpenCV/Kalibr YAML."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from tests.conftest import REPO_ROOT, require_shared
from vo_doppler.errors import InputError
from vo_doppler.io.calibration import read_camera, write_camera_yaml
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD, Camera


def test_bundled_kitti_yaml_matches_the_sequence_calib():
    calib = require_shared("kitti06_0000_0050/calib.txt")
    from_txt = read_camera(calib)
    from_yaml = read_camera(REPO_ROOT / "calib" / "kitti_odometry_04-12.yaml")
    np.testing.assert_allclose(from_yaml.K, from_txt.K)
    assert (from_yaml.width, from_yaml.height) == (1226, 370)


@pytest.mark.parametrize("name", ["kitti_odometry_00-02", "kitti_odometry_03", "synthetic"])
def test_bundled_calibrations_load(name):
    camera = read_camera(REPO_ROOT / "calib" / f"{name}.yaml")
    assert camera.fx > 100 and camera.width > camera.height > 0
    rotation = camera.T_vehicle_camera[:3, :3]
    np.testing.assert_allclose(rotation, CAMERA_TO_VEHICLE_FORWARD[:3, :3])


def test_forward_extrinsic_maps_optical_axis_to_vehicle_forward():
    forward = CAMERA_TO_VEHICLE_FORWARD[:3, :3] @ np.array([0.0, 0.0, 1.0])
    right = CAMERA_TO_VEHICLE_FORWARD[:3, :3] @ np.array([1.0, 0.0, 0.0])
    down = CAMERA_TO_VEHICLE_FORWARD[:3, :3] @ np.array([0.0, 1.0, 0.0])
    np.testing.assert_allclose([forward, right, down], [[1, 0, 0], [0, -1, 0], [0, 0, -1]])


def test_yaml_round_trip_and_kalibr_layout(tmp_path):
    camera = Camera(500.0, 501.0, 320.0, 240.0, 640, 480, np.array([0.1, -0.01, 0.001, 0.002, 0.0]))
    write_camera_yaml(tmp_path / "cam.yaml", camera)
    back = read_camera(tmp_path / "cam.yaml")
    np.testing.assert_allclose(back.K, camera.K)
    np.testing.assert_allclose(back.distortion, camera.distortion)
    T_cam_imu = np.eye(4)
    T_cam_imu[:3, 3] = [0.1, 0.2, 0.3]
    kalibr = {
        "cam0": {
            "intrinsics": [450.0, 451.0, 300.0, 200.0],
            "resolution": [600, 400],
            "distortion_coeffs": [0.01, 0.02, 0.0, 0.0],
            "T_cam_imu": T_cam_imu.tolist(),
        }
    }
    (tmp_path / "kalibr.yaml").write_text(yaml.safe_dump(kalibr))
    cam = read_camera(tmp_path / "kalibr.yaml")
    assert (cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height) == (450, 451, 300, 200, 600, 400)
    np.testing.assert_allclose(cam.T_vehicle_camera[:3, 3], [-0.1, -0.2, -0.3])


def test_calibration_errors_name_the_file(tmp_path):
    bad = tmp_path / "calib.txt"
    bad.write_text("P1: 1 2 3\n")
    with pytest.raises(InputError, match="no P0: row"):
        read_camera(bad)
    bad.write_text("P0: 1 2 3\n")
    with pytest.raises(InputError, match=r"calib.txt:1: P0 row has 3 values"):
        read_camera(bad)
    missing = tmp_path / "cam.yaml"
    missing.write_text("fx: 1\nfy: 2\n")
    with pytest.raises(InputError, match="lacks the key 'cx'"):
        read_camera(missing)
