"""VO heading correction (sec. 3.6, Eq. 11–13): exact synthetic cases."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tests.conftest import REPO_ROOT
from tests.helpers.correction import correct_camera
from vo_doppler.cli import main
from vo_doppler.errors import InputError
from vo_doppler.fusion.correction import CorrectionConfig, absolute_heading
from vo_doppler.fusion.heading_correction import chord_starts, headings_at
from vo_doppler.geo import wrap_angle, yaw_of
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.heading_csv import read_heading_csv, write_heading_csv
from vo_doppler.io.trajectory import read_kitti, read_tum, write_kitti, write_tum
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD as FORWARD_CAMERA_TO_VEHICLE
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.vo.frames import vehicle_trajectory

RATE_HZ = 10.0


def _ground_truth(n=200, yaw0=2.5):
    """Vehicle poses in ENU: weaving path, pitch/roll wobble that is zero at the start."""
    t = np.arange(n) / RATE_HZ
    yaw = yaw0 + 0.4 * np.sin(0.3 * t)
    pitch = 0.03 * np.sin(0.7 * t)
    roll = 0.02 * np.sin(0.5 * t)
    speed = 8.0
    step = speed / RATE_HZ
    heading_mid = np.concatenate([[yaw[0]], 0.5 * (yaw[1:] + yaw[:-1])])
    moves = step * np.stack([np.cos(heading_mid), np.sin(heading_mid), 0.01 * np.ones(n)], axis=1)
    moves[0] = 0.0
    positions = np.cumsum(moves, axis=0) + np.array([100.0, -50.0, 3.0])
    rotations = Rotation.from_euler("ZYX", np.stack([yaw, pitch, roll], axis=1))
    return t, yaw, Trajectory(t, positions, rotations)


def _vo_output(vehicle_gt: Trajectory, camera_to_vehicle=FORWARD_CAMERA_TO_VEHICLE):
    """Camera poses in the first camera frame, as a VO writes them (perfect VO)."""
    T_E_cam = vehicle_gt.matrices @ camera_to_vehicle
    return Trajectory.from_matrices(vehicle_gt.t, np.linalg.inv(T_E_cam[0]) @ T_E_cam)


def _assert_equal_poses(actual: Trajectory, expected_matrices: np.ndarray, atol=1e-9):
    np.testing.assert_allclose(actual.matrices, expected_matrices, atol=atol)


def test_absolute_heading_everywhere_recovers_the_enu_trajectory():
    t, yaw, gt = _ground_truth()
    result = correct_camera(_vo_output(gt), t, yaw)
    expected = gt.matrices.copy()
    expected[:, :3, 3] -= gt.positions[0]
    _assert_equal_poses(result.vehicle, expected)
    assert result.has_absolute.all()
    assert result.window_offset[0] == pytest.approx(-2.5)  # VO starts at yaw 0, truth at 2.5 rad
    np.testing.assert_allclose(result.window_offset[1:], 0.0, atol=1e-12)


def test_gap_holds_the_last_offset_and_rotation_is_about_the_oldest_window_pose():
    t, yaw, gt = _ground_truth()
    valid = (t >= 5.0) & (t <= 8.0)
    window_s = 2.0
    result = correct_camera(_vo_output(gt), t, yaw, valid, window_s=window_s)
    vo_level = vehicle_trajectory(_vo_output(gt)).matrices
    first_window = int(np.flatnonzero(t > 5.0 - window_s)[0])
    before = np.arange(len(t)) < first_window
    # Poses older than the first window with absolute heading stay as the VO put them.
    _assert_equal_poses(result.vehicle.subset(before), vo_level[before])
    # From that window's oldest pose on, the VO is rotated by the true start yaw about it.
    rotate = Rotation.from_euler("Z", 2.5).as_matrix()
    pivot = vo_level[first_window, :3, 3]
    expected = vo_level[~before].copy()
    expected[:, :3, 3] = pivot + (expected[:, :3, 3] - pivot) @ rotate.T
    expected[:, :3, :3] = rotate @ expected[:, :3, :3]
    _assert_equal_poses(result.vehicle.subset(~before), expected)
    after = t > 8.0
    assert not result.has_absolute[after].any()
    np.testing.assert_allclose(result.correction[after], 2.5, atol=1e-12)
    np.testing.assert_allclose(
        wrap_angle(yaw_of(result.vehicle.matrices[after][:, :3, :3]) - yaw[after]), 0.0, atol=1e-9
    )


def test_pitch_and_roll_are_untouched_and_drift_is_removed():
    t, yaw, gt = _ground_truth()
    drift = 0.02 * t  # VO heading error growing 0.02 rad/s: rotate each step by the error
    vo = _vo_output(gt)
    level = vehicle_trajectory(vo).matrices
    steps = np.diff(level[:, :3, 3], axis=0)
    turn = Rotation.from_euler("Z", drift[:, None]).as_matrix()
    positions = np.concatenate(
        [
            [level[0, :3, 3]],
            level[0, :3, 3] + np.cumsum(np.einsum("nij,nj->ni", turn[1:], steps), axis=0),
        ]
    )
    drifted_vehicle = Trajectory(t, positions, Rotation.from_matrix(turn @ level[:, :3, :3]))
    drifted_camera = Trajectory.from_matrices(
        t, drifted_vehicle.matrices @ FORWARD_CAMERA_TO_VEHICLE
    )
    every_second = np.arange(len(t)) % 10 == 0  # 1 Hz absolute heading
    result = correct_camera(drifted_camera, t[every_second], yaw[every_second], window_s=2.0)
    euler_out = Rotation.from_matrix(result.vehicle.matrices[:, :3, :3]).as_euler("ZYX")
    euler_in = drifted_vehicle.orientations.as_euler("ZYX")
    np.testing.assert_allclose(euler_out[:, 1:], euler_in[:, 1:], atol=1e-12)
    heading_error = np.abs(wrap_angle(euler_out[:, 0] - yaw))
    uncorrected = np.abs(wrap_angle(euler_in[:, 0] + 2.5 - yaw))
    # Eq. (11) averages over the 2 s window and the heading arrives at 1 Hz: the corrected
    # error stays within the drift accumulated over window + sample interval (0.06 rad).
    assert heading_error.max() < 0.02 * 3.0 < 0.3 < uncorrected.max()
    truth_end = gt.positions[-1] - gt.positions[0]
    end_error = np.linalg.norm(result.vehicle.positions[-1] - truth_end)
    start_yaw_only = Rotation.from_euler("Z", 2.5).apply(positions[-1])
    assert end_error < 0.02 * gt.path_length
    assert end_error < np.linalg.norm(start_yaw_only - truth_end) / 5


def test_circular_mean_across_the_wrap():
    t = np.arange(10) / RATE_HZ
    east = Trajectory(t, np.stack([t, 0 * t, 0 * t], axis=1), Rotation.identity(len(t)))
    absolute = np.where(np.arange(10) % 2 == 0, np.radians(179.0), np.radians(-179.0))
    result = correct_camera(
        east, t, absolute, camera_to_vehicle=np.eye(4), world="level", window_s=5.0
    )
    final_yaw = yaw_of(result.vehicle.matrices[:, :3, :3])[-1]
    assert abs(wrap_angle(final_yaw - np.pi)) < np.radians(1.01)


def test_camera_extrinsic_is_honoured():
    t, yaw, gt = _ground_truth(n=60)
    mount = np.eye(4)
    mount[:3, :3] = Rotation.from_euler("Z", 0.2).as_matrix() @ FORWARD_CAMERA_TO_VEHICLE[:3, :3]
    mount[:3, 3] = [1.5, 0.3, 1.2]
    result = correct_camera(_vo_output(gt, mount), t, yaw, camera_to_vehicle=mount)
    expected = gt.matrices.copy()
    expected[:, :3, 3] -= gt.positions[0]
    _assert_equal_poses(result.vehicle, expected)
    expected_camera = expected @ mount
    _assert_equal_poses(result.camera, expected_camera)


def test_headings_at_interpolates_on_the_short_arc_and_respects_gaps():
    t_h = np.array([0.0, 1.0, 2.0, 5.0])
    yaw = np.radians([170.0, -170.0, -160.0, 0.0])
    valid = np.array([True, True, True, True])
    out, ok = headings_at(np.array([0.5, 1.0, 3.0, -1.0, 5.0]), t_h, yaw, valid, max_gap_s=1.5)
    assert ok.tolist() == [True, True, False, False, True]
    np.testing.assert_allclose(np.degrees(out[[0, 1, 4]]), [-180.0, -170.0, 0.0], atol=1e-9)
    out, ok = headings_at(np.array([1.0]), t_h, yaw, np.array([True, False, True, True]), 1.5)
    assert not ok[0]


def _table(t, yaw, reliable, conv_valid):
    n = len(t)
    return HeadingTable(
        t=t,
        yaw_tc=np.where(reliable, yaw, np.nan),
        sigma_tc=np.full(n, 0.01),
        tc_reliable=reliable,
        n_obs_window=np.full(n, 12),
        n_sat_epoch=np.full(n, 2),
        yaw_conv=np.where(conv_valid, yaw + 0.5, np.nan),  # deliberately off: must not be used
        conv_valid=conv_valid,
        gyro_bias=np.full(n, 0.001),
        wheel_scale=np.full(n, 1.01),
    )


def test_heading_csv_round_trip(tmp_path):
    t = np.arange(5.0) + 1e9
    yaw = np.radians([10.0, -170.0, 90.0, 179.0, -90.0])
    table = _table(t, yaw, np.array([True, True, False, True, True]), np.array([True] * 5))
    path = tmp_path / "heading.csv"
    write_heading_csv(path, table)
    header = path.read_text().splitlines()[0]
    assert header.startswith("gps_time_s,heading_tc_deg,heading_tc_sigma_deg,tc_reliable")
    back = read_heading_csv(path)
    ok = table.tc_available
    np.testing.assert_allclose(wrap_angle(back.yaw_tc[ok] - yaw[ok]), 0.0, atol=1e-6)
    assert np.isnan(back.yaw_tc[2]) and back.tc_reliable.tolist() == table.tc_reliable.tolist()
    np.testing.assert_allclose(back.gyro_bias, 0.001, atol=1e-7)
    first_course = float(path.read_text().splitlines()[1].split(",")[1])
    assert first_course == pytest.approx(80.0)  # yaw 10° ccw from east = course 80°
    combined = absolute_heading(back, "tc+conv", CorrectionConfig(tc_max_sigma_rad=np.inf))
    assert combined.valid.all() and combined.yaw[2] == pytest.approx(back.yaw_conv[2])
    path.write_text(path.read_text() + "1,2,3\n")
    with pytest.raises(InputError, match=r"heading.csv:7"):
        read_heading_csv(path)


def test_correct_cli_recovers_the_enu_trajectory(tmp_path):
    t, yaw, gt = _ground_truth(n=80)
    gps_offset = 1.4e9
    write_tum(tmp_path / "vo.tum", _vo_output(gt))
    table = _table(t + gps_offset, yaw, np.ones(len(t), bool), np.ones(len(t), bool))
    write_heading_csv(tmp_path / "heading.csv", table)
    out = tmp_path / "out" / "corrected.tum"
    code = main(
        [
            "correct",
            str(tmp_path / "vo.tum"),
            "--heading",
            str(tmp_path / "heading.csv"),
            "--time-offset",
            str(gps_offset),
            "--source",
            "tc",
            "-o",
            str(out),
        ]
    )
    assert code == 0
    corrected = read_tum(out)
    expected = gt.positions - gt.positions[0]
    # Headings are rounded to 1e-4° in the CSV: 2e-6 rad over 80 m.
    np.testing.assert_allclose(corrected.positions, expected, atol=1e-3)
    assert (
        main(
            [
                "correct",
                str(tmp_path / "vo.tum"),
                "--heading",
                str(tmp_path / "heading.csv"),
                "-o",
                str(out),
            ]
        )
        == 1
    )  # no --time-offset: times do not overlap


def test_correct_cli_without_a_usable_heading_writes_nothing_and_says_so(tmp_path, capsys):
    """Headings that exist but none usable (here unreliable) left the trajectory as it was,
    exit 0 and a correction of 0°: a silently uncorrected 'corrected' file."""
    t, yaw, gt = _ground_truth(n=80)
    gps_offset = 1.4e9
    write_tum(tmp_path / "vo.tum", _vo_output(gt))
    none = np.zeros(len(t), bool)
    write_heading_csv(tmp_path / "heading.csv", _table(t + gps_offset, yaw, none, none))
    out = tmp_path / "corrected.tum"
    argv = ["correct", str(tmp_path / "vo.tum"), "--heading", str(tmp_path / "heading.csv")]
    code = main([*argv, "--time-offset", str(gps_offset), "--source", "tc", "-o", str(out)])
    assert code == 1
    assert "no usable tc heading within the trajectory's times" in capsys.readouterr().err
    assert not out.exists()


def test_correct_cli_reads_the_extrinsic_and_writes_kitti(tmp_path):
    calib = REPO_ROOT / "calib" / "synthetic.yaml"
    mount = read_camera(calib).T_vehicle_camera
    t, yaw, gt = _ground_truth(n=40)
    write_kitti(tmp_path / "vo.txt", _vo_output(gt, mount))
    np.savetxt(tmp_path / "times.txt", t)
    write_heading_csv(
        tmp_path / "h.csv", _table(t, yaw, np.ones(len(t), bool), np.ones(len(t), bool))
    )
    out = tmp_path / "corrected.kitti"
    args = [
        "correct",
        str(tmp_path / "vo.txt"),
        "--format",
        "kitti",
        "--times",
        str(tmp_path / "times.txt"),
        "--heading",
        str(tmp_path / "h.csv"),
        "--calib",
        str(calib),
        "--body",
        "camera",
        "-o",
        str(out),
    ]
    assert main(args) == 0
    corrected = read_kitti(out)
    expected = gt.matrices.copy()
    expected[:, :3, 3] -= gt.positions[0]
    np.testing.assert_allclose(corrected.matrices, expected @ mount, atol=1e-3)


@settings(max_examples=25, deadline=None)
@given(offset=st.floats(-np.pi, np.pi), yaw0=st.floats(-np.pi, np.pi))
def test_any_constant_offset_is_removed_exactly(offset, yaw0):
    t, yaw, gt = _ground_truth(n=30, yaw0=yaw0)
    vo = _vo_output(gt)
    level = vehicle_trajectory(vo).matrices
    turned = Rotation.from_euler("z", offset).as_matrix()
    rotated = level.copy()
    rotated[:, :3, :3] = turned @ level[:, :3, :3]
    rotated[:, :3, 3] = level[:, :3, 3] @ turned.T
    result = correct_camera(
        Trajectory.from_matrices(t, rotated), t, yaw, camera_to_vehicle=np.eye(4), world="level"
    )
    expected = gt.matrices.copy()
    expected[:, :3, 3] -= gt.positions[0]
    np.testing.assert_allclose(result.vehicle.matrices, expected, atol=1e-9)


def test_innovation_gate_ignores_an_outlier_burst_once_established():
    t, yaw, gt = _ground_truth()
    corrupted = yaw.copy()
    burst = (t > 8.0) & (t < 9.0)
    corrupted[burst] += np.radians(40.0)
    expected = gt.matrices.copy()
    expected[:, :3, 3] -= gt.positions[0]
    gated = correct_camera(_vo_output(gt), t, corrupted, gate_rad=np.radians(10.0))
    _assert_equal_poses(gated.vehicle, expected, atol=1e-9)
    ungated = correct_camera(_vo_output(gt), t, corrupted)
    assert np.max(np.abs(wrap_angle(yaw_of(ungated.vehicle.matrices[:, :3, :3]) - yaw))) > 0.1


def test_course_reference_is_immune_to_an_extrinsic_yaw_error():
    t, yaw, gt = _ground_truth()
    skewed = FORWARD_CAMERA_TO_VEHICLE.copy()
    skewed[:3, :3] = Rotation.from_euler("z", 2.0, degrees=True).as_matrix() @ skewed[:3, :3]
    vo = _vo_output(gt, skewed)
    expected = gt.positions - gt.positions[0]
    by_course = correct_camera(vo, t, yaw, reference="course")
    np.testing.assert_allclose(by_course.vehicle.positions, expected, atol=1e-9)
    by_orientation = correct_camera(vo, t, yaw, reference="orientation")
    error = np.linalg.norm(by_orientation.vehicle.positions - expected, axis=1)
    assert error.max() > 1.0
    with pytest.raises(
        ValueError, match=r"^reference: unknown heading reference 'sideways'; choose from course"
    ):
        correct_camera(vo, t, yaw, reference="sideways")


def test_chord_starts_group_short_steps_until_the_chord_is_long_enough():
    x = np.array([0.0, 0.6, 0.7, 0.8, 0.9, 1.6, 1.6, 3.0])
    positions = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    np.testing.assert_array_equal(chord_starts(positions, 0.5), [-1, 0, 0, 0, 0, 4, 4, 6])


@settings(max_examples=30, deadline=None)
@given(st.floats(5.0, 200.0), st.floats(0.5, 20.0), st.floats(0.5, 3.0))
def test_chord_course_is_the_tangent_at_the_chord_middle_on_an_arc(radius, speed, chord_m):
    t = np.arange(0.0, 20.0, 0.05)
    angle = speed * t / radius
    positions = np.column_stack([radius * np.sin(angle), radius * (1 - np.cos(angle)), 0 * t])
    start = chord_starts(positions, chord_m)
    has = np.flatnonzero(start >= 0)
    chord = positions[has, :2] - positions[start[has], :2]
    middle = 0.5 * (t[has] + t[start[has]])
    np.testing.assert_allclose(
        wrap_angle(np.arctan2(chord[:, 1], chord[:, 0]) - speed * middle / radius), 0.0, atol=1e-9
    )


def test_creeping_steps_at_a_stop_do_not_turn_the_course_corrected_trajectory():
    """Stopped, a VO's position only jitters: two 6 cm steps 60° off the way the vehicle
    faces are then the only courses in the window. Compared one by one with the absolute
    heading they turned the corrected trajectory by 60°; the 0.5 m chord leaves them out."""
    step = np.r_[np.full(40, 1.0), np.zeros(20), np.full(40, 1.0)]
    direction = np.zeros(len(step))
    step[[45, 52]] = 0.06
    direction[[45, 52]] = np.radians([60.0, -120.0])
    positions = np.zeros((len(step) + 1, 3))
    positions[1:, 0] = np.cumsum(step * np.cos(direction))
    positions[1:, 1] = np.cumsum(step * np.sin(direction))
    t = np.arange(len(positions)) / RATE_HZ
    vo = Trajectory(t, positions, Rotation.identity(len(t)))
    worst = {}
    for chord in (0.05, 0.5):
        result = correct_camera(
            vo,
            t,
            np.zeros(len(t)),
            None,
            2.0,
            camera_to_vehicle=np.eye(4),
            world="level",
            reference="course",
            min_chord_m=chord,
        )
        yaw = yaw_of(result.vehicle.orientations.as_matrix())
        worst[chord] = np.degrees(np.max(np.abs(wrap_angle(yaw))))
    assert worst[0.5] < 2.0  # a chord leaving the stop still carries a creep's 5 cm offset
    assert worst[0.05] > 50.0
