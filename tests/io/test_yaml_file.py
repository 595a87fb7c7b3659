"""Bounded YAML loading: aliases and over-long integers are errors naming the file and line."""

from __future__ import annotations

import pytest

from vo_doppler.errors import InputError
from vo_doppler.io.yaml_file import load_yaml


def test_ordinary_yaml_reads(tmp_path):
    path = tmp_path / "a.yaml"
    path.write_text("a: 12\nb: [1.5, -3]\nc: 0x1F\n")
    assert load_yaml(path, "the test file") == {"a": 12, "b": [1.5, -3], "c": 31}


def test_integer_of_ten_thousand_digits_names_the_line(tmp_path):
    path = tmp_path / "a.yaml"
    path.write_text("a: 1\nb: " + "9" * 10_000 + "\n")
    with pytest.raises(InputError, match=r"a\.yaml:2: .*an integer of 10000 characters") as info:
        load_yaml(path, "the test file")
    assert str(path) in str(info.value)


def test_alias_is_refused(tmp_path):
    path = tmp_path / "a.yaml"
    path.write_text("a: &x [1, 2]\nb: *x\n")
    with pytest.raises(InputError, match="aliases"):
        load_yaml(path, "the test file")
