"""``import_kitti_raw`` on a fake drive written here with known values, and on the
kitti_raw_mini fixture (a subsampled drive: 10 of 108 images, 5 of 108 OXTS rows)."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pymap3d
import pytest
import yaml

from tests.conftest import require_shared
from vo_doppler.errors import InputError
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.kitti_oxts import OXTS_FIELDS, read_oxts
from vo_doppler.io.kitti_raw_import import import_kitti_raw
from vo_doppler.io.sequence import read_sequence
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD

MINI = "kitti_raw_mini/2011_09_26/2011_09_26_drive_0001_sync"
LAT0, LON0, ALT0 = 49.0, 8.4, 110.0
P_RECT_00 = "700.0 0.0 600.0 0.0 0.0 710.0 180.0 0.0 0.0 0.0 1.0 0.0"
P_RECT_02 = "700.0 0.0 600.0 42.0 0.0 710.0 180.0 0.0 0.0 0.0 1.0 0.0"


def _stamp(k: int) -> str:
    """Frame k at 10 Hz from 2011-09-26 13:02:25.5 UTC."""
    nanos = 500_000_000 + k * 100_000_000
    return f"2011-09-26 13:02:{25 + nanos // 10**9:02d}.{nanos % 10**9:09d}"


def _fake_drive(root: Path, n: int = 20, images=range(20), oxts=range(20), extrinsic=True):
    """A ``_sync`` drive driving north-east at 10 m/s with a yaw rate of 0.05 rad/s: the OXTS
    fix of frame k at ENU (7.07·t, 7.07·t, 0) from (LAT0, LON0, ALT0), t = 0.1·k."""
    drive = root / "2011_09_26" / "2011_09_26_drive_0042_sync"
    (drive / "image_00" / "data").mkdir(parents=True)
    (drive / "oxts" / "data").mkdir(parents=True)
    stamps = "\n".join(_stamp(k) for k in range(n)) + "\n"
    (drive / "image_00" / "timestamps.txt").write_text(stamps)
    (drive / "oxts" / "timestamps.txt").write_text(stamps)
    for k in images:
        (drive / "image_00" / "data" / f"{k:010d}.png").write_bytes(b"png %d" % k)
    for k in oxts:
        t = 0.1 * k
        lat, lon, alt = pymap3d.enu2geodetic(7.07 * t, 7.07 * t, 0.0, LAT0, LON0, ALT0)
        values = dict.fromkeys(OXTS_FIELDS, 0.0)
        values.update(lat=lat, lon=lon, alt=alt, yaw=np.pi / 4, vf=10.0 + 0.01 * k, wz=0.05)
        line = " ".join(repr(float(values[name])) for name in OXTS_FIELDS)
        (drive / "oxts" / "data" / f"{k:010d}.txt").write_text(line + "\n")
    day = drive.parent
    (day / "calib_cam_to_cam.txt").write_text(
        "calib_time: 09-Jan-2012 13:57:47\n"
        "S_rect_00: 1.242000e+03 3.750000e+02\n"
        "R_rect_00: 1 0 0 0 1 0 0 0 1\n"
        f"P_rect_00: {P_RECT_00}\n"
        "S_rect_02: 1.242000e+03 3.750000e+02\n"
        f"P_rect_02: {P_RECT_02}\n"
    )
    if extrinsic:
        # OXTS unit 1 m behind and 0.5 m below the velodyne; camera 0 with OpenCV axes at the
        # velodyne, 0.25 m ahead of it
        (day / "calib_imu_to_velo.txt").write_text("R: 1 0 0 0 1 0 0 0 1\nT: -1.0 0.0 -0.5\n")
        (day / "calib_velo_to_cam.txt").write_text("R: 0 -1 0 0 0 -1 1 0 0\nT: 0.0 0.0 -0.25\n")
    return drive


def test_fake_drive_gives_exact_times_signals_truth_and_camera(tmp_path):
    drive = _fake_drive(tmp_path)
    summary = import_kitti_raw(drive, tmp_path / "seq")
    assert (summary.images, summary.oxts_rows, summary.warnings) == (20, 20, ())
    sequence = read_sequence(tmp_path / "seq")
    assert sequence.observations is None and not sequence.has_gnss
    # 2011-09-26 13:02:25.5 UTC = GPS 1001077360.5 (+15 leap seconds), frames 0.1 s apart
    expected_t = 1001077360.5 + 0.1 * np.arange(20)
    np.testing.assert_allclose(sequence.image_times, expected_t, atol=1e-6)
    np.testing.assert_allclose(sequence.yaw_rate.t, expected_t, atol=1e-6)
    np.testing.assert_allclose(sequence.yaw_rate.value, 0.05, rtol=1e-15)
    np.testing.assert_allclose(sequence.wheel_speed.value, 10.0 + 0.01 * np.arange(20))
    assert np.degrees(sequence.enu.lat_rad) == pytest.approx(LAT0, abs=1e-12)
    assert np.degrees(sequence.enu.lon_rad) == pytest.approx(LON0, abs=1e-12)
    truth = sequence.truth
    elapsed = 0.1 * np.arange(20)
    np.testing.assert_allclose(truth.positions[:, 0], 7.07 * elapsed, atol=1e-6)
    np.testing.assert_allclose(truth.positions[:, 1], 7.07 * elapsed, atol=1e-6)
    np.testing.assert_allclose(truth.positions[:, 2], 0.0, atol=1e-6)
    np.testing.assert_allclose(truth.yaw(), np.pi / 4, atol=1e-5)  # + convergence < 2e-6
    camera = sequence.camera
    assert (camera.fx, camera.fy, camera.cx, camera.cy) == (700.0, 710.0, 600.0, 180.0)
    assert (camera.width, camera.height) == (1242, 375)
    assert not camera.has_distortion
    # camera 0.25 m ahead of the velodyne, which is 1 m ahead of and 0.5 m above the OXTS
    # unit; its optical axis along the vehicle's x
    np.testing.assert_allclose(camera.T_vehicle_camera[:3, 3], [1.25, 0.0, 0.5], atol=1e-12)
    np.testing.assert_allclose(
        camera.T_vehicle_camera[:3, :3], CAMERA_TO_VEHICLE_FORWARD[:3, :3], atol=1e-12
    )
    assert [p.name for p in sequence.image_paths] == [f"{k:010d}.png" for k in range(20)]
    assert sequence.image_paths[7].read_bytes() == b"png 7"


def test_colour_camera_takes_its_own_row_and_baseline(tmp_path):
    drive = _fake_drive(tmp_path)
    with pytest.raises(InputError, match=r"drive_0042_sync: no image_02 folder in the drive"):
        import_kitti_raw(drive, tmp_path / "seq", camera="image_02")
    shutil.copytree(drive / "image_00", drive / "image_02")
    import_kitti_raw(drive, tmp_path / "seq", camera="image_02")
    camera = read_camera(tmp_path / "seq" / "calib.yaml")
    assert camera.fx == 700.0
    # P_rect_02 = K [I | t]: t = K⁻¹ P[:, 3] = (0.06, 0, 0) in the rectified camera frame,
    # i.e. camera 2 sits 0.06 m to the right of camera 0's (x_rect_2 = x_rect_0 + 0.06)
    np.testing.assert_allclose(camera.T_vehicle_camera[:3, 3], [1.25, 0.06, 0.5], atol=1e-12)
    manifest = yaml.safe_load((tmp_path / "seq" / "sequence.yaml").read_text())
    assert manifest["camera"]["images"] == "image_02"
    assert "P_rect_02" in manifest["kitti"]["intrinsics_from"]


def test_subsampled_drive_keeps_the_frames_that_exist_and_says_so(tmp_path):
    drive = _fake_drive(tmp_path, images=[0, 1, 2, 9, 15], oxts=[0, 1, 2, 3])
    summary = import_kitti_raw(drive, tmp_path / "seq")
    assert (summary.images, summary.image_timestamps) == (5, 20)
    assert (summary.oxts_rows, summary.oxts_timestamps) == (4, 20)
    assert len(summary.warnings) == 2
    assert "5 data files for the 20 timestamps" in summary.warnings[0]
    assert "4 data files for the 20 timestamps" in summary.warnings[1]
    sequence = read_sequence(tmp_path / "seq")
    np.testing.assert_allclose(
        sequence.image_times, 1001077360.5 + 0.1 * np.array([0, 1, 2, 9, 15]), atol=1e-6
    )
    manifest = yaml.safe_load((tmp_path / "seq" / "sequence.yaml").read_text())
    assert manifest["kitti"]["warnings"] == list(summary.warnings)


def test_without_the_imu_and_velodyne_calibration_the_camera_looks_forward(tmp_path):
    drive = _fake_drive(tmp_path, extrinsic=False)
    summary = import_kitti_raw(drive, tmp_path / "seq")
    assert summary.extrinsic_from.startswith("assumed")
    camera = read_camera(tmp_path / "seq" / "calib.yaml")
    np.testing.assert_array_equal(camera.T_vehicle_camera, CAMERA_TO_VEHICLE_FORWARD)


def test_bad_calibration_names_the_file_and_line(tmp_path):
    drive = _fake_drive(tmp_path)
    calib = drive.parent / "calib_cam_to_cam.txt"
    text = calib.read_text()
    calib.write_text(text.replace(f"P_rect_00: {P_RECT_00}", "P_rect_00: 700 0 600 x"))
    with pytest.raises(InputError, match=r"calib_cam_to_cam.txt:4: P_rect_00 has a value"):
        import_kitti_raw(drive, tmp_path / "seq")
    calib.write_text(text.replace(f"P_rect_00: {P_RECT_00}", "P_rect_00: 700 0 600"))
    with pytest.raises(InputError, match=r"calib_cam_to_cam.txt:4: P_rect_00 has 3 values"):
        import_kitti_raw(drive, tmp_path / "seq")
    calib.write_text(text.replace("S_rect_00", "just words\nS_rect_00"))
    with pytest.raises(InputError, match=r"calib_cam_to_cam.txt:2: not a 'NAME: values' row"):
        import_kitti_raw(drive, tmp_path / "seq")
    calib.write_text(text.replace(f"P_rect_00: {P_RECT_00}\n", ""))
    with pytest.raises(InputError, match=r"calib_cam_to_cam.txt: no P_rect_00: row"):
        import_kitti_raw(drive, tmp_path / "seq")
    calib.unlink()
    with pytest.raises(InputError, match=r"no calib_cam_to_cam.txt beside the drive"):
        import_kitti_raw(drive, tmp_path / "seq")
    assert not (tmp_path / "seq").exists()  # nothing written before every input was read


def test_a_singular_projection_matrix_is_an_error_naming_its_line(tmp_path):
    """Found by the fuzz (kitti-raw case 634): a P_rect whose 1 in K became 0 crashed the
    camera offset's solve with a LinAlgError (exit 3)."""
    drive = _fake_drive(tmp_path)
    calib = drive.parent / "calib_cam_to_cam.txt"
    singular = P_RECT_00.replace("0.0 0.0 1.0 0.0", "0.0 0.0 0.0 0.0")
    calib.write_text(calib.read_text().replace(f"P_rect_00: {P_RECT_00}", f"P_rect_00: {singular}"))
    with pytest.raises(InputError, match=r"calib_cam_to_cam.txt:4: P_rect_00's left 3×3 part"):
        import_kitti_raw(drive, tmp_path / "seq")
    assert not (tmp_path / "seq").exists()


