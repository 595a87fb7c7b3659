"""``vo-doppler correct``: --times only with a KITTI trajectory (a usage error otherwise, before
any work), and a warning when the trajectory's world is probably not the --world given."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.helpers.heading_table import plain_heading_table
from tests.helpers.level_track import level_turn
from vo_doppler import run as run_module
from vo_doppler.cli import main
from vo_doppler.commands import correct_command
from vo_doppler.fusion.placement import initial_yaw_offset, turned_about_start
from vo_doppler.geo import wrap_angle
from vo_doppler.io.heading_csv import write_heading_csv
from vo_doppler.io.trajectory import read_tum, write_kitti, write_tum
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.vo.frames import camera_trajectory


@pytest.fixture
def drive(tmp_path):
    """A level track (vehicle poses, ENU: 60 m east, a left turn, 40 m north) with a heading
    table whose headings are the track's, on the track's clock."""
    track = level_turn()
    write_tum(tmp_path / "track.tum", track)
    write_kitti(tmp_path / "track.kitti", track)
    np.savetxt(tmp_path / "times.txt", track.t)
    t = np.arange(0.0, track.t[-1] + 0.05, 0.2)
    yaw = np.interp(t, track.t, np.unwrap(track.yaw()))
    write_heading_csv(tmp_path / "heading.csv", plain_heading_table(t, yaw_tc=yaw, yaw_conv=yaw))
    return tmp_path


@pytest.mark.parametrize(
    ("format_options", "given"),
    [([], "track.tum is TUM"), (["--format", "tum"], "--format tum")],
)
def test_times_with_a_tum_trajectory_is_exit_2(drive, format_options, given, capsys):
    argv = ["correct", str(drive / "track.tum"), "--heading", str(drive / "heading.csv")]
    argv += ["--times", str(drive / "times.txt"), *format_options, "-o", str(drive / "c.tum")]
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "--times applies to a KITTI trajectory only" in err and given in err
    assert not (drive / "c.tum").exists()


def test_times_with_a_kitti_trajectory_are_its_times(drive, capsys):
    argv = ["correct", str(drive / "track.kitti"), "--heading", str(drive / "heading.csv")]
    argv += ["--times", str(drive / "times.txt"), "--world", "level", "-o", str(drive / "c.tum")]
    assert main(argv) == 0
    np.testing.assert_allclose(read_tum(drive / "c.tum").t, level_turn().t, atol=1e-9)


@pytest.mark.parametrize(("world", "warned"), [("first_camera", True), ("level", False)])
def test_a_level_track_read_as_first_camera_is_warned_and_kept(
    drive, world, warned, capsys, caplog
):
    argv = ["correct", str(drive / "track.tum"), "--heading", str(drive / "heading.csv")]
    argv += ["--world", world, "-o", str(drive / "c.tum")]
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    if warned:
        [warning] = summary["warnings"]
        assert warning.startswith("with --world first_camera the vehicle climbs or falls")
        assert "along 38% of its path" in warning and "give --world level" in warning
        assert warning in caplog.text
        assert abs(summary["final_correction_deg"]) > 45.0  # what the warning explains
    else:
        assert summary["warnings"] == []
        assert abs(summary["final_correction_deg"]) < 0.1


@pytest.mark.parametrize(
    ("correction", "metres", "degrees"), [("window", 1e-6, 1e-6), ("kalman", 0.02, 0.06)]
)
def test_poses_before_the_first_absolute_heading_start_with_it(
    tmp_path, correction, metres, degrees, capsys
):
    """Issue 30: the window method left the poses before the first absolute heading in the
    VO's own frame (a drive starting east instead of north). `correct` now starts the
    trajectory as `run` does (:func:`vo_doppler.fusion.placement.initial_yaw_offset`): the
    VO below (camera poses in a level world), the level track turned 0.7 rad clockwise, with
    headings from 2 s on only, starts as the track (the window method exactly, the Kalman blend
    within its smoothing of the corner) and ends heading as it does."""
    track = level_turn()
    vo = turned_about_start(track, -0.7)
    write_tum(tmp_path / "vo.tum", camera_trajectory(vo, CAMERA_TO_VEHICLE_FORWARD))
    t = np.arange(0.0, track.t[-1] + 0.05, 0.2)
    yaw = np.interp(t, track.t, np.unwrap(track.yaw()))
    yaw[t < 2.0] = np.nan
    table = plain_heading_table(t, yaw_tc=yaw, yaw_conv=yaw, conv_valid=np.isfinite(yaw))
    write_heading_csv(tmp_path / "heading.csv", table)
    argv = ["correct", str(tmp_path / "vo.tum"), "--heading", str(tmp_path / "heading.csv")]
    argv += ["--world", "level", "--correction", correction, "-o", str(tmp_path / "c.tum")]
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["initial_turn_deg"] == pytest.approx(np.degrees(0.7), abs=1e-6)
    assert summary["final_correction_deg"] == pytest.approx(np.degrees(0.7), abs=degrees)
    corrected = read_tum(tmp_path / "c.tum")
    before = track.t < 2.0
    np.testing.assert_allclose(corrected.positions[before], track.positions[before], atol=metres)
    yaw_error = np.degrees(wrap_angle(corrected.yaw() - track.yaw()))
    np.testing.assert_allclose(yaw_error[before], 0.0, atol=degrees)
    assert abs(yaw_error[-1]) < degrees


def test_correct_and_run_start_a_trajectory_by_one_rule():
    """`run` imports the same function (no second copy to drift apart)."""
    assert run_module.initial_yaw_offset is initial_yaw_offset
    assert correct_command.initial_yaw_offset is initial_yaw_offset


@pytest.fixture
def kitti_drive(tmp_path):
    """80 s of a straight drive east, 801 camera poses at 10 Hz as KITTI (no times) with its
    times.txt, and 10-Hz headings on the same image clock (0..80 s)."""
    t = 0.1 * np.arange(801)
    track = Trajectory(t, np.column_stack([t * 10.0, 0 * t, 0 * t]), Rotation.identity(len(t)))
    write_kitti(tmp_path / "vo.kitti", camera_trajectory(track, CAMERA_TO_VEHICLE_FORWARD))
    np.savetxt(tmp_path / "times.txt", t)
    write_heading_csv(tmp_path / "heading.csv", plain_heading_table(t))
    return tmp_path


def test_a_kitti_trajectory_without_its_times_is_refused_naming_times(kitti_drive, capsys):
    """Issue 30: its frame numbers 0..800 overlap the headings' 0..80 s; it exited 0 with a
    tenth of the poses corrected. Now exit 1 naming --times, and nothing written."""
    argv = ["correct", str(kitti_drive / "vo.kitti"), "--heading", str(kitti_drive / "heading.csv")]
    assert main([*argv, "-o", str(kitti_drive / "c.tum")]) == 1
    err = capsys.readouterr().err
    assert "meet over 10% of the trajectory" in err and "they are frame numbers" in err
    assert "pass --times with the images' times.txt" in err and "vo.kitti" in err
    assert not (kitti_drive / "c.tum").exists()
    argv += ["--times", str(kitti_drive / "times.txt"), "-o", str(kitti_drive / "c.tum")]
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["poses_with_absolute_heading"] == 801
    assert summary["warnings"] == []


def test_headings_covering_part_of_the_trajectory_are_warned(kitti_drive, capsys, caplog):
    times = kitti_drive / "times.txt"
    argv = ["correct", str(kitti_drive / "vo.kitti"), "--heading", str(kitti_drive / "heading.csv")]
    argv += ["--times", str(times), "--time-offset", "56", "-o", str(kitti_drive / "c.tum")]
    assert main(argv) == 0
    [warning] = json.loads(capsys.readouterr().out.strip().splitlines()[-1])["warnings"]
    assert "meet over 30% of the trajectory only" in warning and "--time-offset" in warning
    assert warning in caplog.text
