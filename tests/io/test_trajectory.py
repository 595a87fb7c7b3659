"""Trajectory TUM/KITTI round trips and error handling."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from vo_doppler.errors import InputError
from vo_doppler.io.trajectory import (
    AUTO_FORMAT_RULE,
    read_kitti,
    read_trajectory,
    read_tum,
    trajectory_format,
    write_kitti,
    write_tum,
)
from vo_doppler.model.trajectory import Trajectory

finite = st.floats(-1e4, 1e4, allow_nan=False)


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 20), st.integers(0, 2**31 - 1))
def test_tum_and_kitti_round_trip(tmp_path_factory, n, seed):
    rng = np.random.default_rng(seed)
    traj = Trajectory(
        np.cumsum(rng.uniform(0.01, 1.0, n)),
        rng.uniform(-1e3, 1e3, (n, 3)),
        Rotation.random(n, random_state=seed),
    )
    folder = tmp_path_factory.mktemp("traj")
    write_tum(folder / "a.tum", traj)
    write_kitti(folder / "a.kitti", traj)
    back_tum = read_trajectory(folder / "a.tum")
    back_kitti = read_trajectory(folder / "a.kitti", times=traj.t)
    for back in (back_tum, back_kitti):
        np.testing.assert_allclose(back.positions, traj.positions, atol=1e-6)
        np.testing.assert_allclose(back.matrices, traj.matrices, atol=1e-6)
    np.testing.assert_allclose(back_tum.t, traj.t, atol=1e-9)


def test_bad_rows_name_file_and_line(tmp_path):
    path = tmp_path / "bad.tum"
    path.write_text("# header\n0 0 0 0 0 0 0 1\n1 0 0 x 0 0 0 1\n")
    with pytest.raises(InputError, match=r"bad.tum:3"):
        read_tum(path)
    path.write_text("0 0 0 0 0 0 0 1\n1 0 0\n")
    with pytest.raises(InputError, match=r"bad.tum:2.*3 fields"):
        read_tum(path)
    path.write_text("0 0 0 0 0 0 0 0\n")
    with pytest.raises(InputError, match="zero quaternion"):
        read_tum(path)


def test_kitti_time_count_mismatch(tmp_path):
    path = tmp_path / "p.txt"
    path.write_text("1 0 0 0 0 1 0 0 0 0 1 0\n" * 3)
    with pytest.raises(InputError, match="3 poses but 2 timestamps"):
        read_kitti(path, np.array([0.0, 1.0]))


def test_format_sniffing_rejects_unknown(tmp_path):
    path = tmp_path / "p.txt"
    path.write_text("1 2 3\n")
    with pytest.raises(InputError, match="first row has 3 fields"):
        read_trajectory(path)


@pytest.mark.parametrize("name", ["poses.kitti", "poses.tum", "poses.txt", "poses"])
def test_auto_format_goes_by_the_columns_whatever_the_extension(tmp_path, name):
    """TUM and KITTI files are both commonly .txt: the column count (8 or 12) decides, as
    ``--format auto``'s help says (AUTO_FORMAT_RULE)."""
    tum, kitti = tmp_path / "tum", tmp_path / "kitti"
    tum.mkdir(), kitti.mkdir()
    (tum / name).write_text("5.0 1 2 3 0 0 0 1\n6.0 4 5 6 0 0 0 1\n")
    (kitti / name).write_text("1 0 0 7 0 1 0 8 0 0 1 9\n")
    assert trajectory_format(tum / name) == "tum"
    assert trajectory_format(kitti / name) == "kitti"
    np.testing.assert_array_equal(read_trajectory(tum / name).t, [5.0, 6.0])
    np.testing.assert_array_equal(read_trajectory(kitti / name).positions, [[7.0, 8.0, 9.0]])
    assert "columns" in AUTO_FORMAT_RULE and "extension" not in AUTO_FORMAT_RULE
