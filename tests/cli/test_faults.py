"""Faults of the environment (issue 30): a full file system and names that are not UTF-8 are
the user's situation, not bugs: exit 1 naming the output with the previous results intact, or
the work done."""

from __future__ import annotations

import errno
import os
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.helpers.heading_table import plain_heading_table
from tests.helpers.level_track import level_turn
from vo_doppler.cli import main
from vo_doppler.commands import correct_command, gnss_command, heading_command, kitti_speed_command
from vo_doppler.errors import EXIT_FAILURE, EXIT_OK, shown, storage_refused
from vo_doppler.io.heading_csv import write_heading_csv
from vo_doppler.io.images import read_image
from vo_doppler.io.trajectory import write_kitti, write_tum
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.report import run_outputs
from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon

NOT_UTF8 = os.fsdecode(b"caf\xe9-\xff")
"""A Latin-1 name ('café-ÿ' as bytes): no UTF-8 text, held by Python as lone surrogates."""


def full_disk(*_args, **_kwargs) -> None:
    """A write the system refuses as a full disk does at a buffered file's flush: no file
    named."""
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def half_written(path, *_args, **_kwargs) -> None:
    """A writer that stores part of its file, then finds the disk full."""
    Path(path).write_text("t,partial\n0.0,")
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


@pytest.fixture(scope="module")
def drive(tmp_path_factory) -> Path:
    """A 10-s drive without images (the faults are in writing, not in the VO) in a folder whose
    name is not UTF-8, its manifest without a name (so the folder's name is the sequence's)."""
    folder = tmp_path_factory.mktemp("faults") / NOT_UTF8
    simulate_urban_canyon(folder, UrbanCanyonConfig(duration_s=10.0, seed=4, render=False))
    manifest = folder / "sequence.yaml"
    lines = manifest.read_text().splitlines(keepends=True)
    manifest.write_text("".join(line for line in lines if not line.startswith("name:")))
    return folder


