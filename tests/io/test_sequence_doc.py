"""docs/sequence_format.md stays true: its example manifest reads, and every key it documents
is one the reader uses."""

from __future__ import annotations

import re

import yaml

from tests.conftest import REPO_ROOT
from vo_doppler.io.sequence import read_manifest

DOC = REPO_ROOT / "docs" / "sequence_format.md"
READER = REPO_ROOT / "vo_doppler" / "io" / "sequence.py"


def test_example_manifest_is_accepted(tmp_path):
    example = re.search(r"```yaml\n(.*?)```", DOC.read_text(), re.S).group(1)
    (tmp_path / "sequence.yaml").write_text(example)
    manifest = read_manifest(tmp_path)
    for section in ("origin", "camera", "gnss", "can"):
        assert isinstance(manifest[section], dict)
    assert yaml.safe_load(example)["can"]["wheel_speed"].count(",") == 1


def test_every_documented_key_is_read():
    reader = READER.read_text()
    keys = re.findall(r"^\| `([a-z_]+)(?:\.([a-z_]+))?`", DOC.read_text(), re.M)
    assert len(keys) > 15
    for section, key in keys:
        assert f'"{key or section}"' in reader, f"{section}.{key} is documented but not read"
