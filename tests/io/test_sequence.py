"""Sequence manifests: clear errors that name the file and the missing piece."""

from __future__ import annotations

import pytest
import yaml

from vo_doppler.errors import InputError
from vo_doppler.io.sequence import read_manifest, read_sequence
from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon


def write_manifest(folder, data) -> None:
    (folder / "sequence.yaml").write_text(yaml.safe_dump(data))


def test_missing_manifest(tmp_path):
    with pytest.raises(InputError, match=r"sequence.yaml: cannot read the sequence manifest"):
        read_manifest(tmp_path)


def test_wrong_format_is_named(tmp_path):
    write_manifest(tmp_path, {"format": "something-else/2"})
    with pytest.raises(InputError, match=r"not a vo-doppler-sequence/1 manifest.*something-else"):
        read_manifest(tmp_path)
    (tmp_path / "sequence.yaml").write_text("a: [1, 2\n")
    with pytest.raises(InputError, match="not valid YAML"):
        read_manifest(tmp_path)


def test_missing_section_and_key_are_named(tmp_path):
    write_manifest(tmp_path, {"format": "vo-doppler-sequence/1", "camera": {"images": "x"}})
    with pytest.raises(InputError, match="no 'gnss' section"):
        read_sequence(tmp_path)
    write_manifest(
        tmp_path,
        {
            "format": "vo-doppler-sequence/1",
            "camera": {"times": "times.txt"},
            "gnss": {},
            "can": {},
            "origin": {},
        },
    )
    with pytest.raises(InputError, match="section 'camera' lacks 'images'"):
        read_sequence(tmp_path)


def test_antenna_lever_arm_is_read_and_defaults_to_zero(tmp_path):
    config = UrbanCanyonConfig(
        duration_s=1.0, seed=1, image_size=(64, 36), antenna_lever_arm_m=(1.2, -0.3, 1.5)
    )
    simulate_urban_canyon(tmp_path, config)
    assert read_sequence(tmp_path).antenna_lever_arm_m == (1.2, -0.3, 1.5)
    manifest = yaml.safe_load((tmp_path / "sequence.yaml").read_text())
    del manifest["gnss"]["antenna_lever_arm_m"]
    write_manifest(tmp_path, manifest)
    assert read_sequence(tmp_path).antenna_lever_arm_m == (0.0, 0.0, 0.0)
    for bad in ([1.0, 2.0], "1,2,3", [1.0, None, 2.0]):
        manifest["gnss"]["antenna_lever_arm_m"] = bad
        write_manifest(tmp_path, manifest)
        with pytest.raises(InputError, match=r"gnss\.antenna_lever_arm_m .* not three numbers"):
            read_sequence(tmp_path)
