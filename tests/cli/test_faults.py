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

from vo_doppler.cli import main
from vo_doppler.commands import gnss_command
from vo_doppler.errors import EXIT_FAILURE, EXIT_OK, shown, storage_refused
from vo_doppler.io.images import read_image
from vo_doppler.report import run_outputs
from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon

NOT_UTF8 = os.fsdecode(b"caf\xe9-\xff")
"""A Latin-1 name ('café-ÿ' as bytes): no UTF-8 text, held by Python as lone surrogates."""


def full_disk(*_args, **_kwargs) -> None:
    """A write the system refuses as a full disk does at a buffered file's flush: no file
    named."""
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
