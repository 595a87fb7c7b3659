"""`vo-doppler simulate`'s summary says what it wrote."""

from __future__ import annotations

import pytest

from vo_doppler.cli import main

pytestmark = pytest.mark.slow


def test_without_images_the_summary_says_no_frame_was_rendered(tmp_path, capsys):
    out = tmp_path / "sim"
    assert main(["-q", "simulate", "--no-images", "--duration", "10", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "none rendered (--no-images;" in printed
    assert not (out / "image_0").exists()