def test_bad_oxts_or_image_names_stop_the_import_before_writing(tmp_path):
    drive = _fake_drive(tmp_path)
    (drive / "oxts" / "data" / "0000000003.txt").write_text("1 2 3\n")
    with pytest.raises(InputError, match=r"0000000003.txt:1: 3 numbers, expected 30"):
        import_kitti_raw(drive, tmp_path / "seq")
    assert not (tmp_path / "seq").exists()
    drive = _fake_drive(tmp_path / "b")
    (drive / "image_00" / "data" / "0000000020.png").write_bytes(b"x")
    with pytest.raises(InputError, match=r"0000000020.png: frame 20 has no timestamp"):
        import_kitti_raw(drive, tmp_path / "seq")
    with pytest.raises(
        InputError, match=r"^camera: unknown kitti camera 'image_9'; choose from image_00, image_01"
    ):
        import_kitti_raw(drive, tmp_path / "seq", camera="image_9")


@pytest.mark.shared_data
def test_kitti_raw_mini_truth_is_the_oxts_fixes_and_the_yaw_rate_oxts_wz(tmp_path):
    drive = require_shared(MINI)
    summary = import_kitti_raw(drive, tmp_path / "seq")
    assert (summary.images, summary.image_timestamps) == (10, 108)
    assert (summary.oxts_rows, summary.oxts_timestamps) == (5, 108)
    sequence = read_sequence(tmp_path / "seq")
    oxts = read_oxts(drive / "oxts")
    # the ground truth back to geodetic through pymap3d, against the fixes as written
    lat, lon, alt = pymap3d.enu2geodetic(
        *sequence.truth.positions.T,
        np.degrees(sequence.enu.lat_rad),
        np.degrees(sequence.enu.lon_rad),
        sequence.enu.height_m,
    )
    north = np.radians(lat - oxts.fields["lat"]) * 6.37e6
    east = np.radians(lon - oxts.fields["lon"]) * 6.37e6 * np.cos(np.radians(lat))
    assert np.max(np.hypot(north, east)) < 0.01
    assert np.max(np.abs(alt - oxts.fields["alt"])) < 0.01
    assert sequence.truth.path_length == pytest.approx(5.4, abs=0.3)  # 0.42 s at 13 m/s
    np.testing.assert_allclose(sequence.yaw_rate.value, oxts.fields["wz"], rtol=1e-15)
    np.testing.assert_allclose(sequence.wheel_speed.value, oxts.fields["vf"], rtol=1e-15)
    np.testing.assert_allclose(sequence.yaw_rate.t, oxts.t, atol=1e-6)
    np.testing.assert_allclose(sequence.truth.t, oxts.t, atol=1e-6)
    # OXTS yaw −2.6087 rad (about west-south-west), as the truth's
    assert sequence.truth.yaw()[0] == pytest.approx(oxts.fields["yaw"][0], abs=1e-9)
    assert [p.stem for p in sequence.image_paths] == [
        f"{k:010d}" for k in (0, 1, 2, 3, 4, 5, 25, 45, 65, 85)
    ]
    assert sequence.camera.fx == pytest.approx(721.5377)
    assert (sequence.camera.width, sequence.camera.height) == (1242, 375)
    # camera 0 1.08 m ahead of the OXTS unit, 0.31 m to its right and 0.73 m above it
    np.testing.assert_allclose(
        sequence.camera.T_vehicle_camera[:3, 3], [1.083, -0.310, 0.730], atol=1e-3
    )