@pytest.fixture(scope="module")
def first_run(drive, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("runs") / f"out-{NOT_UTF8}"
    assert main(["-q", "run", str(drive), "-o", str(out)]) == EXIT_OK
    return out


@pytest.mark.slow
def test_run_with_names_that_are_not_utf8_writes_its_report(first_run):
    report = (first_run / "report.html").read_text(encoding="utf-8")
    assert shown(NOT_UTF8) == "caf\\xe9-\\xff"
    assert shown(NOT_UTF8) in report  # the sequence's name and the command line
    assert (first_run / "trajectories.png").stat().st_size > 0


@pytest.mark.slow
def test_run_on_a_full_disk_is_exit_1_naming_the_folder_and_keeps_the_results(
    drive, first_run, monkeypatch, capsys, caplog
):
    before = snapshot(first_run)
    monkeypatch.setattr(run_outputs, "write_geojson", full_disk)
    assert main(["-q", "run", str(drive), "-o", str(first_run)]) == EXIT_FAILURE
    err = capsys.readouterr().err
    assert "No space left on device" in err and shown(first_run) in err
    assert "internal error" not in err and len(err.splitlines()) == 1
    assert "left as it was" in caplog.text
    assert snapshot(first_run) == before
    leftovers = [p.name for p in first_run.parent.iterdir() if p.name.startswith(".")]
    assert leftovers == []


@pytest.mark.slow
def test_gnss_velocity_on_a_full_disk_is_exit_1_naming_the_output(drive, tmp_path, capsys):
    obs = tmp_path / f"rover-{NOT_UTF8}.obs"  # a file name that is not UTF-8: in the title
    shutil.copy(drive / "gnss" / "rover.obs", obs)
    out = tmp_path / NOT_UTF8 / "vel.csv"
    argv = ["-q", "gnss", "velocity", str(obs), "--nav", str(drive / "gnss" / "brdc.nav")]
    assert main([*argv, "-o", str(out)]) == EXIT_OK
    before = snapshot(out.parent)
    assert set(before) == {"vel.csv", "vel.png"}
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(gnss_command, "velocity_figure", full_disk)
        assert main([*argv, "-o", str(out)]) == EXIT_FAILURE
    err = capsys.readouterr().err
    assert shown(out) in err and "No space left on device" in err and "internal" not in err
    assert snapshot(out.parent) == before


def _full_disk_leaves_no_partial_file(argv, out: Path, module, writers, capsys) -> None:
    """``argv -o out`` with each of ``module``'s ``writers`` storing part of its file and then
    finding the disk full: exit 1 naming ``out`` in one line, and in ``out``'s folder nothing
    (before any run) or the files of the run before as they were, no partial file beside."""

    def fails(before: dict[str, bytes]) -> None:
        for writer in writers:
            capsys.readouterr()
            with pytest.MonkeyPatch.context() as patch:
                patch.setattr(module, writer, half_written)
                assert main([*argv, "-o", str(out)]) == EXIT_FAILURE
            err = capsys.readouterr().err
            assert shown(out) in err and "No space left on device" in err
            assert "internal" not in err and len(err.splitlines()) == 1
            assert sorted(p.name for p in out.parent.iterdir()) == sorted(before)
            assert snapshot(out.parent) == before

    out.parent.mkdir(parents=True, exist_ok=True)
    fails({})
    assert main([*argv, "-o", str(out)]) == EXIT_OK
    before = snapshot(out.parent)
    assert out.name in before
    fails(before)


@pytest.mark.slow
def test_heading_on_a_full_disk_leaves_no_partial_file(drive, tmp_path, capsys):
    argv = ["-q", "heading", str(drive / "gnss/rover.obs"), "--nav", str(drive / "gnss/brdc.nav")]
    argv += ["--can", str(drive / "can/vehicle.log"), "--dbc", str(drive / "can/vehicle.dbc")]
    argv += ["--yaw-rate", "VEHICLE_DYNAMICS.YAW_RATE", "--time-offset-can", "-315964782"]
    argv += ["--wheel-speed", "WHEEL_SPEEDS.WHEEL_SPEED_RL,WHEEL_SPEEDS.WHEEL_SPEED_RR"]
    out = tmp_path / NOT_UTF8 / "heading.csv"
    writers = ("write_heading_csv", "heading_figure")  # the first file, then the second
    _full_disk_leaves_no_partial_file(argv, out, heading_command, writers, capsys)
    assert sorted(p.name for p in out.parent.iterdir()) == ["heading.csv", "heading.png"]


def test_correct_on_a_full_disk_leaves_no_partial_file(tmp_path, capsys):
    track = level_turn()
    write_tum(tmp_path / "track.tum", track)
    t = np.arange(0.0, track.t[-1] + 0.05, 0.2)
    yaw = np.interp(t, track.t, np.unwrap(track.yaw()))
    write_heading_csv(tmp_path / "h.csv", plain_heading_table(t, yaw_tc=yaw, yaw_conv=yaw))
    argv = ["-q", "correct", str(tmp_path / "track.tum"), "--heading", str(tmp_path / "h.csv")]
    argv += ["--world", "level"]
    out = tmp_path / NOT_UTF8 / "corrected.tum"
    _full_disk_leaves_no_partial_file(argv, out, correct_command, ("write_tum",), capsys)


def test_kitti_speed_on_a_full_disk_leaves_no_partial_file(tmp_path, capsys):
    t = 0.1 * np.arange(30)
    positions = np.column_stack([np.zeros(30), np.zeros(30), 8.0 * t])
    write_kitti(tmp_path / "poses.txt", Trajectory(t, positions, Rotation.identity(30)))
    np.savetxt(tmp_path / "times.txt", t)
    argv = ["-q", "kitti-speed", str(tmp_path / "poses.txt")]
    argv += ["--times", str(tmp_path / "times.txt")]
    out = tmp_path / NOT_UTF8 / "speed.csv"
    _full_disk_leaves_no_partial_file(argv, out, kitti_speed_command, ("write_sensor_csv",), capsys)


def test_only_storage_refusals_are_the_environments():
    assert storage_refused(OSError(errno.ENOSPC, "full"))
    assert storage_refused(OSError(errno.EROFS, "read-only"))
    assert not storage_refused(OSError(errno.EBADF, "bad descriptor"))
    assert not storage_refused(ValueError("no"))


def test_an_image_whose_name_is_not_utf8_is_read(tmp_path):
    """``cv2.imread`` encodes the name as UTF-8 and crashes the process on a lone surrogate."""
    image = (np.arange(48 * 64) % 251).astype(np.uint8).reshape(48, 64)
    path = tmp_path / f"{NOT_UTF8}.png"
    ok, encoded = cv2.imencode(".png", image)
    assert ok
    path.write_bytes(encoded.tobytes())
    assert np.array_equal(read_image(path), image)
    assert read_image(tmp_path / "missing.png") is None


def test_an_image_file_past_the_bound_is_not_read(tmp_path):
    path = tmp_path / "000000.png"
    path.write_bytes(b"\x89PNG\r\n\x1a\n")
    os.truncate(path, 8 << 30)  # sparse: no disk used
    assert read_image(path) is None
