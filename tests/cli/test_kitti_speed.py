"""``vo-doppler kitti-speed``: the speed CSV the README's KITTI example feeds to ``vo --speed``."""

from __future__ import annotations

import numpy as np
from scipy.integrate import trapezoid
from scipy.spatial.transform import Rotation

from tests.conftest import require_shared
from vo_doppler.cli import main
from vo_doppler.io.sensor_csv import read_speed_csv
from vo_doppler.io.trajectory import read_kitti, write_kitti
from vo_doppler.model.trajectory import Trajectory


def test_kitti_poses_with_times_give_the_true_speed(tmp_path):
    t = 0.1 * np.arange(30)
    positions = np.column_stack([np.zeros(30), np.zeros(30), 8.0 * t])
    write_kitti(tmp_path / "poses.txt", Trajectory(t, positions, Rotation.identity(30)))
    np.savetxt(tmp_path / "times.txt", t)
    out = tmp_path / "speed.csv"
    argv = ["kitti-speed", str(tmp_path / "poses.txt"), "--times", str(tmp_path / "times.txt")]
    assert main([*argv, "-o", str(out)]) == 0
    speed = read_speed_csv(out)
    np.testing.assert_allclose(speed.t, t)
    np.testing.assert_allclose(speed.value, 8.0, rtol=1e-9)


def test_kitti_poses_without_times_ask_for_them(tmp_path, capsys):
    t = np.arange(5.0)
    write_kitti(
        tmp_path / "poses.txt", Trajectory(t, np.outer(t, [0, 0, 1.0]), Rotation.identity(5))
    )
    assert main(["kitti-speed", str(tmp_path / "poses.txt"), "-o", str(tmp_path / "s.csv")]) == 1
    assert "--times" in capsys.readouterr().err


def test_kitti06_speed_integrates_to_the_path_length(tmp_path):
    folder = require_shared("kitti06_0000_0050")
    out = tmp_path / "speed.csv"
    argv = ["kitti-speed", str(folder / "poses.txt"), "--times", str(folder / "times.txt")]
    assert main([*argv, "-o", str(out)]) == 0
    speed = read_speed_csv(out)
    truth = read_kitti(folder / "poses.txt", np.loadtxt(folder / "times.txt"))
    assert len(speed) == len(truth)
    np.testing.assert_allclose(trapezoid(speed.value, speed.t), truth.path_length, rtol=1e-6)
