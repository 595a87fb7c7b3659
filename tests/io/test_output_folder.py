"""Output folders written all at once."""

from __future__ import annotations

import pytest

from vo_doppler.errors import OutputError
from vo_doppler.io.output_folder import check_output_folder, staged_output, untouched


def test_a_file_is_refused(tmp_path):
    target = tmp_path / "out"
    target.write_text("x")
    with pytest.raises(OutputError, match="the output exists and is not a folder"):
        check_output_folder(target)
    with pytest.raises(OutputError, match="is not a folder"):
        check_output_folder(target / "below")


def test_success_replaces_the_previous_folder_without_stale_files(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "stale.png").write_text("old")
    with staged_output(out) as staging:
        assert staging.parent == out.parent and staging != out
        (staging / "new.txt").write_text("new")
        assert (out / "stale.png").exists()  # the old results stay until the end
    assert sorted(p.name for p in out.iterdir()) == ["new.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_failure_leaves_the_previous_folder_and_no_staging(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "old.txt").write_text("old")
    with pytest.raises(RuntimeError), staged_output(out) as staging:
        (staging / "half.txt").write_text("half")
        raise RuntimeError
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert [p.name for p in out.iterdir()] == ["old.txt"]
    assert untouched(out) == f"nothing written: {out} left as it was"
    assert untouched(tmp_path / "new") == f"nothing written: {tmp_path / 'new'} not created"


def test_nested_new_folder_is_created(tmp_path):
    out = tmp_path / "a" / "b"
    with staged_output(out) as staging:
        (staging / "x").write_text("1")
    assert (out / "x").read_text() == "1"
