"""The ``vo-doppler vo`` command end to end on a few real KITTI frames."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from tests.conftest import REPO_ROOT, require_shared
from vo_doppler.cli import main
from vo_doppler.io.trajectory import read_kitti, read_tum, write_tum
from vo_doppler.model.trajectory import Trajectory

N = 14


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    source = require_shared("kitti06_0000_0050")
    folder = tmp_path_factory.mktemp("kitti")
    images = folder / "image_0"
    images.mkdir()
    for f in sorted((source / "image_0").glob("*.png"))[:N]:
        shutil.copy(f, images / f.name)
    (images / "000007.png").write_bytes(b"\x89PNG\r\n\x1a\n truncated")
    times = np.loadtxt(source / "times.txt")[:N]
    np.savetxt(folder / "times.txt", times)
    truth = read_kitti(source / "poses.txt").subset(slice(0, N))
    steps = np.linalg.norm(np.diff(truth.positions, axis=0), axis=1) / np.diff(times)
    speed = np.column_stack([times, np.r_[steps[0], steps]])
    np.savetxt(folder / "speed.csv", speed, delimiter=",", header="t,speed_mps", comments="")
    (folder / "poses.txt").write_text(
        "\n".join((source / "poses.txt").read_text().splitlines()[:N]) + "\n"
    )
    return folder, source / "calib.txt"


def test_vo_command_writes_every_output(sequence, capsys):
    folder, calib = sequence
    out = folder / "out"
    code = main(
        [
            "vo",
            str(folder / "image_0"),
            "--calib",
            str(calib),
            "--speed",
            str(folder / "speed.csv"),
            "--gt",
            str(folder / "poses.txt"),
            "-o",
            str(out),
        ]
    )
    assert code == 0
    tum = read_tum(out / "trajectory.tum")
    kitti = read_kitti(out / "trajectory.kitti")
    assert len(tum) == len(kitti) == N
    np.testing.assert_allclose(tum.positions, kitti.positions, atol=1e-6)
    stats = json.loads((out / "vo_stats.json").read_text())
    for key in (
        "frames",
        "keyframes",
        "fps",
        "mean_tracks",
        "ba_iterations",
        "reprojection_rms_px",
        "flagged_frames",
    ):
        assert key in stats
    assert stats["frames"] == N and stats["metric_scale"] is True
    assert [(f["index"], f["file"]) for f in stats["flagged_frames"]] == [(7, "000007.png")]
    assert "unreadable" in stats["flagged_frames"][0]["reasons"]
    assert stats["evaluation"]["final_drift_pct"] < 3.0
    assert (out / "trajectory.png").stat().st_size > 10_000
    assert "metric scale from speed" in capsys.readouterr().out


def test_without_speed_the_scale_is_declared_arbitrary(sequence, capsys):
    folder, calib = sequence
    out = folder / "out_nospeed"
    assert main(["vo", str(folder / "image_0"), "--calib", str(calib), "-o", str(out)]) == 0
    assert "scale is arbitrary" in capsys.readouterr().out
    assert json.loads((out / "vo_stats.json").read_text())["metric_scale"] is False


def test_usage_and_input_errors(sequence, tmp_path, capsys):
    folder, calib = sequence
    with pytest.raises(SystemExit) as usage:
        main(["vo", str(folder / "image_0"), "-o", str(tmp_path)])
    assert usage.value.code == 2
    with pytest.raises(SystemExit) as short_window:
        main(["vo", str(folder / "image_0"), "--calib", str(calib), "--window", "2", "-o", "x"])
    assert short_window.value.code == 2
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["vo", str(empty), "--calib", str(calib), "--fps", "10", "-o", str(tmp_path)]) == 1
    assert f"{tmp_path}: the output folder contains the input {empty}" in capsys.readouterr().err
    out = str(tmp_path / "out")
    assert main(["vo", str(empty), "--calib", str(calib), "--fps", "10", "-o", out]) == 1
    assert "no PNG/JPG images" in capsys.readouterr().err
    bad_times = tmp_path / "times.txt"
    bad_times.write_text("0\n0.1\n0.1\n")
    code = main(
        [
            "vo",
            str(folder / "image_0"),
            "--calib",
            str(calib),
            "--times",
            str(bad_times),
            "-o",
            out,
        ]
    )
    assert code == 1
    assert f"3 timestamps for {N} images" in capsys.readouterr().err


def test_ground_truth_on_other_times_is_not_evaluated_and_says_why(sequence, caplog):
    folder, calib = sequence
    poses = read_kitti(folder / "poses.txt")
    times = np.loadtxt(folder / "times.txt")
    elsewhere = folder / "elsewhere.tum"
    write_tum(elsewhere, Trajectory(times + 1000.0, poses.positions, poses.orientations))
    out = folder / "out_elsewhere"
    command = ["vo", str(folder / "image_0"), "--calib", str(calib), "--gt", str(elsewhere)]
    assert main([*command, "-o", str(out)]) == 0
    stats = json.loads((out / "vo_stats.json").read_text())
    assert "evaluation" not in stats
    reason = stats["evaluation_skipped"]
    assert reason.startswith(f"not evaluated against {elsewhere}: fewer than two timestamps match")
    last = times[-1]
    assert f"(images 0.000..{last:.3f} s, ground truth 1000.000..{last + 1000:.3f} s)" in reason
    assert reason in caplog.text


@pytest.mark.parametrize("problem", ["missing", "rows"])
def test_ground_truth_is_read_before_the_vo(problem, tmp_path, monkeypatch, capsys):
    """A missing ground truth, or a KITTI one with more poses than images, stops the command
    before the VO runs and before the output folder exists."""
    images = tmp_path / "images"
    images.mkdir()
    for i in range(3):
        (images / f"{i:06d}.png").write_bytes(b"not decoded: the VO must not start")
    truth = tmp_path / "gt.txt"
    if problem == "rows":
        truth.write_text("1 0 0 0 0 1 0 0 0 0 1 0\n" * 4)

    def no_vo(*args, **kwargs):
        raise AssertionError("the VO ran before the ground truth was read")

    monkeypatch.setattr("vo_doppler.commands.vo_command.run_visual_odometry", no_vo)
    out = tmp_path / "out"
    calib = str(REPO_ROOT / "calib" / "synthetic.yaml")
    command = ["vo", str(images), "--calib", calib, "--fps", "10", "--gt", str(truth)]
    assert main([*command, "-o", str(out)]) == 1
    err = capsys.readouterr().err
    expected = "No such file or directory" if problem == "missing" else "4 poses but 3 timestamps"
    assert f"{truth}: " in err and expected in err
    assert not out.exists()


def test_a_calibration_for_another_image_size_is_refused_before_any_work(tmp_path, capsys):
    """Issue 30: exit 1 naming both sizes, nothing written."""
    import cv2

    images = tmp_path / "image_0"
    images.mkdir()
    for k in range(3):
        cv2.imwrite(str(images / f"{k:06d}.png"), np.full((376, 1241), 40 * k, np.uint8))
    calib = REPO_ROOT / "calib" / "kitti_odometry_04-12.yaml"
    out = tmp_path / "out"
    code = main(["vo", str(images), "--calib", str(calib), "--fps", "10", "-o", str(out)])
    assert code == 1 and not out.exists()
    err = capsys.readouterr().err
    assert "1241×376 px but the camera calibration is for 1226×370 px" in err
