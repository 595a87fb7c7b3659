"""``vo-doppler correct``: --times only with a KITTI trajectory (a usage error otherwise, before
any work), and a warning when the trajectory's world is probably not the --world given."""

from __future__ import annotations

import json
import logging

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.helpers.heading_table import plain_heading_table
from tests.helpers.level_track import level_turn
from vo_doppler.cli import main
from vo_doppler.commands import correct_command
from vo_doppler.fusion import pipelines
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


def test_the_summary_is_printed_once(drive, capsys, caplog):
    """Issue 30: correct printed its JSON twice (logged at INFO, the default level, and
    printed)."""
    caplog.set_level(logging.INFO)
    argv = ["correct", str(drive / "track.tum"), "--heading", str(drive / "heading.csv")]
    assert main([*argv, "--world", "level", "-o", str(drive / "c.tum")]) == 0
    captured = capsys.readouterr()
    said = captured.out + captured.err + caplog.text
    assert said.count('"poses_with_absolute_heading"') == 1
    [line] = captured.out.strip().splitlines()
    assert json.loads(line)["poses"] == len(level_turn())


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
    """`run`'s trajectories (`fusion.pipelines.correct_all`) start by the same function (no
    second copy to drift apart)."""
    assert pipelines.initial_yaw_offset is initial_yaw_offset
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


def _own_headings(t: np.ndarray, yaw: np.ndarray, seed: int = 3):
    """Course (deg, 4 decimals as heading.csv writes it), σ (deg) and validity of a heading
    from elsewhere: 0.5° of noise, σ between 0.3° and 1.5°, every seventh epoch invalid."""
    rng = np.random.default_rng(seed)
    course = np.round(np.degrees(np.pi / 2 - yaw) + 0.5 * rng.standard_normal(len(t)), 4) % 360
    sigma = np.round(rng.uniform(0.3, 1.5, len(t)), 4)
    valid = np.arange(len(t)) % 7 != 3
    return course, sigma, valid


@pytest.mark.parametrize("correction", ["kalman", "window"])
@pytest.mark.parametrize("source", ["tc+conv", "conv"])
def test_a_minimal_heading_csv_gives_what_the_full_heading_csv_gives(
    drive, correction, source, capsys
):
    """Issue 31: your own heading as gps_time_s, course_deg (or heading_deg), sigma_deg and
    valid, or in three columns without valid, gives the very file and summary of a heading.csv
    holding the same headings as its conventional heading (no tight heading)."""
    track = level_turn()
    t = np.arange(0.0, track.t[-1] + 0.05, 0.2)
    course, sigma, valid = _own_headings(t, np.interp(t, track.t, np.unwrap(track.yaw())))
    yaw = np.where(valid, np.pi / 2 - np.radians(course), np.nan)
    sigma_rad = np.where(valid, np.radians(sigma), np.nan)
    full = plain_heading_table(
        t,
        yaw_tc=np.full(len(t), np.nan),
        sigma_tc=np.full(len(t), np.nan),
        tc_reliable=np.zeros(len(t), bool),
        yaw_conv=yaw,
        conv_valid=valid,
        sigma_conv=sigma_rad,
        conv_gnss_valid=valid,
        sigma_conv_gnss=sigma_rad,
    )
    write_heading_csv(drive / "full.csv", full)
    rows = "".join(
        f"{ti:.3f},{c:.4f},{s:.4f},{int(v)}\n"
        for ti, c, s, v in zip(t, course, sigma, valid, strict=True)
    )
    (drive / "own.csv").write_text("gps_time_s,course_deg,sigma_deg,valid\n" + rows)
    (drive / "own_heading.csv").write_text("gps_time_s,heading_deg,sigma_deg,valid\n" + rows)
    three = "".join(  # three columns: an invalid heading left empty
        f"{ti:.3f},{f'{c:.4f}' if v else ''},{s:.4f}\n"
        for ti, c, s, v in zip(t, course, sigma, valid, strict=True)
    )
    (drive / "own3.csv").write_text("gps_time_s,course_deg,sigma_deg\n" + three)
    summaries = {}
    for name in ("full", "own", "own_heading", "own3"):
        argv = ["correct", str(drive / "track.tum"), "--heading", str(drive / f"{name}.csv")]
        argv += ["--world", "level", "--correction", correction, "--source", source]
        assert main([*argv, "-o", str(drive / f"{name}.tum")]) == 0
        summaries[name] = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
        del summaries[name]["output"]
    assert summaries["own"] == summaries["full"] == summaries["own_heading"] == summaries["own3"]
    assert summaries["own"]["poses_with_absolute_heading"] > 0.9 * len(track)
    written = (drive / "full.tum").read_bytes()
    assert (drive / "own.tum").read_bytes() == written
    assert (drive / "own_heading.tum").read_bytes() == written
    assert (drive / "own3.tum").read_bytes() == written


def test_a_minimal_heading_csv_has_no_tight_heading_for_source_tc(drive, capsys):
    (drive / "own.csv").write_text("gps_time_s,course_deg,sigma_deg\n0.0,90,1\n5.0,90,1\n")
    argv = ["correct", str(drive / "track.tum"), "--heading", str(drive / "own.csv")]
    assert main([*argv, "--source", "tc", "-o", str(drive / "c.tum")]) == 1
    err = capsys.readouterr().err
    assert "own.csv: no usable tc heading within the trajectory's times" in err
    assert "a minimal heading CSV is read as the conventional heading: give --source conv" in err


@pytest.mark.parametrize(
    ("text", "where", "message"),
    [
        ("gps_time_s,course_deg\n0,90\n", ":1:", "lacks column sigma_deg: expected a minimal"),
        ("gps_time_s,heading\n0,90\n", ":1:", "heading_deg or course_deg"),
        ("gps_time_s,course_deg,sigma_deg\n0,90,1\n1,east,1\n", ":3:", "course_deg 'east'"),
        ("gps_time_s,course_deg,sigma_deg\n0,90,1\n1,90,0\n", ":3:", "sigma_deg '0' of a valid"),
        ("gps_time_s,course_deg,sigma_deg,valid\n0,90,1,yes\n", ":2:", "valid 'yes' is not 0"),
    ],
)
def test_a_bad_minimal_heading_csv_names_its_file_line_and_columns(
    drive, text, where, message, capsys
):
    (drive / "own.csv").write_text(text)
    argv = ["correct", str(drive / "track.tum"), "--heading", str(drive / "own.csv")]
    assert main([*argv, "-o", str(drive / "c.tum")]) == 1
    err = capsys.readouterr().err
    assert f"own.csv{where}" in err and message in err
    assert "sigma_deg" in err and "gps_time_s" in err
