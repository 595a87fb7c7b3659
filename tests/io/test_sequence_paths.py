"""Manifest paths stay inside the sequence folder unless explicitly allowed."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest
import yaml

from vo_doppler.errors import ManifestError
from vo_doppler.io.sequence import read_sequence

SAMPLE = Path(__file__).resolve().parents[2] / "sample_sequences" / "urban_canyon_small"


@pytest.fixture
def sequence(tmp_path) -> Path:
    folder = tmp_path / "seq"
    shutil.copytree(SAMPLE, folder)
    return folder


def set_times(folder: Path, value: str) -> None:
    path = folder / "sequence.yaml"
    manifest = yaml.safe_load(path.read_text())
    manifest["camera"]["times"] = value
    path.write_text(yaml.safe_dump(manifest))


def test_symlink_leaving_the_folder_is_refused(sequence):
    (sequence / "link.txt").symlink_to("/etc/passwd")
    set_times(sequence, "link.txt")
    with pytest.raises(
        ManifestError, match=r"camera\.times: the path leaves the sequence folder"
    ) as info:
        read_sequence(sequence)
    assert "--allow-outside-paths" in str(info.value)  # the message says how to allow it


def test_absolute_path_is_read_only_when_allowed(sequence, tmp_path):
    outside = tmp_path / "times_outside.txt"
    shutil.copy(sequence / "times.txt", outside)
    set_times(sequence, str(outside))
    with pytest.raises(ManifestError, match=r"camera\.times: absolute paths are refused") as info:
        read_sequence(sequence)
    assert info.value.key == "camera.times"
    assert "allow_outside=True" in str(info.value)
    inputs = read_sequence(sequence, allow_outside=True)
    assert len(inputs.image_times) == len(inputs.image_paths)


def test_relative_path_inside_is_fine(sequence):
    os.rename(sequence / "times.txt", sequence / "image_0" / "times.txt")
    set_times(sequence, "image_0/../image_0/times.txt")
    assert len(read_sequence(sequence).image_times) == 570


def test_an_image_folder_without_images_names_the_manifest_and_its_key(sequence):
    path = sequence / "sequence.yaml"
    manifest = yaml.safe_load(path.read_text())
    (sequence / "empty").mkdir()
    manifest["camera"]["images"] = "empty"
    path.write_text(yaml.safe_dump(manifest))
    with pytest.raises(ManifestError, match=r"camera\.images: .*no PNG/JPG images") as info:
        read_sequence(sequence)
    assert info.value.key == "camera.images"
    assert info.value.path == path
